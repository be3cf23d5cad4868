#!/usr/bin/env python3
"""Writes demos/scenes/crane.json (paper Fig. 17): a crane electromagnet dips
into a heap of steel balls in a bin, lifts a heap of induced magnets, then its
magnetization is lowered and switched off. Balls have random easy axes (random
orientations), so a few keep enough remanence to hang on when it is off.
Usage: make_crane.py [--balls N] [--out PATH] [--seed S] [--coil H] [--ms M] [--hk H] [--moments N]"""
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
args = p.parse_args()
rng = random.Random(args.seed)

R = 0.005                  # ball radius, m
bin_half = 0.065           # inner half width of the bin, m
crane = [0.12, 0.12, 0.03]  # crane magnet (box), m
h_crane = 0.012            # its lattice spacing: 10 x 10 x 2 = 200 cells

def random_quaternion():
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    return [math.sqrt(u1) * math.cos(2 * math.pi * u3), math.sqrt(1 - u1) * math.sin(2 * math.pi * u2),
            math.sqrt(1 - u1) * math.cos(2 * math.pi * u2), math.sqrt(u1) * math.sin(2 * math.pi * u3)]

# Balls stacked in square layers (slightly apart), the bin holding them.
balls = []
per_row = int((2 * bin_half) / (2 * R * 1.02))
layer = 0
while len(balls) < args.balls:
    offset = R * 1.02 if layer % 2 else 0.0
    n = per_row - (layer % 2)
    for i in range(n):
        for j in range(n):
            if len(balls) >= args.balls:
                break
            x = -bin_half + R * 1.02 + offset + 2 * R * 1.02 * i
            y = -bin_half + R * 1.02 + offset + 2 * R * 1.02 * j
            z = R * 1.01 + layer * 2 * R * 0.75
            balls.append([x, y, z])
    layer += 1
top = max(b[2] for b in balls) + R
wall_h = 0.05
bodies = [
    {"name": "crane", "shape": {"box": crane}, "material": "crane_core", "position": [0, 0, 0.2],
     "fixed": True, "cell_size": h_crane},
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
    "title": "Crane magnet (paper Fig. 17): an electromagnet lifts a heap of steel balls; its "
             "magnetization is lowered, then switched off, and a few balls hang on by remanence",
    "gravity": [0, 0, -9.81], "cell_size": 0.0, "seed": 17,
    "materials": {
        "crane_core": {"type": "soft", "saturation": 1.7e6, "susceptibility": 1000,
                       "coil_field": [0, 0, -args.coil], "color": [0.35, 0.35, 0.4]},
        "steel": {"type": "soft", "saturation": args.ms, "susceptibility": 1000, "anisotropy_field": args.hk,
                  "easy_axis": [0, 0, 1], "moments_per_cell": args.moments, "color": [0.72, 0.74, 0.78]},
        "steel_plate_inert": {"type": "inert", "color": [0.5, 0.42, 0.3]},
    },
    "bodies": bodies,
    "solver": {"tolerance": 1e-4},
    "simulation": {"time_step": 0.001, "duration": 5.0, "frame_rate": 30, "contact_solver": "quick",
                   "solver_iterations": 40},
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
json.dump(scene, open(args.out, "w"), indent=1)
print(f"{len(balls)} balls in {layer} layers, heap top {top:.4f} m, crane face at {low - crane[2] / 2:.4f} m")
