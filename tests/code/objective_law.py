#!/usr/bin/env python3
"""An objective linear spring-dashpot law with a Coulomb slider for `verdem verify --code`,
written from docs/code-interface.md alone (plain Python 3.11 or later, no packages):

    python3 objective_law.py CASE.toml MOTION.csv --out FORCES.csv
        [--increment positions|trapezoid] [--twist quaternions|spins] [--defect NAME]

The stored spring turns with the contact frame (the tilt of the normal, then the twist about
it), the slip is the objective one (centres' velocity scaled by (R1 + R2)/d, spins with full
radii, at the step's midpoint normal), the spring is capped at mu|fn| and reset to the cap
while sliding, the dashpot is added after, and the torques use the arms to the contact point
in the middle of the overlap. Its time discretisation is a choice, as in any code:

    --increment positions  the step's velocities from positions and quaternions (default)
    --increment trapezoid  the mean of the two rows' velocities and spins
    --twist quaternions    the twist of a step from the quaternions (default)
    --twist spins          the twist from the rows' spins, their trapezoidal mean of w.n

`--defect` makes it wrong in one way, for the tests to show which rows catch what:

    frame    the spring is not turned with the contact frame at all (kept in the lab frame)
    twist    the spring follows the tilt of the normal but not the twist about it
    cap      the spring is not reset to the cap while sliding (wound past it)
    kt       the tangential stiffness is 1.0001 times the case's
    reset    the spring is kept when the contact is lost (and used when it closes again)
"""

import argparse
import csv
import math
import tomllib

FORCES = "t fx1 fy1 fz1 tx1 ty1 tz1 fx2 fy2 fz2 tx2 ty2 tz2 delta fn ft".split()


def add(a, b):
    return [x + y for x, y in zip(a, b)]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def scale(s, a):
    return [s * x for x in a]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(dot(a, a))


def tangential(a, n):
    """The part of a perpendicular to the unit vector n."""
    return sub(a, scale(dot(a, n), n))


def qmul(p, q):
    """Hamilton product of quaternions (w, x, y, z)."""
    return [p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
            p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
            p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
            p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0]]


def rotation_vector(q):
    """Axis times angle of a unit quaternion, the angle from atan2 (docs: acos loses digits)."""
    w, v = q[0], q[1:]
    if w < 0.0:
        w, v = -w, scale(-1.0, v)
    length = norm(v)
    return [0.0, 0.0, 0.0] if length == 0.0 else scale(2.0 * math.atan2(length, w) / length, v)


def sphere(row, s):
    """Position, orientation, velocity and spin of sphere s (0 or 1) in a motion row."""
    o = 1 + 13 * s
    return row[o:o + 3], row[o + 3:o + 7], row[o + 7:o + 10], row[o + 10:o + 13]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("case")
    p.add_argument("motion")
    p.add_argument("--out", required=True)
    p.add_argument("--increment", choices=["positions", "trapezoid"], default="positions")
    p.add_argument("--twist", choices=["quaternions", "spins"], default="quaternions")
    p.add_argument("--defect", choices=["frame", "twist", "cap", "kt", "reset"])
    a = p.parse_args()
    with open(a.case, "rb") as f:
        case = tomllib.load(f)
    c = case["contact"]
    kn, gamman, kt, gammat, mu = c["kn"], c["gamman"], c["kt"], c["gammat"], c["mu"]
    if a.defect == "kt":
        kt *= 1.0001
    r1, r2 = (s["radius"] for s in case["scene"]["sphere"])
    with open(a.motion, newline="") as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    rows = [[float(x) for x in r] for r in list(csv.reader(lines))[1:]]

    out = []
    xi = [0.0, 0.0, 0.0]  # the spring's stretch, lab frame, in the tangent plane
    n_old = None  # the normal of the previous row, while in contact
    for k, row in enumerate(rows):
        (x1, q1, v1, w1), (x2, q2, v2, w2) = sphere(row, 0), sphere(row, 1)
        r = sub(x2, x1)
        d = norm(r)
        delta = r1 + r2 - d
        if delta <= 0.0:
            if a.defect != "reset":
                xi, n_old = [0.0, 0.0, 0.0], None  # contact lost: the history is forgotten
            out.append([row[0]] + [0.0] * 12 + [delta, 0.0, 0.0])
            continue
        n = scale(1.0 / d, r)
        dt, turn = 0.0, [[0.0] * 3, [0.0] * 3]
        if k > 0:
            prev = rows[k - 1]
            dt = row[0] - prev[0]
            (px1, pq1, pv1, pw1), (px2, pq2, pv2, pw2) = sphere(prev, 0), sphere(prev, 1)
            conj = lambda q: [q[0], -q[1], -q[2], -q[3]]
            turn = [rotation_vector(qmul(q1, conj(pq1))), rotation_vector(qmul(q2, conj(pq2)))]
            if a.increment == "positions":
                v1, v2 = scale(1.0 / dt, sub(x1, px1)), scale(1.0 / dt, sub(x2, px2))
                w1, w2 = scale(1.0 / dt, turn[0]), scale(1.0 / dt, turn[1])
            else:
                v1, v2 = scale(0.5, add(v1, pv1)), scale(0.5, add(v2, pv2))
                w1, w2 = scale(0.5, add(w1, pw1)), scale(0.5, add(w2, pw2))
            if a.twist == "spins":
                # the trapezoidal mean of the rows' spins, turned into the step's rotations
                turn = [scale(0.5 * dt, add(w, pw)) for w, pw in ((row[11:14], pw1),
                                                               (row[24:27], pw2))]
        m = n if n_old is None else scale(1.0 / norm(add(n_old, n)), add(n_old, n))
        # the objective slip at the midpoint normal m (McNamara, Garcia-Rojo & Herrmann 2008)
        slip = sub(scale((r1 + r2) / d, sub(v2, v1)), cross(add(scale(r2, w2), scale(r1, w1)), m))
        slip = tangential(tangential(slip, m), n)
        if n_old is not None and a.defect != "frame":
            # tilt: the minimal rotation taking n_old to n, applied to xi (perpendicular to n_old)
            xi = sub(xi, scale(dot(xi, n) / (1.0 + dot(n_old, n)), add(n_old, n)))
            if a.defect != "twist":
                # twist about the normal: the pair's mean turn of the step about m
                phi = 0.5 * dot(add(turn[0], turn[1]), m)
                xi = add(scale(math.cos(phi), xi), scale(math.sin(phi), cross(n, xi)))
        xi = add(xi, scale(dt, slip))
        fn = kn * delta - gamman * dot(sub(v2, v1), n)  # linear spring-dashpot
        limit = mu * abs(fn)
        spring = scale(-kt, tangential(xi, n))
        if norm(spring) > limit:
            # Coulomb: the spring is capped and, sliding, reset to the cap
            spring = scale(limit / norm(spring), spring)
            if a.defect != "cap":
                xi = scale(-1.0 / kt, spring)
        ft = sub(spring, scale(gammat, slip))
        if norm(ft) > limit:
            ft = scale(limit / norm(ft), ft)
        n_old = n
        f2 = add(scale(fn, n), ft)
        f1 = scale(-1.0, f2)
        arm2 = scale(-(r2 - 0.5 * delta), n)  # centre of sphere 2 to the contact point
        arm1 = add(r, arm2)  # centre of sphere 1 to the contact point
        out.append([row[0], *f1, *cross(arm1, f1), *f2, *cross(arm2, f2), delta, fn, norm(ft)])

    with open(a.out, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(FORCES)
        w.writerows([[repr(x) for x in r] for r in out])


if __name__ == "__main__":
    main()
