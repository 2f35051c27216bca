# The body of every Yade input verdem generates (src/peers/yade.rs writes the dictionary P
# above it). Run as `yade -jN -n -x in.yade.py` inside the folder of the run.
#
# The law: ViscElMat / Ip2_ViscElMat_ViscElMat_ViscElPhys / Law2_ScGeom_ViscElPhys_Basic, a linear
# spring-dashpot with absolute damping. Ip2 combines the two materials' values in series,
# a1 a2 / (a1 + a2) (contactParameterCalculation in pkg/dem/ViscoelasticPM.cpp), so every
# material value is twice the per-contact value; check_law() reads the values of the first
# contacts back and stops the run if they differ from the case's.
#
# The step: Yade's leapfrog (v += F/m dt; x += v dt, NewtonIntegrator) is verdem's kick-drift-
# kick with the two half kicks of a step merged, provided the velocities are those of the half
# step. The state comes with full-step velocities v(0), so the first step's forces F(0) are
# computed with them (as verdem's set-up evaluation, which also advances the springs) and the
# velocities are then moved back by F(0) dt/2m before Yade's first kick (first_half_kick).
#
# A save of step n (save.n.txt, contacts.n.txt) is taken after the forces of step n and before
# the kick: positions, contacts and forces of the same instant, velocities converted to full
# step by adding F(n) dt/2m (and T(n) dt/2I).
#
# In-run dumps (contact_every > 0), taken at the same instant by the same runner: every
# contact_every steps the contacts (contacts.n.txt, as a save's) and the positions of the bodies
# they join (positions.n.txt), every particle_every steps all bodies (particles.n.txt, as
# save.n.txt). Every step a runner between the InteractionLoop and the NewtonIntegrator (the
# forces of that step, before the ForceResetter of the next) adds the force on each wall's
# bodies (O.forces: the force on the body) to a running sum, and every contact_every = K steps
# writes its mean to walls.txt: at step n, the mean over steps n - K + 1..n of the bottom wall's
# force (x, y, z), then the top wall's, as the LAMMPS family's `fix ave/time`.
import math
import time

KIND_FREE = 0
FREE_MASK, WALL_MASK, AVOID_MASK = 0b011, 0b110, 0b100


def read_state(path):
    """Rows (kind, radius, x, v, w) of the state file, in id order."""
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            c = line.split()
            n = [float(t) for t in c[1:]]
            rows.append((int(c[0]), n[0], n[1:4], n[4:7], n[7:10]))
    return rows


def cell_edges(rows):
    """The periodic cell: the box's edges along its periodic axes; along the others (a Yade cell
    is periodic in all three) the spheres' span plus four largest diameters, so that nothing
    meets across them."""
    dmax = 2.0 * max(r[1] for r in rows)
    edges = []
    for k in range(3):
        box = P["hi"][k] - P["lo"][k]
        if P["periodic"][k]:
            edges.append(box)
        else:
            xs = [r[2][k] for r in rows]
            edges.append(max(max(xs) - min(xs), box) + 4.0 * dmax)
    return edges


# The ids of the bottom [0] and top [1] walls' bodies.
WALL_IDS = ([], [])


def build_scene(rows):
    if any(P["periodic"]):
        O.periodic = True
        O.cell.setBox(*cell_edges(rows))
    # per-contact values: springs and dashpots in series, a1 a2 / (a1 + a2) = a for a1 = a2 = 2a
    mat = O.materials.append(ViscElMat(
        kn=2.0 * P["kn"], cn=2.0 * P["gamman"], ks=2.0 * P["kt"], cs=2.0 * P["gammat"],
        frictionAngle=math.atan(P["mu"]), density=P["density"]))
    for (kind, r, x, v, w) in rows:
        b = utils.sphere(tuple(x), r, material=mat)
        b.state.vel = Vector3(*v)
        b.state.angVel = Vector3(*w)
        if kind == KIND_FREE:
            b.groupMask = FREE_MASK
        else:
            # moved rigidly at its velocity, never integrated: infinite mass
            b.groupMask = WALL_MASK
            b.state.blockedDOFs = "xyzXYZ"
            if P["wall_vx"] is not None:
                b.state.vel = Vector3(P["wall_vx"][kind - 1], 0.0, 0.0)
                b.state.angVel = Vector3(0.0, 0.0, 0.0)
        i = O.bodies.append(b)
        if kind != KIND_FREE:
            WALL_IDS[kind - 1].append(i)


CHECKED = []


def check_law(phys):
    """Stops the run unless the contact's values are the case's (to 1e-12)."""
    if CHECKED:
        return
    got = (phys.kn, phys.cn, phys.ks, phys.cs, phys.tangensOfFrictionAngle)
    want = (P["kn"], P["gamman"], P["kt"], P["gammat"], P["mu"])
    for name, g, w in zip(("kn", "cn", "ks", "cs", "tan(frictionAngle)"), got, want):
        if abs(g - w) > 1e-12 * abs(w):
            raise RuntimeError("contact parameter %s = %r, the case's is %r" % (name, g, w))
    CHECKED.append(True)


def half_step(n):
    """dt/2 after the first kick, 0 before it (the state then has full-step velocities)."""
    return 0.0 if n == 0 else 0.5 * O.dt


def first_half_kick():
    h = 0.5 * O.dt
    for b in O.bodies:
        if b.groupMask == FREE_MASK:
            s = b.state
            s.vel = s.vel - O.forces.f(b.id) * (h / s.mass)
            t = O.forces.t(b.id)
            s.angVel = Vector3(*[s.angVel[k] - t[k] * h / s.inertia[k] for k in range(3)])
    kick.dead = True


def wrapped(x):
    """x with its periodic coordinates in [lo, hi)."""
    out = list(x)
    for k in range(3):
        if P["periodic"][k]:
            lo, length = P["lo"][k], P["hi"][k] - P["lo"][k]
            out[k] = x[k] - length * math.floor((x[k] - lo) / length)
            if out[k] >= P["hi"][k]:
                out[k] -= length
    return out


def contact_force(I):
    """Force on id1 and the spring of id1 (length) of a Law2_ScGeom_ViscElPhys_Basic contact, as
    the law computed it this step: the elastic part is stored (phys.shearForce, on id2); the
    dashpot cs vs was added unless the elastic part reached mu |Fn|."""
    g, ph = I.geom, I.phys
    s1, s2 = O.bodies[I.id1].state, O.bodies[I.id2].state
    # the velocities are those the law saw: a save runs before the kicks of its step
    shift = O.cell.hSize * Vector3(*I.cellDist) if O.periodic else Vector3(0, 0, 0)
    c1 = g.contactPoint - s1.pos
    c2 = g.contactPoint - s2.pos - shift
    rel = (s1.vel + s1.angVel.cross(c1)) - (s2.vel + s2.angVel.cross(c2))
    vs = rel - g.normal.dot(rel) * g.normal
    elastic = ph.shearForce
    cap = ph.normalForce.squaredNorm() * ph.tangensOfFrictionAngle ** 2
    sliding = elastic.squaredNorm() >= cap * (1.0 - 1e-12)
    total = ph.normalForce + elastic + (Vector3(0, 0, 0) if sliding else ph.cs * vs)
    return -total, elastic / ph.ks


def write_bodies(path, n):
    """All bodies of step n in id order: radius, wrapped position, full-step velocities (one
    formatted line per body, written at once: the cost of an in-run dump is mostly here)."""
    h = half_step(n)
    line = " ".join(["%r"] * 10) + "\n"
    lines = ["# step %d: radius x y z vx vy vz wx wy wz (full-step velocities)\n" % n]
    forces = O.forces
    for b in O.bodies:
        s = b.state
        v, w = s.vel, s.angVel
        if b.groupMask == FREE_MASK:
            v = v + forces.f(b.id) * (h / s.mass)
            t, i = forces.t(b.id), s.inertia
            w = Vector3(w[0] + t[0] * h / i[0], w[1] + t[1] * h / i[1], w[2] + t[2] * h / i[2])
        x = wrapped(s.pos)
        lines.append(line % (b.shape.radius, x[0], x[1], x[2], v[0], v[1], v[2], w[0], w[1], w[2]))
    with open(path, "w") as f:
        f.writelines(lines)


def write_contacts(n):
    """The contacts of step n (contacts.n.txt); returns the ids of the bodies they join."""
    ids = set()
    with open("contacts.%d.txt" % n, "w") as f:
        f.write("# step %d: id1 id2 (0-based) force on id1, spring of id1 (length)\n" % n)
        for I in O.interactions:
            if not I.isReal or I.geom.penetrationDepth <= 0:
                continue
            check_law(I.phys)
            force, spring = contact_force(I)
            f.write("%d %d %s\n" % (I.id1, I.id2, " ".join(
                repr(float(q)) for q in list(force) + list(spring))))
            ids.add(I.id1)
            ids.add(I.id2)
    return ids


def write_positions(n, ids):
    """The wrapped positions of the bodies `ids` at step n (positions.n.txt), by id."""
    with open("positions.%d.txt" % n, "w") as f:
        f.write("# step %d: id (0-based) x y z of every body in contact\n" % n)
        for i in sorted(ids):
            x = wrapped(O.bodies[i].state.pos)
            f.write("%d %s\n" % (i, " ".join(repr(float(q)) for q in x)))


def dump():
    """The saves every `every` steps and the in-run dumps (see the top of this file)."""
    n = O.iter
    save = n % P["every"] == 0
    sample = P["contact_every"] > 0 and n % P["contact_every"] == 0
    if save:
        write_bodies("save.%d.txt" % n, n)
    if save or sample:
        ids = write_contacts(n)
    if sample:
        write_positions(n, ids)
        if n % P["particle_every"] == 0:
            write_bodies("particles.%d.txt" % n, n)


AXES = (Vector3(1, 0, 0), Vector3(0, 1, 0), Vector3(0, 0, 1))
WALL_SUMS = [0.0] * 6


def walls():
    """Adds this step's force on each wall's bodies (utils.sumForces, summed in C++) to
    WALL_SUMS; every contact_every steps appends their mean to walls.txt and restarts them. The
    set-up forces of iteration 0 belong to no step."""
    n = O.iter
    if n == 0:
        with open("walls.txt", "w") as f:
            f.write("# step, then the mean over the last %d steps of the force on the bottom wall "
                    "(fx fy fz), then on the top wall\n" % P["contact_every"])
        return
    for g, ids in enumerate(WALL_IDS):
        for k, axis in enumerate(AXES):
            WALL_SUMS[3 * g + k] += utils.sumForces(ids, axis)
    if n % P["contact_every"] == 0:
        k = float(P["contact_every"])
        with open("walls.txt", "a") as f:
            f.write("%d %s\n" % (n, " ".join(repr(s / k) for s in WALL_SUMS)))
        WALL_SUMS[:] = [0.0] * 6


FORCE_STEPS = []


def watch():
    """Counts the steps with a positive normal force (the collision's duration)."""
    for I in O.interactions:
        if I.isReal and I.geom.penetrationDepth > 0:
            check_law(I.phys)
            if I.phys.normalForce.squaredNorm() > 0.0:
                FORCE_STEPS.append(O.iter)


build_scene(read_state(P["state"]))
O.dt = P["dt"]
engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb()], avoidSelfInteractionMask=AVOID_MASK,
                          verletDist=P["verlet"]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_ViscElMat_ViscElMat_ViscElPhys()],
                    [Law2_ScGeom_ViscElPhys_Basic()]),
]
if P["contact_every"] > 0:
    engines.append(PyRunner(command="walls()", iterPeriod=1, initRun=True))
if P["every"] > 0:
    period = P["contact_every"] if P["contact_every"] > 0 else P["every"]
    engines.append(PyRunner(command="dump()", iterPeriod=period, initRun=True))
if P["collision"]:
    engines.append(PyRunner(command="watch()", iterPeriod=1, initRun=True))
engines.append(PyRunner(command="first_half_kick()", iterPeriod=1, initRun=True, label="kick"))
engines.append(NewtonIntegrator(damping=0.0, gravity=Vector3(*P["gravity"])))
O.engines = engines

# with saves, one more iteration computes the forces of the last save
iterations = P["steps"] + (1 if P["every"] > 0 else 0)
start = time.perf_counter()
if iterations > 0:  # O.run(0) would run for ever
    O.run(iterations, True)
seconds = time.perf_counter() - start
if O.iter != iterations:
    raise RuntimeError("Yade stopped at iteration %d of %d" % (O.iter, iterations))
if P["collision"]:
    with open("force_duration.txt", "w") as f:
        f.write("%d %r\n" % (len(FORCE_STEPS), len(FORCE_STEPS) * O.dt))
print("verdem: loop seconds %r for %d iterations on %d threads" % (seconds, iterations,
                                                                   O.numThreads))
