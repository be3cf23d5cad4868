#!/usr/bin/env python3
"""Two sweeps and their plot (docs/sweeps.md "Example").

1. Balls held by the crane magnet against its coil field (the core's
   magnetization): demos/scenes/crane_small.json (120 balls) cut to 3.0 s,
   long enough for its held_full count at 2.95 s (the lift ends at 2.3 s).
2. Chain length (balls lifted out of the tube) against the balls'
   susceptibility, with and without mutual induction: demos/scenes/ball_chain.json.

Runs `odemag sweep` (the local runner) for each, then gnuplot for the plot.
About 3-4 minutes on 2 cores. Usage:
    python3 examples/sweeps/crane_and_chain.py [--odemag build/bin/odemag] [--out out/sweeps]
        [--image docs/images/sweeps.png]
"""
import argparse
import csv
import json
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
p = argparse.ArgumentParser()
p.add_argument("--odemag", default=os.path.join(ROOT, "build", "bin", "odemag"))
p.add_argument("--out", default=os.path.join(ROOT, "out", "sweeps"))
p.add_argument("--image", default=os.path.join(ROOT, "out", "sweeps", "sweeps.png"))
p.add_argument("--jobs", default=str(os.cpu_count() or 1))
args = p.parse_args()
os.makedirs(args.out, exist_ok=True)
scenes = os.path.join(ROOT, "demos", "scenes")

sweeps = {
    "crane": {
        "scene": os.path.join(scenes, "crane_small.json"),
        "set": {"simulation.duration": 3.0},
        "grid": {"materials.crane_core.coil_field[2]": [-2e4, -4e4, -6e4, -1e5, -2e5, -5e5]},
        "collect": ["held_full"],
        "run": ["--backend", "cpu"],
    },
    "chain": {
        "scene": os.path.join(scenes, "ball_chain.json"),
        "grid": {"solver.mutual_induction": [True, False],
                 "materials.steel.susceptibility": [2, 5, 10, 20, 50, 100, 1000]},
        "collect": ["balls_lifted"],
        "run": ["--backend", "cpu"],
    },
}
tables = {}
for name, spec in sweeps.items():
    spec_file = os.path.join(args.out, name + ".json")
    with open(spec_file, "w") as f:
        json.dump(spec, f, indent=1)
    out = os.path.join(args.out, name)
    subprocess.run([args.odemag, "sweep", spec_file, "--out", out, "--jobs", args.jobs], check=True)
    with open(os.path.join(out, "results.csv"), newline="") as f:
        tables[name] = list(csv.DictReader(f))

# Data files for gnuplot: coil field (kA/m, positive) -> balls held; chi -> balls lifted.
crane_dat = os.path.join(args.out, "crane.dat")
with open(crane_dat, "w") as f:
    for r in tables["crane"]:
        f.write("%g %g\n" % (-float(r["materials.crane_core.coil_field[2]"]) / 1e3, float(r["held_full"])))
chain_dat = {}
for mi in ("true", "false"):
    chain_dat[mi] = os.path.join(args.out, "chain_%s.dat" % mi)
    with open(chain_dat[mi], "w") as f:
        for r in tables["chain"]:
            if r["solver.mutual_induction"] == mi:
                f.write("%g %g\n" % (float(r["materials.steel.susceptibility"]), float(r["balls_lifted"])))

os.makedirs(os.path.dirname(os.path.abspath(args.image)), exist_ok=True)
plot = """set terminal pngcairo size 1000,420 font ",10"
set output '{image}'
set multiplot layout 1,2
set title 'Crane (crane\\_small, 120 balls): balls held at full field'
set xlabel 'coil field in the core (kA/m)'
set ylabel 'balls held (of 120)'
set logscale x
set yrange [0:130]
set grid
set key top left
plot '{crane}' with linespoints pt 7 lw 2 title 'held\\_full (2.95 s)'
set title 'Ball chain: balls lifted against susceptibility'
set xlabel 'susceptibility of the balls'
set ylabel 'balls lifted (of 10)'
set yrange [0:11]
set key bottom right
plot '{on}' with linespoints pt 7 lw 2 title 'mutual induction', \\
     '{off}' with linespoints pt 5 lw 2 title 'without mutual induction'
unset multiplot
""".format(image=args.image, crane=crane_dat, on=chain_dat["true"], off=chain_dat["false"])
with open(os.path.join(args.out, "sweeps.gnuplot"), "w") as f:
    f.write(plot)
subprocess.run(["gnuplot", os.path.join(args.out, "sweeps.gnuplot")], check=True)
for name, rows in tables.items():
    print(name)
    for r in rows:
        print("  " + ", ".join("%s = %s" % (k, v) for k, v in r.items() if k != "status"))
print("plot: " + args.image)
