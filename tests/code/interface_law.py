#!/usr/bin/env python3
"""A contact law for `verdem verify --code`, written from docs/code-interface.md alone, as a
developer new to verdem would: a linear spring-dashpot normal force and a tangential spring
with a Coulomb slider, objective (plain Python 3.11 or later, no packages).

    python3 interface_law.py CASE.toml MOTION.csv --out FORCES.csv

Its choices, each within the freedom the page gives:

- time discretisation: the velocities and spins of the row itself (the motion's own), the
  twist from the quaternions of the step's two rows (the rotation vector of q(k) q(k-1)^-1,
  its angle from atan2); the slip is taken at the row's own normal. With `--velocities
  positions`, the step's velocities and spins come from its two rows' positions and
  quaternions instead, still with the slip at the row's normal: a first-order scheme with a
  large error that the page says passes by convergence, within the extrapolation's
  uncertainty;
- frame: the stored spring is projected onto the new tangent plane and given back its length
  (the tilt), then turned about the normal by the mean of the two spheres' turns about it
  (the twist);
- slip: full radii as the spins' arms, the centres' relative velocity scaled by (R1 + R2)/d,
  so that neither a rigid rotation nor a change of overlap feeds it;
- Coulomb: the spring force capped at mu|fn|, the spring reset to the cap while sliding, the
  tangential dashpot added after and the sum capped again;
- torques: both about one contact point, the middle of the overlap on the line of centres.
"""

import argparse
import csv
import math
import tomllib

HEADER = "t,fx1,fy1,fz1,tx1,ty1,tz1,fx2,fy2,fz2,tx2,ty2,tz2,delta,fn,ft"


class V:
    """A 3-vector."""

    __slots__ = ("x", "y", "z")

    def __init__(self, x, y, z):
        self.x, self.y, self.z = x, y, z

    def __add__(self, o):
        return V(self.x + o.x, self.y + o.y, self.z + o.z)

    def __sub__(self, o):
        return V(self.x - o.x, self.y - o.y, self.z - o.z)

    def __mul__(self, s):
        return V(self.x * s, self.y * s, self.z * s)

    __rmul__ = __mul__

    def __neg__(self):
        return V(-self.x, -self.y, -self.z)

    def dot(self, o):
        return self.x * o.x + self.y * o.y + self.z * o.z

    def cross(self, o):
        return V(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z,
                 self.x * o.y - self.y * o.x)

    def length(self):
        return math.sqrt(self.dot(self))

    def along(self, n):
        """The part perpendicular to the unit vector n."""
        return self - n * self.dot(n)

    def values(self):
        return [self.x, self.y, self.z]


ZERO = V(0.0, 0.0, 0.0)


def turn_between(q_new, q_old):
    """The rotation vector (axis times angle) turning orientation q_old into q_new, both unit
    quaternions (w, x, y, z): of q_new * conj(q_old), its angle as 2 atan2(|xyz|, |w|)."""
    aw, ax, ay, az = q_new
    bw, bx, by, bz = q_old[0], -q_old[1], -q_old[2], -q_old[3]
    w = aw * bw - ax * bx - ay * by - az * bz
    v = V(aw * bx + ax * bw + ay * bz - az * by,
          aw * by - ax * bz + ay * bw + az * bx,
          aw * bz + ax * by - ay * bx + az * bw)
    if w < 0.0:
        w, v = -w, -v
    s = v.length()
    if s == 0.0:
        return ZERO
    return v * (2.0 * math.atan2(s, w) / s)


class Sphere:
    """One sphere at one row of the motion."""

    def __init__(self, cols):
        self.x = V(*cols[0:3])
        self.q = tuple(cols[3:7])
        self.v = V(*cols[7:10])
        self.w = V(*cols[10:13])

    def stepped(self, before, turn, dt):
        """This sphere with the velocity and spin of the step from `before`, `dt` earlier,
        over which it turned by `turn` (a rotation vector)."""
        s = Sphere([0.0] * 13)
        s.x, s.q = self.x, self.q
        s.v = (self.x - before.x) * (1.0 / dt)
        s.w = turn * (1.0 / dt)
        return s


class Contact:
    """The law of one contact and its history, the stored spring."""

    def __init__(self, law, r1, r2):
        self.kn, self.gn = law["kn"], law["gamman"]
        self.kt, self.gt = law["kt"], law["gammat"]
        self.mu = law["mu"]
        self.r1, self.r2 = r1, r2
        self.spring = None  # the stored displacement, lab frame; None out of contact

    def forces(self, a, b, dt, turn_a, turn_b):
        """Force and torque on each sphere (a is sphere 1, b sphere 2), the overlap, fn and
        ft. `dt` is the step from the previous row (0 on the first), `turn_a` and `turn_b`
        the spheres' turns over it (rotation vectors); a and b carry the step's velocities."""
        r = b.x - a.x
        d = r.length()
        delta = self.r1 + self.r2 - d
        if delta <= 0.0:
            self.spring = None  # the contact is lost: its history is forgotten
            return ZERO, ZERO, ZERO, ZERO, delta, 0.0, 0.0
        n = r * (1.0 / d)
        if self.spring is None:
            self.spring = ZERO
        else:
            # tilt: onto the new tangent plane, with its length kept
            length = self.spring.length()
            tilted = self.spring.along(n)
            if tilted.length() > 0.0:
                self.spring = tilted * (length / tilted.length())
            # twist: about n by the spheres' mean turn about it
            phi = 0.5 * (turn_a + turn_b).dot(n)
            c, s = math.cos(phi), math.sin(phi)
            self.spring = self.spring * c + n.cross(self.spring) * s
        # the slip velocity: centres scaled by (R1 + R2)/d, spins on full radii
        vrel = (b.v - a.v) * ((self.r1 + self.r2) / d) - (a.w * self.r1 + b.w * self.r2).cross(n)
        slip = vrel.along(n)
        self.spring = self.spring + slip * dt
        fn = self.kn * delta - self.gn * (b.v - a.v).dot(n)
        cap = self.mu * abs(fn)
        elastic = self.spring * (-self.kt)
        if elastic.length() > cap:
            elastic = elastic * (cap / elastic.length())
            self.spring = elastic * (-1.0 / self.kt)  # sliding: the spring sits at the cap
        ft = elastic - slip * self.gt
        if ft.length() > cap:
            ft = ft * (cap / ft.length())
        f2 = n * fn + ft
        f1 = -f2
        # both torques about the middle of the overlap
        point = a.x + n * (self.r1 - 0.5 * delta)
        t1 = (point - a.x).cross(f1)
        t2 = (point - b.x).cross(f2)
        return f1, t1, f2, t2, delta, fn, ft.length()


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case")
    p.add_argument("motion")
    p.add_argument("--out", required=True)
    p.add_argument("--velocities", choices=["rows", "positions"], default="rows")
    args = p.parse_args()
    with open(args.case, "rb") as f:
        case = tomllib.load(f)
    r1, r2 = (s["radius"] for s in case["scene"]["sphere"])
    contact = Contact(case["contact"], r1, r2)
    with open(args.motion, newline="") as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    table = [[float(x) for x in row] for row in list(csv.reader(lines))[1:]]
    out = []
    previous = None
    for cols in table:
        t = cols[0]
        a, b = Sphere(cols[1:14]), Sphere(cols[14:27])
        dt, turn_a, turn_b = 0.0, ZERO, ZERO
        row = (t, a, b)
        if previous is not None:
            t0, a0, b0 = previous
            dt = t - t0
            turn_a, turn_b = turn_between(a.q, a0.q), turn_between(b.q, b0.q)
            if args.velocities == "positions":
                a, b = a.stepped(a0, turn_a, dt), b.stepped(b0, turn_b, dt)
        previous = row
        f1, t1, f2, t2, delta, fn, ft = contact.forces(a, b, dt, turn_a, turn_b)
        out.append([t, *f1.values(), *t1.values(), *f2.values(), *t2.values(), delta, fn, ft])
    with open(args.out, "w") as f:
        f.write(HEADER + "\n")
        for row in out:
            f.write(",".join(repr(x) for x in row) + "\n")


if __name__ == "__main__":
    main()
