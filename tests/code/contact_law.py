#!/usr/bin/env python3
"""An external contact law for `verdem verify --code`: the benchmark's linear spring-dashpot
with MercuryDPM's sliding friction (rate-form tangential spring, spring + dashpot capped at
mu|fn|, lever arms to the contact point in the middle of the overlap), written independently
of verdem in plain Python (3.11 or later, no packages).

    python3 contact_law.py CASE.toml MOTION.csv --out FORCES.csv [--defect NAME]

reads the contact law and the radii from CASE.toml and the motion from MOTION.csv, and writes
the forces and torques at every row (docs/code-interface.md). `--defect` injects a known error,
for the tests to show that `verdem verify --code` catches it:

    rotation  the spring is not turned into the new tangent plane (no rate-form term)
    kt        the tangential stiffness is 10 % too large
    torque    the torques have the wrong sign
    reset     the spring is not reset when the contact opens
"""

import argparse
import csv
import math
import sys
import tomllib

MOTION = ("t x1 y1 z1 qw1 qx1 qy1 qz1 vx1 vy1 vz1 wx1 wy1 wz1 "
          "x2 y2 z2 qw2 qx2 qy2 qz2 vx2 vy2 vz2 wx2 wy2 wz2").split()
FORCES = "t fx1 fy1 fz1 tx1 ty1 tz1 fx2 fy2 fz2 tx2 ty2 tz2 delta fn ft".split()


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(s, a):
    return (s * a[0], s * a[1], s * a[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def qmul(p, q):
    """Hamilton product of quaternions (w, x, y, z)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw)


def rotation_vector(q):
    """Axis times angle of the unit quaternion q (angle in [0, pi]); atan2, not acos, which
    loses digits for the small turns of one step."""
    w, v = q[0], q[1:]
    if w < 0.0:
        w, v = -w, scale(-1.0, v)
    length = norm(v)
    if length == 0.0:
        return (0.0, 0.0, 0.0)
    return scale(2.0 * math.atan2(length, w) / length, v)


def read_motion(path):
    rows = []
    with open(path, newline="") as f:
        reader = csv.reader(line for line in f if line.strip() and not line.startswith("#"))
        if next(reader) != MOTION:
            sys.exit(f"{path}: unexpected header")
        for r in reader:
            v = [float(x) for x in r]
            sphere = []
            for o in (1, 14):
                q = v[o + 3:o + 7]
                length = math.sqrt(sum(c * c for c in q))
                sphere.append((tuple(v[o:o + 3]), tuple(c / length for c in q),
                               tuple(v[o + 7:o + 10]), tuple(v[o + 10:o + 13])))
            rows.append((v[0], sphere))
    return rows


def main():
    p = argparse.ArgumentParser()
    p.add_argument("case")
    p.add_argument("motion")
    p.add_argument("--out", required=True)
    p.add_argument("--defect", choices=["rotation", "kt", "torque", "reset"])
    a = p.parse_args()

    with open(a.case, "rb") as f:
        case = tomllib.load(f)
    c = case["contact"]
    kn, gamman = c["kn"], c["gamman"]
    kt, gammat, mu = c.get("kt", 0.0), c.get("gammat", 0.0), c.get("mu", 0.0)
    clip = c.get("clip_normal", False)
    if a.defect == "kt":
        kt *= 1.1
    diameter = case["material"]["diameter"]
    r1, r2 = (s.get("radius", 0.5 * diameter) for s in case["scene"]["sphere"])

    rows = read_motion(a.motion)
    xi = (0.0, 0.0, 0.0)
    out = []
    for k, (t, s) in enumerate(rows):
        (x1, q1, v1, w1), (x2, q2, v2, w2) = s
        dt = 0.0
        if k > 0:
            # the increment over [t_(k-1), t_k]: velocities from positions and orientations
            tp, sp = rows[k - 1]
            dt = t - tp
            v1 = scale(1.0 / dt, sub(x1, sp[0][0]))
            v2 = scale(1.0 / dt, sub(x2, sp[1][0]))
            conj = lambda q: (q[0], -q[1], -q[2], -q[3])
            w1 = scale(1.0 / dt, rotation_vector(qmul(q1, conj(sp[0][1]))))
            w2 = scale(1.0 / dt, rotation_vector(qmul(q2, conj(sp[1][1]))))
        r = sub(x2, x1)
        dist = norm(r)
        delta = r1 + r2 - dist
        if dist * dist >= (r1 + r2) ** 2:
            if a.defect != "reset":
                xi = (0.0, 0.0, 0.0)
            out.append([t] + [0.0] * 12 + [delta, 0.0, 0.0])
            continue
        n = scale(1.0 / dist, r)
        # lever arms from each centre to the contact point in the middle of the overlap
        arm2 = scale(-(r2 - 0.5 * delta), n)
        arm1 = add(r, arm2)
        vrel = sub(add(v2, cross(w2, arm2)), add(v1, cross(w1, arm1)))
        vn = dot(vrel, n)
        vt = sub(vrel, scale(vn, n))
        fn = kn * delta - gamman * vn  # linear spring-dashpot, MercuryDPM
        if clip:
            fn = max(fn, 0.0)
        ft = (0.0, 0.0, 0.0)
        if mu > 0.0:
            # MercuryDPM's rate form: d(xi)/dt = vt - n (xi . v_centres) / dist
            rate = vt
            if a.defect != "rotation":
                rate = sub(vt, scale(dot(xi, sub(v2, v1)) / dist, n))
            xi = add(xi, scale(dt, rate))
            ft = scale(-1.0, add(scale(kt, xi), scale(gammat, vt)))
            fcrit = mu * abs(fn)
            if dot(ft, ft) > fcrit * fcrit:
                ft = scale(fcrit / norm(ft), ft)
                xi = scale(-1.0 / kt, add(ft, scale(gammat, vt)))
        f2 = add(scale(fn, n), ft)
        f1 = scale(-1.0, f2)
        sign = -1.0 if a.defect == "torque" else 1.0
        t1 = scale(sign, cross(arm1, f1)) if mu > 0.0 else (0.0, 0.0, 0.0)
        t2 = scale(sign, cross(arm2, f2)) if mu > 0.0 else (0.0, 0.0, 0.0)
        out.append([t, *f1, *t1, *f2, *t2, delta, fn, norm(ft)])

    with open(a.out, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(FORCES)
        for row in out:
            w.writerow([repr(v) for v in row])


if __name__ == "__main__":
    main()
