# Kratos DEM driver written by verdem: runs a verdem state (an MDPA file) under the settings of
# kratos.json (written by verdem from a case) and writes its saves as dump.STEP.txt in the
# LAMMPS dump layout that verdem reads (id type radius x y z vx vy vz omegax omegay omegaz).
#
# Started as `python verdem_kratos.py` in the run folder, with Kratos' own output sent to
# kratos.log by verdem. Prints one line `verdem-kratos loop seconds: T` with the wall time of
# the solution loop (without reading the state and setting up).
#
# Parameter mapping (Kratos DEMApplication 10.4.4, custom_constitutive/):
# - law DEM_D_Linear_Custom_Constants (DEM_D_Linear_custom_constants_CL.cpp,
#   InitializeContact): kn = K_NORMAL, kt = K_TANGENTIAL of the contact's material relation;
# - normal and tangential dashpots from DEM_D_Linear_viscous_Coulomb::CalculateViscoDampingForce
#   (DEM_D_Linear_viscous_Coulomb_CL.cpp): 2 * DAMPING_GAMMA * sqrt(m_eq * kn) and
#   2 * DAMPING_GAMMA * sqrt(m_eq * kt), m_eq = m1 m2 / (m1 + m2) of the two spheres' own masses
#   (a sphere with imposed velocity keeps its mass here). With equal masses m_eq = m/2 for every
#   pair, so DAMPING_GAMMA = gamman / (2 sqrt(m/2 * kn)) gives the absolute normal damping
#   gamman; the tangential one is then gamman * sqrt(kt/kn), not gammat;
# - DAMPING_GAMMA is overwritten after set-up: SphereStrategy.ModifySubProperties
#   (sphere_strategy.py) derives it from COEFFICIENT_OF_RESTITUTION by bisection;
# - normal force clipped at 0 (CalculateForces: normal_contact_force < 0 -> 0);
# - Coulomb: |elastic + viscous tangential force| <= mu * Fn, STATIC_FRICTION =
#   DYNAMIC_FRICTION = mu (CalculateTangentialForceWithNeighbour, DEM_D_Linear_viscous_Coulomb_CL.h);
# - spheres of the state's wall groups get their VELOCITY and ANGULAR_VELOCITY fixed at the
#   state's values: the integration scheme then moves them at that velocity and never
#   integrates them;
# - periodic box: PeriodicDomainOption with the BoundingBox corners (all three directions:
#   Kratos has no per-direction option); a direction that is not periodic is given a period
#   larger than the state's extent by `margin` on each side, so no sphere meets an image in it.

import json
import math
import os
import sys
import time

import KratosMultiphysics as K
import KratosMultiphysics.DEMApplication as DEM
from KratosMultiphysics.DEMApplication.DEM_analysis_stage import DEMAnalysisStage

S = json.load(open("kratos.json"))
PROBLEM = "verdem"
MDPA = PROBLEM + "DEM.mdpa"
GROUPS = ("free", "bottom", "top")


def box(nodes):
    """The periodic box: the state's box in its periodic directions, widened elsewhere."""
    lo, hi = list(S["lo"]), list(S["hi"])
    for k in range(3):
        if not S["periodic"][k]:
            c = [n[k] for n in nodes]
            lo[k] = min(lo[k], min(c)) - S["margin"]
            hi[k] = max(hi[k], max(c)) + S["margin"]
    return lo, hi


def read_mdpa(path):
    """Positions of the MDPA's nodes, in order, and the names of its sub-model parts."""
    nodes, groups, block = [], [], None
    for line in open(path):
        f = line.split()
        if line.startswith("Begin "):
            block = f[1]
            if f[1] == "SubModelPart":
                groups.append(f[2])
        elif line.startswith("End "):
            block = None
        elif block == "Nodes":
            nodes.append([float(f[1]), float(f[2]), float(f[3])])
    return nodes, groups


def materials(groups):
    """MaterialsDEM.json: one material for every group, the law on their relation."""
    law = {
        "DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME": "DEM_D_Linear_Custom_Constants",
        "K_NORMAL": S["kn"],
        "K_TANGENTIAL": S["kt"],
        "STATIC_FRICTION": S["mu"],
        "DYNAMIC_FRICTION": S["mu"],
        "FRICTION_DECAY": 500.0,
        "COEFFICIENT_OF_RESTITUTION": 0.5,
        "ROLLING_FRICTION": 0.0,
        "ROLLING_FRICTION_WITH_WALLS": 0.0,
        "DEM_ROLLING_FRICTION_MODEL_NAME": "DEMRollingFrictionModelBounded",
    }
    return {
        "materials": [{
            "material_name": "sphere",
            "material_id": 1,
            "Variables": {
                "PARTICLE_DENSITY": S["density"],
                "YOUNG_MODULUS": 1.0,
                "POISSON_RATIO": 0.0,
                "PARTICLE_SPHERICITY": 1.0,
                "K_NORMAL": S["kn"],
                "K_TANGENTIAL": S["kt"],
            },
        }],
        "material_relations": [{
            "material_names_list": ["sphere", "sphere"],
            "material_ids_list": [1, 1],
            "Variables": law,
        }],
        "material_assignation_table": [["SpheresPart." + g, "sphere"] for g in groups],
    }


def parameters(lo, hi):
    p = {
        "Dimension": 3,
        "PeriodicDomainOption": True,
        "BoundingBoxOption": False,
        "BoundingBoxMinX": lo[0], "BoundingBoxMinY": lo[1], "BoundingBoxMinZ": lo[2],
        "BoundingBoxMaxX": hi[0], "BoundingBoxMaxY": hi[1], "BoundingBoxMaxZ": hi[2],
        "dem_inlet_option": False,
        "GravityX": 0.0, "GravityY": 0.0, "GravityZ": 0.0,
        "RotationOption": True,
        "RollingFrictionOption": False,
        "GlobalDamping": 0.0,
        "CleanIndentationsOption": False,
        "DeltaOption": "Absolute",
        "SearchTolerance": S["skin"],
        # a search every step: Kratos' trajectories change with a rarer search (by ~1e-5 in
        # 100 steps of the shear case at 5 or 50 steps between searches), more than round-off
        "NeighbourSearchFrequency": 1,
        "ElementType": "SphericPartDEMElement3D",
        "TranslationalIntegrationScheme": "Symplectic_Euler",
        "RotationalIntegrationScheme": "Direct_Integration",
        "AutomaticTimestep": False,
        "MaxTimeStep": S["dt"],
        "FinalTime": S["dt"] * (S["steps"] + 1),
        "GraphExportFreq": 1e30, "VelTrapGraphExportFreq": 1e30, "OutputTimeStep": 1e30,
        "ControlTime": 1e30,
        "do_print_results_option": False,
        "post_gid_option": False,
        "echo_level": 0,
        "problem_name": PROBLEM,
        "solver_settings": {
            "RemoveBallsInitiallyTouchingWalls": False,
            "strategy": "sphere_strategy",
            "material_import_settings": {"materials_filename": "MaterialsDEM.json"},
        },
    }
    return K.Parameters(json.dumps(p))


class Stage(DEMAnalysisStage):
    """The DEM analysis stopped after exactly S["steps"] steps, saving every S["every"] (one
    step more when it saves: a save is completed by the step after it)."""

    def KeepAdvancingSolutionLoop(self):
        return self.verdem_step < S["steps"] + (1 if S["every"] else 0)

    def FinalizeSolutionStep(self):
        super().FinalizeSolutionStep()
        self.verdem_step += 1
        if S["count_contact"] and self.verdem_step <= S["steps"] and overlap(self.spheres_model_part):
            self.verdem_contact_steps += 1
        if self.verdem_pending is not None:
            save(self, self.verdem_pending)
            self.verdem_pending = None
        if S["every"] and self.verdem_step % S["every"] == 0 and self.verdem_step <= S["steps"]:
            self.verdem_pending = record(self)


def overlap(mp):
    """Whether nodes 1 and 2 (a collision's pair) overlap."""
    a, b = mp.GetNode(1), mp.GetNode(2)
    d = math.sqrt((a.X - b.X) ** 2 + (a.Y - b.Y) ** 2 + (a.Z - b.Z) ** 2)
    return d < a.GetSolutionStepValue(K.RADIUS) + b.GetSolutionStepValue(K.RADIUS)


def record(stage):
    """The step, positions and velocities of every sphere by id, to be saved after the next
    step."""
    nodes = sorted(stage.spheres_model_part.Nodes, key=lambda n: n.Id)
    rows = []
    for n in nodes:
        v = n.GetSolutionStepValue(K.VELOCITY)
        w = n.GetSolutionStepValue(K.ANGULAR_VELOCITY)
        rows.append((n.Id, n.GetSolutionStepValue(K.RADIUS), n.X, n.Y, n.Z,
                     v[0], v[1], v[2], w[0], w[1], w[2]))
    return stage.verdem_step, rows


def save(stage, pending):
    """dump.STEP.txt of a recorded step: every sphere by id, floats written to round-trip.
    Kratos' symplectic Euler step moves a sphere with the velocity it has after the step's
    kick, u(k+1) = u(k) + F(k) dt/m: the velocity at the save's own time is the mean
    (u(k) + u(k+1))/2 of the recorded and the present velocities (angular ones alike)."""
    step, rows = pending
    lo, hi = stage.verdem_box
    out = ["ITEM: TIMESTEP", str(step), "ITEM: NUMBER OF ATOMS", str(len(rows)),
           "ITEM: BOX BOUNDS pp pp pp"]
    out += ["%r %r" % (lo[k], hi[k]) for k in range(3)]
    out.append("ITEM: ATOMS id type radius x y z vx vy vz omegax omegay omegaz")
    mp = stage.spheres_model_part
    for row in rows:
        n = mp.GetNode(row[0])
        v = n.GetSolutionStepValue(K.VELOCITY)
        w = n.GetSolutionStepValue(K.ANGULAR_VELOCITY)
        now = (v[0], v[1], v[2], w[0], w[1], w[2])
        mean = [0.5 * (a + b) for a, b in zip(row[5:], now)]
        out.append(" ".join([str(row[0]), str(stage.verdem_type[row[0]])]
                            + [repr(float(x)) for x in list(row[1:5]) + mean]))
    with open("dump.%d.txt.tmp" % step, "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace("dump.%d.txt.tmp" % step, "dump.%d.txt" % step)


def half_kick_back(mp, m, radius):
    """Kratos' scheme starts from the half-step velocity u(0) = v(0) - F(0) dt/(2m) (and
    w(0) - T(0) dt/(2I), I = 2/5 m r^2): the state's forces, written by verdem beside the state
    as STATE.forces.txt, turn its velocities into those, for the free spheres."""
    path = S["state"][: -len(".mdpa")] + ".forces.txt"
    if not os.path.exists(path):
        return
    inertia = 0.4 * m * radius ** 2
    free = {n.Id for n in mp.GetSubModelPart("free").Nodes} if mp.HasSubModelPart("free") else set()
    for line in open(path):
        f = line.split()
        node = int(f[0])
        if node not in free:
            continue
        n = mp.GetNode(node)
        for k, var in enumerate((K.VELOCITY_X, K.VELOCITY_Y, K.VELOCITY_Z)):
            n.SetSolutionStepValue(var, n.GetSolutionStepValue(var) - float(f[1 + k]) * S["dt"] / (2.0 * m))
        for k, var in enumerate((K.ANGULAR_VELOCITY_X, K.ANGULAR_VELOCITY_Y, K.ANGULAR_VELOCITY_Z)):
            n.SetSolutionStepValue(var, n.GetSolutionStepValue(var) - float(f[4 + k]) * S["dt"] / (2.0 * inertia))


def main():
    if not os.path.exists(MDPA) or not os.path.samefile(S["state"], MDPA):
        with open(S["state"]) as src, open(MDPA, "w") as dst:
            dst.write(src.read())
    nodes, groups = read_mdpa(MDPA)
    with open("MaterialsDEM.json", "w") as f:
        json.dump(materials(groups), f, indent=1)
    lo, hi = box(nodes)
    stage = Stage(K.Model(), parameters(lo, hi))
    stage.verdem_step = 0
    stage.verdem_contact_steps = 0
    stage.verdem_box = (lo, hi)
    stage.Initialize()
    mp = stage.spheres_model_part
    stage.verdem_type = {}
    for t, g in enumerate(GROUPS, start=1):
        if mp.HasSubModelPart(g):
            for n in mp.GetSubModelPart(g).Nodes:
                stage.verdem_type[n.Id] = t
                if g != "free":
                    for var in (K.VELOCITY_X, K.VELOCITY_Y, K.VELOCITY_Z,
                                K.ANGULAR_VELOCITY_X, K.ANGULAR_VELOCITY_Y, K.ANGULAR_VELOCITY_Z):
                        n.Fix(var)
    masses = {round(e.GetGeometry()[0].GetSolutionStepValue(K.RADIUS), 15) for e in mp.Elements}
    if len(masses) != 1:
        sys.exit("verdem-kratos: spheres of %d radii; Kratos' dashpot 2*DAMPING_GAMMA*sqrt(m_eq*kn) "
                 "is the absolute damping gamman only when every sphere has the same mass" % len(masses))
    radius = masses.pop()
    m = S["density"] * 4.0 / 3.0 * math.pi * radius ** 3
    gamma = S["gamman"] / (2.0 * math.sqrt(0.5 * m * S["kn"]))
    for p in mp.Properties:
        for sub in p.GetSubProperties():
            sub.SetValue(DEM.DAMPING_GAMMA, gamma)
    half_kick_back(mp, m, radius)
    stage.verdem_pending = record(stage) if S["every"] else None
    start = time.perf_counter()
    stage.RunSolutionLoop()
    seconds = time.perf_counter() - start
    stage.Finalize()
    if S["count_contact"]:
        with open("contact_steps.txt", "w") as f:
            f.write("%d\n" % stage.verdem_contact_steps)
    print("verdem-kratos loop seconds: %r" % seconds, flush=True)


main()
