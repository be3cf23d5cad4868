#!/usr/bin/env python3
"""What a Python step() costs over the C++ step, on demos/scenes/crane_small.json
(the target: at most 5% more). One process, one scene, the same steps:

1. sim.step() called from Python N times: the wall time of each call
   (time.perf_counter) against the wall time of the same step measured inside
   C++ around Simulation::step (records["wall_ms"]): the difference is
   everything the binding adds (the call, releasing and taking the GIL, the
   finiteness check).
2. The same N steps of a second, identical simulation stepped by the C++
   loop of sim.advance_to (10 steps a call, taking turns with (1)): its total
   wall time against the total of (1).

Usage: PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_step.py [--steps N] [--out DIR]
Writes DIR/python_step.csv (per step) and DIR/python_step.md (the summary;
default DIR benchmarks/results); with --threads N, python_step_threadsN.*.
"""

import argparse
import os
import pathlib
import platform
import time

import numpy as np

import odemag

ROOT = pathlib.Path(__file__).resolve().parents[1]


def machine():
    model = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} logical CPUs, Python {platform.python_version()}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--scene", default=str(ROOT / "demos/scenes/crane_small.json"))
    parser.add_argument("--out", default=str(ROOT / "benchmarks/results"))
    parser.add_argument("--threads", type=int, default=None, help="CPU threads (default: the scene's, 0 = all cores)")
    a = parser.parse_args()
    scene = odemag.load(a.scene)

    # Chunks of 10 steps, by the C++ loop and by Python calls in turn (which
    # goes first alternates), so that both see the same load of a shared machine.
    stepped, looped = odemag.Simulation(scene, threads=a.threads), odemag.Simulation(scene, threads=a.threads)
    python_ms, loop_ms = [], 0.0
    chunk = 10

    def by_loop(n):
        nonlocal loop_ms
        t0 = time.perf_counter()
        looped.advance_to((looped.steps + n) * scene.time_step)
        loop_ms += 1e3 * (time.perf_counter() - t0)

    def by_python(n):
        for _ in range(n):
            t0 = time.perf_counter()
            stepped.step()
            python_ms.append(1e3 * (time.perf_counter() - t0))

    for k in range(0, a.steps, chunk):
        n = min(chunk, a.steps - k)
        for run in ((by_loop, by_python) if k // chunk % 2 == 0 else (by_python, by_loop)):
            run(n)
    python_ms = np.array(python_ms)
    r = stepped.records
    cpp_ms = r["wall_ms"]
    assert looped.steps == stepped.steps == a.steps
    assert np.array_equal(looped.positions, stepped.positions)  # the same steps were timed

    load = os.getloadavg()
    per_step_overhead = python_ms - cpp_ms
    overhead = per_step_overhead.sum() / cpp_ms.sum()
    loop_overhead = python_ms.sum() / loop_ms - 1.0

    name = "python_step" if a.threads is None else f"python_step_threads{a.threads}"
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / f"{name}.csv", "w") as f:
        f.write("step,python_ms,cpp_step_ms,magnetic_ms,rigid_ms,substeps\n")
        for i in range(a.steps):
            f.write(f"{i + 1},{python_ms[i]:.6f},{cpp_ms[i]:.6f},{r['magnetic_ms'][i]:.6f},"
                    f"{r['rigid_ms'][i]:.6f},{r['substeps'][i]}\n")
    summary = f"""# Python step() against the C++ step

`benchmarks/python_step.py --steps {a.steps}` on `{os.path.relpath(a.scene, ROOT)}`
({len(scene.body_names)} bodies, {scene.time_step * 1e3:g} ms steps), one process;
machine: {machine()}; backend {stepped.backend}, threads {a.threads if a.threads is not None else "the scene's"};
load average (1 min) at the end {load[0]:.2f} (the machine is shared: absolute times vary
several-fold with the load, the binding's few microseconds per call do not).

| measure | total over {a.steps} steps | per step |
|---|---|---|
| Python `sim.step()`, wall (perf_counter around each call) | {python_ms.sum():.1f} ms | {python_ms.mean():.3f} ms |
| the same steps inside C++ (`Simulation::step`, records["wall_ms"]) | {cpp_ms.sum():.1f} ms | {cpp_ms.mean():.3f} ms |
| binding overhead (difference) | {per_step_overhead.sum():.2f} ms | {1e3 * per_step_overhead.mean():.1f} us (median {1e3 * np.median(per_step_overhead):.1f} us, max {1e3 * per_step_overhead.max():.1f} us) |
| **overhead relative to the C++ step** | **{100 * overhead:.3f} %** | |
| the same {a.steps} steps of an identical simulation by `sim.advance_to` (loop in C++, 10 steps a call, taking turns with the Python steps) | {loop_ms:.1f} ms | {loop_ms / a.steps:.3f} ms |
| Python stepping against the C++ loop | {100 * loop_overhead:+.2f} % | |

The first comparison isolates the binding (the same steps, timed both sides);
the second compares two runs of the same work and so includes the run-to-run
noise of a shared machine (it can come out negative). Per-step numbers are in
`{name}.csv`.
"""
    (out / f"{name}.md").write_text(summary)
    print(summary)


if __name__ == "__main__":
    main()
