#!/usr/bin/env python3
"""Writes the articulation scenes (docs/articulation.md): pendulum, chain_hanging, loop_six,
pd_arm, ragdoll_pile, twisting_chain_rigid and the 2-D pendulum_2d and chain_2d. Run from this folder: python3 generate_articulation_scenes.py"""
import json
import math


def quat_z(angle):
    return [math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)]


def quat_from_z_to(v):
    """Unit quaternion [w, x, y, z] turning +z onto the unit vector v."""
    z = (0.0, 0.0, 1.0)
    c = sum(a * b for a, b in zip(z, v))
    if c < -1 + 1e-12:
        return [0.0, 1.0, 0.0, 0.0]
    axis = (z[1] * v[2] - z[2] * v[1], z[2] * v[0] - z[0] * v[2], z[0] * v[1] - z[1] * v[0])
    w = 1 + c
    n = math.sqrt(w * w + sum(a * a for a in axis))
    return [w / n] + [a / n for a in axis]


def r(v, digits=12):
    return [round(x, digits) for x in v]


def write(name, header, scene):
    with open(name + ".json", "w") as f:
        for line in header.strip().splitlines():
            f.write("// " + line + "\n")
        f.write(json.dumps(scene, indent=1))
        f.write("\n")


def pendulum():
    # A rod (box 1 m long) with a bob (sphere) fixed to its end, hinged to the world at the top.
    a = math.radians(5)
    down = (math.sin(a), -math.cos(a), 0.0)
    rod_c = [0.5 * x for x in down]
    bob_c = [1.0 * x for x in down]
    q = quat_z(a)
    scene = {
        "description": "rod and bob pendulum on a revolute joint, 5 degree amplitude",
        "dimension": 3,
        "time": {"dt": 1 / 240, "end": 10.0, "frame_rate": 30},
        "gravity": [0, -9.81, 0],
        "entities": [
            {"name": "rod", "shape": {"type": "box", "half_extents": [0.01, 0.5, 0.01]},
             "rigid_body": {"mass": 1.0, "position": r(rod_c), "orientation": r(q)},
             "joint": {"type": "revolute", "parent": "world", "anchor": [0, 0, 0], "axis": [0, 0, 1]}},
            {"name": "bob", "shape": {"type": "sphere", "radius": 0.1},
             "rigid_body": {"mass": 2.0, "position": r(bob_c), "orientation": r(q)},
             "joint": {"type": "fixed", "parent": "rod", "anchor": r(bob_c)}},
        ],
    }
    write("pendulum", """
Pendulum (thesis Sec. 4.5, App. C): a 1 m rod (1 kg) with a 2 kg ball fixed to its end by a
fixed joint, hinged to the world at the top by a revolute joint, released at 5 degrees. Its
period is 2 pi sqrt(I_pivot / (m g d)) to 0.05 % at this amplitude.""", scene)


def chain_hanging():
    n, length, radius = 20, 0.1, 0.01
    q = quat_from_z_to((1.0, 0.0, 0.0))
    entities = []
    for i in range(n):
        entities.append({
            "name": "link%d" % i,
            "shape": {"type": "capsule", "radius": radius, "half_height": 0.5 * length - radius},
            "rigid_body": {"mass": 0.1, "position": [(i + 0.5) * length, 0, 0], "orientation": r(q)},
            "joint": {"type": "spherical", "parent": "world" if i == 0 else "link%d" % (i - 1),
                      "anchor": [i * length, 0, 0]},
        })
    entities.append({"name": "solver", "articulation": {"post_stabilization": "global", "pre_stabilization": "global"}})
    scene = {"description": "20-link chain on spherical joints released horizontally",
             "dimension": 3, "time": {"dt": 1 / 240, "end": 2.0, "frame_rate": 30},
             "gravity": [0, -9.81, 0], "entities": entities}
    write("chain_hanging", """
A chain of 20 capsule links (0.1 m, 0.1 kg) on spherical joints, the first pinned to the world,
released horizontally. No colliders: the links swing through each other. Joints solved globally
(App. C): pairwise Gauss-Seidel needs hundreds of sweeps on a chain this long.""", scene)


def loop_six():
    n, side, radius = 6, 0.2, 0.02
    height = 0.3
    verts = [(side * math.cos(2 * math.pi * k / n), height, side * math.sin(2 * math.pi * k / n)) for k in range(n)]
    entities = [{"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": True},
                 "collider": {"restitution": 0.0, "friction": 0.5}}]
    gap = 2.5 * radius  # capsule ends stop short of the joint: jointed neighbours never touch
    for k in range(n):
        a, b = verts[k], verts[(k + 1) % n]
        d = [b[i] - a[i] for i in range(3)]
        ln = math.sqrt(sum(x * x for x in d))
        u = [x / ln for x in d]
        c = [(a[i] + b[i]) / 2 for i in range(3)]
        entities.append({
            "name": "bar%d" % k,
            "shape": {"type": "capsule", "radius": radius, "half_height": 0.5 * ln - gap - radius},
            "rigid_body": {"mass": 0.2, "position": r(c), "orientation": r(quat_from_z_to(u)),
                           "angular_velocity": [0.0, 0.0, 0.0]},
            "collider": {"restitution": 0.0, "friction": 0.5},
            "joint": {"type": "spherical", "parent": "bar%d" % ((k - 1) % n), "anchor": r(a)},
        })
    scene = {"description": "closed loop of six bars on spherical joints dropped on the ground",
             "dimension": 3, "time": {"dt": 1 / 120, "end": 2.0, "frame_rate": 30},
             "gravity": [0, -9.81, 0], "entities": entities}
    write("loop_six", """
A closed loop of six capsule bars (hexagon of side 0.2 m) on spherical joints, the first bar's
joint closing the loop onto the last, dropped 0.3 m onto the ground. The bars' ends stop short of
the joints so that jointed neighbours never touch.""", scene)


def pd_arm():
    length, q = 0.5, quat_from_z_to((1.0, 0.0, 0.0))
    mass = 1.0
    # Effective inertia of the straight arm about the shoulder: both links.
    i_link = mass * length * length / 12
    inertia = (i_link + mass * (length / 2) ** 2) + (i_link + mass * (1.5 * length) ** 2)
    wn, zeta = 2 * math.pi, 0.3
    kp = inertia * wn * wn
    kd = 2 * zeta * math.sqrt(kp * inertia)
    # The elbow held straight by a drive ten times faster, critically damped (about its own link).
    i_elbow = i_link + mass * (length / 2) ** 2
    kp2 = i_elbow * (10 * wn) ** 2
    kd2 = 2 * math.sqrt(kp2 * i_elbow)
    entities = [
        {"name": "upper", "shape": {"type": "box", "half_extents": [0.02, 0.02, length / 2]},
         "rigid_body": {"mass": mass, "position": [length / 2, 0, 0], "orientation": r(q)},
         "joint": {"type": "revolute", "parent": "world", "anchor": [0, 0, 0], "axis": [0, 0, 1],
                   "pd": {"kp": round(kp, 9), "kd": round(kd, 9), "target": 0.5}}},
        {"name": "fore", "shape": {"type": "box", "half_extents": [0.02, 0.02, length / 2]},
         "rigid_body": {"mass": mass, "position": [1.5 * length, 0, 0], "orientation": r(q)},
         "joint": {"type": "revolute", "parent": "upper", "anchor": [length, 0, 0], "axis": [0, 0, 1],
                   "pd": {"kp": round(kp2, 9), "kd": round(kd2, 9), "target": 0.0}}},
    ]
    scene = {"description": "two-link arm: PD drive of the shoulder to 0.5 rad, elbow held straight",
             "dimension": 3, "time": {"dt": 1 / 1000, "end": 4.0, "frame_rate": 50},
             "gravity": [0, 0, 0], "entities": entities}
    write("pd_arm", """
A two-link arm (two 0.5 m, 1 kg bars) in a horizontal plane, no gravity. The shoulder's PD drive
steps to 0.5 rad with gains for a 1 Hz natural frequency and damping ratio 0.3 about the straight
arm's inertia (%.6f kg m^2): overshoot exp(-pi z / sqrt(1 - z^2)) = %.4f. The elbow's drive
(10x faster, critically damped) keeps it straight.""" % (inertia, math.exp(-math.pi * zeta / math.sqrt(1 - zeta * zeta))),
          scene)


def ragdoll_pile():
    entities = [{"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": True},
                 "collider": {"restitution": 0.0, "friction": 0.6}}]
    col = {"restitution": 0.0, "friction": 0.6}
    y_axis = quat_from_z_to((0.0, 1.0, 0.0))
    count = 0
    for k in range(20):
        ox = 0.35 * ((k % 3) - 1)
        oz = 0.35 * (((k // 3) % 2) - 0.5)
        oy = 1.2 + 0.45 * k
        yaw = 0.7 * k
        cy, sy = math.cos(yaw), math.sin(yaw)

        def at(p):  # ragdoll frame: turned about y by yaw, lifted
            return r([ox + cy * p[0] + sy * p[2], oy + p[1], oz - sy * p[0] + cy * p[2]])

        yawq = [math.cos(yaw / 2), 0.0, math.sin(yaw / 2), 0.0]

        def qmul(a, b):
            return [a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
                    a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
                    a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
                    a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]]

        # Lying along x (the body's length horizontal), so that the pile builds in layers.
        along = qmul(yawq, quat_from_z_to((1.0, 0.0, 0.0)))
        p = "r%d_" % k
        parts = [  # name, shape, mass, centre (ragdoll frame), orientation
            ("torso", {"type": "box", "half_extents": [0.1, 0.06, 0.16]}, 8.0, (0.0, 0.0, 0.0), along),
            ("head", {"type": "sphere", "radius": 0.07}, 2.0, (0.27, 0.0, 0.0), yawq),
        ]
        limbs = [  # name, from, to, radius, mass
            ("uarm_l", (0.13, 0.0, 0.14), (-0.03, 0.0, 0.3), 0.03, 1.0),
            ("larm_l", (-0.03, 0.0, 0.3), (-0.23, 0.0, 0.36), 0.025, 0.8),
            ("uarm_r", (0.13, 0.0, -0.14), (-0.03, 0.0, -0.3), 0.03, 1.0),
            ("larm_r", (-0.03, 0.0, -0.3), (-0.23, 0.0, -0.36), 0.025, 0.8),
            ("thigh_l", (-0.2, 0.0, 0.07), (-0.45, 0.0, 0.08), 0.04, 2.0),
            ("shin_l", (-0.45, 0.0, 0.08), (-0.7, 0.0, 0.09), 0.035, 1.5),
            ("thigh_r", (-0.2, 0.0, -0.07), (-0.45, 0.0, -0.08), 0.04, 2.0),
            ("shin_r", (-0.45, 0.0, -0.08), (-0.7, 0.0, -0.09), 0.035, 1.5),
        ]
        joint_of = {"uarm_l": ("torso", "spherical"), "larm_l": ("uarm_l", "revolute"),
                    "uarm_r": ("torso", "spherical"), "larm_r": ("uarm_r", "revolute"),
                    "thigh_l": ("torso", "spherical"), "shin_l": ("thigh_l", "revolute"),
                    "thigh_r": ("torso", "spherical"), "shin_r": ("thigh_r", "revolute")}
        for name, shape, mass, c, q in parts:
            e = {"name": p + name, "shape": shape, "rigid_body": {"mass": mass, "position": at(c), "orientation": r(q)},
                 "collider": col}
            if name == "head":
                e["joint"] = {"type": "spherical", "parent": p + "torso", "anchor": at((0.185, 0.0, 0.0))}
            entities.append(e)
            count += 1
        for name, a, b, rad, mass in limbs:
            d = [b[i] - a[i] for i in range(3)]
            ln = math.sqrt(sum(x * x for x in d))
            gap = 0.02  # the limb stops short of its joints: jointed parts never touch
            c = [(a[i] + b[i]) / 2 for i in range(3)]
            u = [x / ln for x in d]
            wu = [cy * u[0] + sy * u[2], u[1], -sy * u[0] + cy * u[2]]
            parent, jtype = joint_of[name]
            joint = {"type": jtype, "parent": p + parent, "anchor": at(a)}
            if jtype == "revolute":
                joint["axis"] = r([-sy * 0 + 0.0, 1.0, 0.0])
            entities.append({"name": p + name,
                             "shape": {"type": "capsule", "radius": rad, "half_height": 0.5 * ln - rad - gap},
                             "rigid_body": {"mass": mass, "position": at(c), "orientation": r(quat_from_z_to(wu))},
                             "collider": col, "joint": joint})
            count += 1
    assert count == 200
    # Rest mechanisms: rolling resistance at the jointed bodies' contacts (Coulomb friction does
    # not stop a head rolling round its neck), Step III's joint-and-contact projection (without it
    # the pile creeps at zero end-of-step velocity), swept to convergence, and sleeping.
    entities.append({"name": "solver", "articulation": {"rolling_resistance": 0.002, "step_three_contact_solve": True,
                                                        "contact_solve_sweeps": 2000}})
    scene = {"description": "20 ragdolls of 10 bodies dropped in a pile", "dimension": 3,
             "time": {"dt": 1 / 30, "end": 12.0, "frame_rate": 30}, "gravity": [0, -9.81, 0], "entities": entities,
             "solvers": {"contact": {"schedule": "thesis", "sleep": True}},
             "checks": [{"name": "joints_closed", "kind": "diagnostic", "diagnostic": "joint_error_max",
                         "statistic": "max", "reference": 0, "tolerance": 1e-3},
                        {"name": "all_asleep", "kind": "diagnostic", "diagnostic": "bodies_asleep",
                         "statistic": "final", "reference": 200, "tolerance": 0.5},
                        {"name": "at_rest", "kind": "diagnostic", "diagnostic": "kinetic_energy",
                         "statistic": "max", "after": 11.0, "reference": 0, "tolerance": 1e-9}]}
    write("ragdoll_pile", """
20 ragdolls of 10 bodies (torso box, head ball, capsule limbs; spherical neck, shoulders and
hips, revolute elbows and knees) dropped in layers onto the ground and each other at dt = 1/30.
Limbs stop short of their joints: jointed parts never touch. Rest mechanisms: rolling
resistance of 2 mm at the jointed bodies' contacts, Step III's joint-and-contact projection
(2000 sweeps) and sleeping: the pile comes to rest, all 200 bodies asleep from 10 s
(docs/benchmarks_articulation.md). Checks: no joint opens by 1 mm in any step; every body asleep
at the end; no kinetic energy over the last second. The thesis's contact schedule.""", scene)


def twisting_chain_rigid(loops=(1, 3, 5), rings=7, end=2.0):
    """Rigid part of Fig. 4.1: hexagonal rings of six capsules hung on one another along x."""
    side, radius, mass = 0.3, 0.03, 0.2
    col = {"restitution": 0.0, "friction": 0.5}
    notch = 0.045  # a rigid ring's unjointed vertex: its two caps kept apart (they would collide)
    entities = []
    for k in range(rings):
        c = (side * k, 0.0, 0.0)
        e = (0.0, 1.0, 0.0) if k % 2 == 0 else (0.0, 0.0, 1.0)  # rings alternate between the xy and xz planes

        def vertex(j):
            t = math.pi / 3 * (j % 6)
            return [c[i] + side * (math.cos(t) * (1.0 if i == 0 else 0.0) + math.sin(t) * e[i]) for i in range(3)]

        kind = "static" if k == 0 else "loop" if k in loops else "rigid"
        for j in range(6):
            # Capsule j runs from vertex j + 1 to vertex j + 2, so that vertex 1 (at 60 degrees, off
            # the axis) is where a rigid ring's chain of fixed joints stays open.
            a, b = vertex(j + 1), vertex(j + 2)
            d = [b[i] - a[i] for i in range(3)]
            ln = math.sqrt(sum(x * x for x in d))
            u = [x / ln for x in d]
            cut_a = notch if kind != "loop" and k != 0 and j == 0 else 0.0
            cut_b = notch if kind != "loop" and k != 0 and j == 5 else 0.0
            aa = [a[i] + cut_a * u[i] for i in range(3)]
            bb = [b[i] - cut_b * u[i] for i in range(3)]
            centre = [(aa[i] + bb[i]) / 2 for i in range(3)]
            half = 0.5 * (ln - cut_a - cut_b)  # the caps' centres at the vertices
            name = "ring%d_%d" % (k, j)
            body = {"mass": mass, "position": r(centre), "orientation": r(quat_from_z_to(u))}
            if kind == "static":
                body = {"static": True, "position": r(centre), "orientation": r(quat_from_z_to(u))}
            ent = {"name": name, "shape": {"type": "capsule", "radius": radius, "half_height": round(half, 12)},
                   "rigid_body": body, "collider": col}
            if kind == "loop":
                ent["joint"] = {"type": "spherical", "parent": "ring%d_%d" % (k, (j - 1) % 6), "anchor": r(a)}
            elif kind == "rigid" and j > 0:
                ent["joint"] = {"type": "fixed", "parent": "ring%d_%d" % (k, j - 1), "anchor": r(a)}
            entities.append(ent)
        if k == rings - 1:
            entities.append({"name": "crank", "shape": {"type": "sphere", "radius": 0.05},
                             "rigid_body": {"mass": 1.0, "position": r(c)},
                             "kinematic": {"schedule": [{"angular_velocity": [math.pi, 0.0, 0.0]}]}})
            entities.append({"name": "crank_weld", "joint": {"type": "fixed", "parent": "crank",
                                                             "child": "ring%d_0" % k, "anchor": r(c)}})
    entities.append({"name": "solver", "articulation": {"post_stabilization": "global", "pre_stabilization": "global",
                                                        "push_out_contact_passes": 10}})
    return {"description": "rigid part of the twisting chain (Fig. 4.1): rings and articulated loops wound by a spun ring",
            "dimension": 3, "time": {"dt": 1 / 120, "end": end, "frame_rate": 30},
            "gravity": [0, -9.81, 0], "entities": entities,
            "checks": [{"name": "joints_closed", "kind": "diagnostic", "diagnostic": "joint_error_max",
                        "statistic": "max", "reference": 0, "tolerance": 1e-6},
                       {"name": "overlap_left", "kind": "diagnostic", "diagnostic": "joint_push_out_overlap_left",
                        "statistic": "max", "reference": 0, "tolerance": 0.01}]}


def pendulum_2d_period():
    """2 pi sqrt(I_pivot / (m g d)) of pendulum_2d: rod 0.02 x 1 m (1 kg), disk r 0.1 (2 kg) at 1 m."""
    inertia = (1.0 * (0.02 ** 2 + 1.0) / 12 + 1.0 * 0.5 ** 2) + (0.5 * 2.0 * 0.1 ** 2 + 2.0 * 1.0 ** 2)
    return 2 * math.pi * math.sqrt(inertia / (3.0 * 9.81 * (2.5 / 3.0)))


def pendulum_2d():
    # The 2-D pendulum: the rod and bob of `pendulum` in the plane, the bob a disk.
    a = math.radians(5)
    down = (math.sin(a), -math.cos(a))
    period = pendulum_2d_period()
    swing = 3.0 * 9.81 * (2.5 / 3.0) * (1 - math.cos(a))
    start_energy = 9.81 * (1.0 * 0.5 * down[1] + 2.0 * 1.0 * down[1])
    # At t = (4 + 1/4) T the rod passes through the vertical; a period off by a fraction eps puts
    # its centre at 0.5 sin(a sin(2 pi 4.25 eps)) from it: 5.8 mm for eps = 0.5 %.
    crossing = 4.25 * period
    tolerance = 0.5 * math.sin(a * math.sin(2 * math.pi * 4.25 * 0.005))
    scene = {
        "description": "2-D rod and bob pendulum on a pin, 5 degree amplitude",
        "dimension": 2,
        "time": {"dt": 1 / 240, "end": 10.0, "frame_rate": 30},
        "gravity": [0, -9.81],
        "entities": [
            {"name": "rod", "shape": {"type": "box", "half_extents": [0.01, 0.5]},
             "rigid_body": {"mass": 1.0, "position": r([0.5 * x for x in down]), "angle": round(a, 12)},
             "joint": {"type": "revolute", "parent": "world", "anchor": [0, 0]}},
            {"name": "bob", "shape": {"type": "disk", "radius": 0.1},
             "rigid_body": {"mass": 2.0, "position": r(down), "angle": round(a, 12)},
             "joint": {"type": "fixed", "parent": "rod", "anchor": r(down)}},
        ],
        "checks": [
            {"name": "period", "kind": "body", "body": "rod", "field": "position", "axis": 0,
             "at": round(crossing, 9), "reference": 0, "tolerance": round(tolerance, 6)},
            {"name": "energy_rise", "kind": "diagnostic", "diagnostic": "total_energy", "statistic": "max",
             "reference": round(start_energy, 9), "tolerance": round(1e-3 * swing, 9)},
            {"name": "joints_closed", "kind": "diagnostic", "diagnostic": "joint_error_max",
             "statistic": "max", "reference": 0, "tolerance": 1e-8},
        ],
    }
    write("pendulum_2d", """
2-D pendulum (thesis Sec. 4.5, App. C, in the plane): a 1 m rod (box 0.02 x 1 m, 1 kg) with a
2 kg disk (r 0.1 m) fixed to its end by a fixed joint, pinned to the world at the top by a
revolute joint, released at 5 degrees. Period 2 pi sqrt(I_pivot / (m g d)) = %.6f s.
Checks: the rod's centre at t = 4.25 periods within %.4f m of the vertical (a period within
0.5 %%), the total energy never above its start by 0.1 %% of the swing, joints closed to 1e-8 m.""" % (
        period, tolerance), scene)


def chain_2d():
    n, length = 20, 0.1
    entities = []
    for i in range(n):
        entities.append({
            "name": "link%d" % i,
            "shape": {"type": "box", "half_extents": [0.5 * length, 0.01]},
            "rigid_body": {"mass": 0.1, "position": [(i + 0.5) * length, 0]},
            "joint": {"type": "revolute", "parent": "world" if i == 0 else "link%d" % (i - 1),
                      "anchor": [i * length, 0]},
        })
    entities.append({"name": "solver", "articulation": {"post_stabilization": "global", "pre_stabilization": "global"}})
    start_energy = 0.0  # all links at y = 0
    scale = n * 0.1 * 9.81 * n * length  # the chain's weight times its length
    scene = {"description": "2-D chain of 20 links on pins released horizontally",
             "dimension": 2, "time": {"dt": 1 / 240, "end": 2.0, "frame_rate": 30},
             "gravity": [0, -9.81], "entities": entities,
             "checks": [
                 {"name": "joints_closed", "kind": "diagnostic", "diagnostic": "joint_error_max",
                  "statistic": "max", "reference": 0, "tolerance": 1e-4 * length},
                 {"name": "energy_rise", "kind": "diagnostic", "diagnostic": "total_energy", "statistic": "max",
                  "reference": start_energy, "tolerance": 1e-3 * scale},
             ]}
    write("chain_2d", """
2-D chain: 20 box links (0.1 x 0.02 m, 0.1 kg) on pins, the first pinned to the world, released
horizontally (global pre- and post-stabilization). Checks: joint_error_max below 1e-4 of a link's
length in every step; the total energy never above its start by 0.1 % of the chain's weight
times its length.""", scene)


if __name__ == "__main__":
    pendulum()
    chain_hanging()
    loop_six()
    pd_arm()
    ragdoll_pile()
    pendulum_2d()
    chain_2d()
    scene = twisting_chain_rigid()
    write("twisting_chain_rigid", """
Rigid part of the twisting chain (thesis Fig. 4.1): seven hexagonal rings of six capsules (0.3 m
sides, radius 3 cm) along x, each turned 90 degrees from the one before so that its vertex on the
axis sits at the centre of the next ring's hole. Ring 0 is static; rings 1, 3, 5 are articulated
loops (spherical joints at the vertices); rings 2, 4, 6 are rigid (chains of fixed joints, open at
the vertex at 60 degrees); ring 6 is welded to a kinematic crank turning half a turn a second
about the axis, which winds the chain. The capsules' caps are centred on the vertices.""", scene)
