#!/usr/bin/env python3
"""A contact law wrapped for `verdem verify --code` (docs/code-interface.md).

    python3 law.py CASE.toml MOTION.csv --out FORCES.csv

reads the law's parameters and the radii from CASE.toml and the motion of the two spheres from
MOTION.csv, and writes the force and torques on each sphere at every row to FORCES.csv.
Python 3.11 or later, standard library only.

`contact_force` is verdem's objective law: a linear spring-dashpot normal force, a tangential
spring that turns with the contact, a tangential dashpot and a Coulomb slider. To judge your
own law, replace its body by a call into your code and keep its history in `state`; then run
`verdem verify --code "python3 law.py" --convention NAME` with the convention your law claims.
"""

import argparse
import csv
import math
import tomllib

MOTION = ("t x1 y1 z1 qw1 qx1 qy1 qz1 vx1 vy1 vz1 wx1 wy1 wz1 "
          "x2 y2 z2 qw2 qx2 qy2 qz2 vx2 vy2 vz2 wx2 wy2 wz2").split()
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


def turn(q, p):
    """The rotation vector (axis times angle) taking orientation p to q, unit quaternions
    (w, x, y, z): that of q p^-1. The angle is 2 atan2(|xyz|, |w|), not 2 acos(w), which loses
    half the digits for the small turns of one row."""
    w, x, y, z = q
    pw, px, py, pz = p[0], -p[1], -p[2], -p[3]
    r = [w * pw - x * px - y * py - z * pz,
         w * px + x * pw + y * pz - z * py,
         w * py - x * pz + y * pw + z * px,
         w * pz + x * py - y * px + z * pw]
    s = norm(r[1:])
    if s == 0.0:
        return [0.0, 0.0, 0.0]
    return scale(math.copysign(2.0 * math.atan2(s, abs(r[0])) / s, r[0]), r[1:])


def contact_force(c, r1, r2, x, x_old, v, w1, w2, dt, state):
    """The force on sphere 2 (lab frame) and its normal part fn, for overlapping spheres of
    radii r1, r2: x = x2 - x1 now and x_old at the previous row, v = v2 - v1 and the spins w1,
    w2 over the step dt. state["spring"] is the tangential spring (length), kept from row to
    row; its elastic force on sphere 2 is -kt * spring."""
    dist = norm(x)
    n = scale(1.0 / dist, x)
    fn = c["kn"] * (r1 + r2 - dist) - c["gamman"] * dot(v, n)
    if c.get("clip_normal", False):
        fn = max(fn, 0.0)
    kt, gammat, mu = c["kt"], c["gammat"], c["mu"]
    if mu == 0.0:
        return scale(fn, n), fn
    spring = state.get("spring", [0.0, 0.0, 0.0])
    # turn the spring with the contact: tilt it from the previous normal to n, then twist it
    # about n by the mean spin about the step's middle normal m
    n_old = scale(1.0 / norm(x_old), x_old)
    m = add(n_old, n)
    m = scale(1.0 / norm(m), m)
    spring = sub(spring, scale(dot(spring, n) / (1.0 + dot(n_old, n)), add(n_old, n)))
    phi = 0.5 * dt * dot(add(w1, w2), m)
    spring = add(scale(math.cos(phi), spring), scale(math.sin(phi), cross(n, spring)))
    # stretch it by the slip: the relative velocity at the contact less that of a rigid motion
    # of the pair, taken at m, then in the tangent plane of n
    slip = sub(scale((r1 + r2) / dist, v), cross(add(scale(r2, w2), scale(r1, w1)), m))
    slip = sub(slip, scale(dot(slip, m), m))
    slip = sub(slip, scale(dot(slip, n), n))
    spring = add(spring, scale(dt, slip))
    # Coulomb: the elastic force is capped at mu |fn| (the spring slides back to it), then the
    # dashpot is added and the total capped again
    limit = mu * abs(fn)
    elastic = scale(-kt, spring)
    if norm(elastic) > limit:
        elastic = scale(limit / norm(elastic), elastic)
        spring = scale(-1.0 / kt, elastic)
    state["spring"] = spring
    ft = sub(elastic, scale(gammat, slip))
    if norm(ft) > limit:
        ft = scale(limit / norm(ft), ft)
    return add(scale(fn, n), ft), fn


def read_motion(path):
    with open(path, newline="") as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    rows = list(csv.reader(lines))
    if rows[0] != MOTION:
        raise SystemExit(f"{path}: the header is not {','.join(MOTION)}")
    return [[float(x) for x in row] for row in rows[1:]]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case")
    p.add_argument("motion")
    p.add_argument("--out", required=True)
    a = p.parse_args()
    with open(a.case, "rb") as f:
        case = tomllib.load(f)
    r1, r2 = (s["radius"] for s in case["scene"]["sphere"])

    out, state, prev = [], {}, None
    for row in read_motion(a.motion):
        t, x1, q1, x2, q2 = row[0], row[1:4], row[4:8], row[14:17], row[17:21]
        x = sub(x2, x1)
        if prev is None:
            # the first row has no step: its own velocities
            dt, v1, w1, v2, w2, x_old = 0.0, row[8:11], row[11:14], row[21:24], row[24:27], x
        else:
            # the step from the previous row: the velocities of its positions and orientations
            dt = t - prev[0]
            v1, v2 = scale(1.0 / dt, sub(x1, prev[1:4])), scale(1.0 / dt, sub(x2, prev[14:17]))
            w1, w2 = scale(1.0 / dt, turn(q1, prev[4:8])), scale(1.0 / dt, turn(q2, prev[17:21]))
            x_old = sub(prev[14:17], prev[1:4])
        prev = row
        delta = r1 + r2 - norm(x)
        if delta <= 0.0:
            state.clear()  # apart: no force, and the contact's history is forgotten
            out.append([t] + [0.0] * 12 + [delta, 0.0, 0.0])
            continue
        f2, fn = contact_force(case["contact"], r1, r2, x, x_old, sub(v2, v1), w1, w2,
                               dt, state)
        f1 = scale(-1.0, f2)
        # lever arms from each centre to the contact point in the middle of the overlap
        n = scale(1.0 / norm(x), x)
        arm2 = scale(-(r2 - 0.5 * delta), n)
        arm1 = add(x, arm2)
        ft = norm(sub(f2, scale(dot(f2, n), n)))
        out.append([t, *f1, *cross(arm1, f1), *f2, *cross(arm2, f2), delta, fn, ft])

    with open(a.out, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(FORCES)
        w.writerows([[repr(v) for v in row] for row in out])


if __name__ == "__main__":
    main()
