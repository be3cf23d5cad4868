#!/usr/bin/env python3
"""Writes demos/scenes/crane.json (paper Fig. 17): a crane electromagnet dips
into a heap of steel balls in a bin, lifts a heap of induced magnets, then its
magnetization is lowered and switched off. Balls have random easy axes (random
orientations), so a few keep enough remanence to hang on when it is off.
With --electromagnet the crane is a real electromagnet instead of the paper's
model (a uniform coil field inside the core only, a linear-to-saturation core):
a copper winding (`coils`: a rounded-rectangle coil around the core) whose
field also acts outside the core, and a core of low-carbon steel with the
TEAM problem 20 B-H curve (demos/scenes/crane_electromagnet.json,
crane_electromagnet_small.json; docs/scenes.md).
Usage: make_crane.py [--balls N] [--out PATH] [--seed S] [--coil H] [--ms M] [--hk H] [--moments N]
                     [--electromagnet] [--ampere-turns NI]"""
import argparse, json, math, random

p = argparse.ArgumentParser()
p.add_argument("--balls", type=int, default=490)
p.add_argument("--out", default="demos/scenes/crane.json")
p.add_argument("--seed", type=int, default=17)
p.add_argument("--coil", type=float, default=5e5)     # coil field in the core, A/m
# Ball steel: Ms 8e5 A/m (mu0 Ms = 1 T) and H_K 3.2e5 A/m > Ms/3, so a ball
# keeps a remanent magnetization (a one-cell sphere's own demagnetising field
# Ms/3 cannot undo it); the core's field (about 3e5-5e5 A/m at its face)
# switches the balls whose easy axes lie within about 45 degrees of it and
# only bends the others. docs/scenes.md has the measurements.
p.add_argument("--ms", type=float, default=8e5)       # saturation of the balls, A/m
p.add_argument("--hk", type=float, default=3.2e5)     # anisotropy field of the balls, A/m
p.add_argument("--moments", type=int, default=8)      # moments per ball cell
p.add_argument("--electromagnet", action="store_true")  # a real coil and a steel B-H curve
p.add_argument("--ampere-turns", type=float, default=30000)  # the winding's N I at full current, A
args = p.parse_args()
rng = random.Random(args.seed)

R = 0.005                  # ball radius, m
heap_half = 0.065          # half width of the balls' first layer, m
crane = [0.12, 0.12, 0.03]  # crane magnet (box), m
h_crane = 0.015            # its lattice spacing: 8 x 8 x 2 = 128 whole cubes of the 120 x 120 x 30 mm core
# --electromagnet: the winding around the core, a rounded-rectangle coil from
# 2 mm to 42 mm off the core's sides (40 mm radial build), 60 mm tall, its
# lower end flush with the core's pole face (it stands 30 mm above the core's
# back, away from the load). Section 40 x 60 mm = 2.4e-3 m^2, so 30 kAT is a
# mean current density of 12.5 A/mm^2 over the section (docs/scenes.md: why).
coil_gap, coil_build, coil_height = 0.002, 0.04, 0.06
coil_turns = 500
# Low-carbon steel, the B-H table of the Compumag TEAM workshop's problem 20
# statement ("3-D static force problem", its Table 1; N. Takahashi, T. Nakata,
# H. Morishige, IEEE Trans. Magn. 30(5), 3483, 1994), as (H, B) in A/m and T: Ms = B/mu0 - H at the last point = 1.695e6 A/m, initial mu_r 295.
TEAM20_BH = [(0, 0.0), (27, 0.01), (58, 0.025), (100, 0.05), (153, 0.1), (185, 0.15), (205, 0.2),
             (233, 0.3), (255, 0.4), (285, 0.5), (320, 0.6), (355, 0.7), (405, 0.8), (470, 0.9),
             (555, 1.0), (673, 1.1), (836, 1.2), (1065, 1.3), (1220, 1.35), (1420, 1.4), (1720, 1.45),
             (2130, 1.5), (2670, 1.55), (3480, 1.6), (4500, 1.65), (5950, 1.7), (7650, 1.75),
             (10100, 1.8), (13000, 1.85), (15900, 1.9), (21100, 1.95), (26300, 2.0), (32900, 2.05),
             (42700, 2.1), (61700, 2.15), (84300, 2.2), (110000, 2.25), (135000, 2.3)]

def random_quaternion():
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    return [math.sqrt(u1) * math.cos(2 * math.pi * u3), math.sqrt(1 - u1) * math.sin(2 * math.pi * u2),
            math.sqrt(1 - u1) * math.cos(2 * math.pi * u2), math.sqrt(u1) * math.sin(2 * math.pi * u3)]

# Balls stacked in square layers (slightly apart), the bin holding them.
balls = []
per_row = int((2 * heap_half) / (2 * R * 1.02))
layer = 0
while len(balls) < args.balls:
    offset = R * 1.02 if layer % 2 else 0.0
    n = per_row - (layer % 2)
    for i in range(n):
        for j in range(n):
            if len(balls) >= args.balls:
                break
            x = -heap_half + R * 1.02 + offset + 2 * R * 1.02 * i
            y = -heap_half + R * 1.02 + offset + 2 * R * 1.02 * j
            z = R * 1.01 + layer * 2 * R * 0.75
            balls.append([x, y, z])
    layer += 1
top = max(b[2] for b in balls) + R
wall_h = 0.05
bin_half = heap_half       # inner half width of the bin, m
if args.electromagnet:
    # The winding reaches 42 mm beyond the core's sides and comes down with
    # the pole face below the walls' top: the bin is wide enough for it (5 mm
    # clear), or it would pass through the walls and press the balls on them
    # into its copper (a solid for the balls, docs/simulation.md "Coil windings").
    bin_half = crane[0] / 2 + coil_gap + coil_build + 0.005
crane_body = {"name": "crane", "shape": {"box": crane}, "material": "crane_core", "position": [0, 0, 0.2],
              "fixed": True, "cell_size": h_crane}
core_material = {"type": "soft", "saturation": 1.7e6, "susceptibility": 1000,
                 "coil_field": [0, 0, -args.coil], "color": [0.35, 0.35, 0.4]}
title = ("Crane magnet (paper Fig. 17): an electromagnet lifts a heap of steel balls; its "
         "magnetization is lowered, then switched off, and a few balls hang on by remanence")
if args.electromagnet:
    # Field along -z (down into the heap) like the paper's coil_field:
    # positive current about axis -z.
    crane_body["coils"] = [{"type": "rounded_rectangle", "core_half_width": crane[0] / 2,
                            "core_half_depth": crane[1] / 2, "inner_corner_radius": coil_gap,
                            "outer_corner_radius": coil_gap + coil_build, "height": coil_height,
                            "centre": [0, 0, coil_height / 2 - crane[2] / 2], "axis": [0, 0, -1],
                            "current": args.ampere_turns / coil_turns, "turns": coil_turns}]
    core_material = {"type": "soft", "bh_curve": [[h, b] for h, b in TEAM20_BH], "color": [0.35, 0.35, 0.4]}
    title = (f"Crane electromagnet: a {args.ampere_turns / 1000:g} kAT copper coil on a low-carbon steel "
             "core (TEAM 20 B-H curve) lifts a heap of steel balls; its current is lowered, then "
             "switched off, and a few balls hang on by remanence")
bodies = [
    crane_body,
    {"name": "bin_left", "shape": {"box": [0.01, 2 * bin_half + 0.02, wall_h]}, "material": "steel_plate_inert",
     "position": [-bin_half - 0.005, 0, wall_h / 2], "fixed": True},
    {"name": "bin_right", "shape": {"box": [0.01, 2 * bin_half + 0.02, wall_h]}, "material": "steel_plate_inert",
     "position": [bin_half + 0.005, 0, wall_h / 2], "fixed": True},
    {"name": "bin_front", "shape": {"box": [2 * bin_half, 0.01, wall_h]}, "material": "steel_plate_inert",
     "position": [0, -bin_half - 0.005, wall_h / 2], "fixed": True},
    {"name": "bin_back", "shape": {"box": [2 * bin_half, 0.01, wall_h]}, "material": "steel_plate_inert",
     "position": [0, bin_half + 0.005, wall_h / 2], "fixed": True},
]
for k, pos in enumerate(balls):
    bodies.append({"name": f"ball_{k + 1:03d}", "shape": {"sphere": R}, "material": "steel",
                   "position": pos, "orientation": random_quaternion(), "density": 7850})

low = top + crane[2] / 2 + 0.002     # crane face 2 mm above the heap
up = 0.2
keys = [{"time": 0.0, "position": [0, 0, up]}, {"time": 0.8, "position": [0, 0, low]},
        {"time": 1.3, "position": [0, 0, low]}, {"time": 2.3, "position": [0, 0, up]}]
scene = {
    "title": title,
    "gravity": [0, 0, -9.81], "cell_size": 0.0, "seed": 17,
    "materials": {
        "crane_core": core_material,
        "steel": {"type": "soft", "saturation": args.ms, "susceptibility": 1000, "anisotropy_field": args.hk,
                  "easy_axis": [0, 0, 1], "moments_per_cell": args.moments, "color": [0.72, 0.74, 0.78]},
        "steel_plate_inert": {"type": "inert", "color": [0.5, 0.42, 0.3]},
    },
    "bodies": bodies,
    "solver": {"tolerance": 1e-4},
    # Later substeps relax only around the balls that need them (docs/simulation.md
    # "Substeps"; the same balls held over seeds, benchmarks/results/crane_moving.md).
    # 30 QuickStep sweeps (the default): over seeds 1-5 the same balls held as
    # with 40, within 4% of the substeps, T_r -24%; 20 takes 7% more substeps
    # (benchmarks/results/crane_solver_iterations.md).
    "simulation": {"time_step": 0.001, "duration": 5.0, "frame_rate": 30, "contact_solver": "quick",
                   "solver_iterations": 30, "magnetic_solve": "moving"},
    "timeline": [
        {"action": "keyframes", "body": "crane", "keys": keys},
        {"time": 3.0, "action": "scale_magnetization", "body": "crane", "to": 0.15, "end_time": 3.3},
        {"time": 4.0, "action": "scale_magnetization", "body": "crane", "to": 0.0, "end_time": 4.2},
    ],
    "camera": {"position": [0.35, -0.45, 0.3], "target": [0, 0, 0.1], "fov": 40},
    "outcomes": [
        {"name": "held_full", "count_above": {"prefix": "ball_", "height": 0.1}, "time": 2.95},
        {"name": "held_reduced", "count_above": {"prefix": "ball_", "height": 0.1}, "time": 3.95},
        {"name": "held_off", "count_above": {"prefix": "ball_", "height": 0.1}},
    ],
}
# No spinning resistance about the contact normals: one row fewer per contact
# in ODE's quick step, T_r -21% on the crane over six seeds, the same balls held
# (benchmarks/results/crane_spinning.md); crane_electromagnet_small over three seeds:
# T_r -15%, the same substeps and counts within their spread (docs/scenes.md).
scene["simulation"]["contact"] = {"spinning_friction": 0}
json.dump(scene, open(args.out, "w"), indent=1)
print(f"{len(balls)} balls in {layer} layers, heap top {top:.4f} m, crane face at {low - crane[2] / 2:.4f} m")
