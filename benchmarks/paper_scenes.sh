#!/usr/bin/env bash
# The paper's Table 1 scenes with `odemag run`: per rigid step the magnetic
# time T_m and the rigid time T_r (median, 90th percentile), cell count and
# outer relaxation iterations, next to the paper's numbers (docs/benchmarks.md).
#
#   benchmarks/paper_scenes.sh [--quick] [--odemag PATH] [--before PATH]
#                              [--threads N] [--steps N]
#                              [--scenes "ball_chain crane ..."] [--out DIR]
#
# Writes DIR/paper_scenes.csv and DIR/paper_scenes.md (DIR defaults to
# benchmarks/results). Without --odemag it builds build-bench/bin/odemag first
# (Release, CPU only; a no-op when up to date). Every scene runs its full
# duration (the paper's Delta t is each scene's time_step), frames off;
# --steps N runs N rigid steps of each scene instead, --quick runs the crane
# for 1 s (1000 steps: the descent onto the heap and the first grip) instead
# of 5 s. --before PATH: an odemag program of an earlier version, run on
# each scene just before the current one (same machine, same conditions);
# the tables then give its T_m and T_r beside the current ones and their
# ratio (before / current, above 1: the current version is faster).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
odemag=""
before=""
threads=2
quick=0
steps=""
out="$root/benchmarks/results"
scenes="ball_chain wood_plate iron_plate thin_iron_plate thick_iron_plate nail_and_balls crane"

usage() { sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
source "$root/benchmarks/bench_common.sh"
read_options "odemag before threads steps scenes out" "quick" "$@"

if [ -z "$odemag" ]; then
  bench_program odemag odemag
fi
[ -x "$odemag" ] || { echo "paper_scenes.sh: $odemag is not an executable" >&2; exit 2; }
[ -z "$before" ] || [ -x "$before" ] || { echo "paper_scenes.sh: $before is not an executable" >&2; exit 2; }

# Two OpenMP threads (the VM has two cores) and passive waiting: on a machine
# shared with other jobs, spinning OpenMP barriers made small two-thread runs
# up to 20x slower (docs/validation.md); passive threads sleep instead.
export OMP_NUM_THREADS=$threads OMP_WAIT_POLICY=passive

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

for scene in $scenes; do
  file="$root/demos/scenes/$scene.json"
  [ -f "$file" ] || { echo "paper_scenes.sh: no scene $file" >&2; exit 2; }
  args=()
  if [ -n "$steps" ]; then
    dt=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get('simulation',{}).get('time_step',0.004))" "$file")
    args+=(--duration "$(python3 -c "print($steps * $dt)")")
  elif [ "$quick" = 1 ] && [ "$scene" = crane ]; then
    args+=(--duration 1.0)
  fi
  echo "paper_scenes.sh: $scene ${args[*]:-}" >&2
  # Wall, user and system seconds of the run: CPU seconds per wall second
  # below the thread count mean the machine was shared (or one thread idled).
  TIMEFORMAT='%R %U %S'
  if [ -n "$before" ]; then
    { time "$before" run "$file" --out "$work/before/$scene" --frames no --quiet yes --backend cpu \
        --threads "$threads" "${args[@]}" 2>&3; } 3>&2 2>"$work/$scene.before.time"
    echo "paper_scenes.sh: $scene (before) done in $(cut -d' ' -f1 "$work/$scene.before.time") s" >&2
  fi
  { time "$odemag" run "$file" --out "$work/$scene" --frames no --quiet yes --backend cpu \
      --threads "$threads" "${args[@]}" 2>&3; } 3>&2 2>"$work/$scene.time"
  echo "paper_scenes.sh: $scene done in $(cut -d' ' -f1 "$work/$scene.time") s" >&2
done

python3 - "$work" "$out" "$threads" "$quick" "$steps" "$(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)" "${before:-}" $scenes <<'EOF'
import json, os, sys

work, out, threads, quick, steps, commit, before = sys.argv[1:8]
scenes = sys.argv[8:]

# Paper Table 1 (Kim, Park & Han 2018): cells, Delta t, T_m, T_r in ms; CUDA
# magnetics on a GeForce GTX 780, Bullet on an Intel Core i7-4770 3.40 GHz.
paper = {
    "ball_chain": ("ball chain (Fig. 12)", 28, 4, 2.5, 1.3),
    "wood_plate": ("wood plate (Fig. 13a)", 32, 10, 2.4, 1.0),
    "iron_plate": ("iron plate (Fig. 13b)", 191, 10, 8.1, 1.1),
    "thin_iron_plate": ("thin iron (Fig. 15a)", 140, 4, 24, 4.4),
    "thick_iron_plate": ("thick iron (Fig. 15b)", 140, 4, 24, 4.5),
    "nail_and_balls": ("nail and balls (Fig. 16)", 88, 5, 1.4, 1.4),
    "crane": ("crane magnet (Fig. 17)", 690, 1, 118, 57),
}

def cpu_model():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"

machine = f"{cpu_model()}, {os.cpu_count()} logical CPUs, {threads} OpenMP threads (OMP_WAIT_POLICY=passive)"

columns = ["scene", "cells", "responsive_cells", "dt_ms", "steps", "substeps_mean",
           "tm_median_ms", "tm_p90_ms", "tm_mean_ms", "tr_median_ms", "tr_p90_ms", "tr_mean_ms",
           "iterations_mean", "iterations_max", "steps_not_converged", "wall_s", "cpu_per_wall",
           "paper_cells", "paper_dt_ms", "paper_tm_ms", "paper_tr_ms",
           "ratio_tm_paper_over_ours", "ratio_tr_paper_over_ours",
           "before_tm_mean_ms", "before_tr_mean_ms", "before_iterations_mean", "before_substeps_mean",
           "ratio_tm_before_over_ours", "ratio_tr_before_over_ours", "machine"]
rows = []
for scene in scenes:
    s = json.load(open(os.path.join(work, scene, "summary.json")))
    p = paper.get(scene, (scene, None, None, None, None))
    tm, tr, it = s["magnetic_ms"], s["rigid_ms"], s["iterations"]
    ratio = lambda a, b: (a / b) if (a is not None and b) else None
    real, user, system = (float(x) for x in open(os.path.join(work, scene + ".time")).read().split()[-3:])
    rows.append({
        "scene": scene, "cells": s["cells"], "responsive_cells": s["responsive_cells"],
        "dt_ms": 1e3 * s["time_step"], "steps": s["steps"], "substeps_mean": s["substeps"].get("mean"),
        "tm_median_ms": tm.get("median"), "tm_p90_ms": tm.get("p90"), "tm_mean_ms": tm.get("mean"),
        "tr_median_ms": tr.get("median"), "tr_p90_ms": tr.get("p90"), "tr_mean_ms": tr.get("mean"),
        "iterations_mean": it.get("mean"), "iterations_max": it.get("max"),
        "steps_not_converged": s["steps_not_converged"], "wall_s": s["wall_seconds"],
        "cpu_per_wall": (user + system) / real if real > 0 else None,
        "paper_cells": p[1], "paper_dt_ms": p[2], "paper_tm_ms": p[3], "paper_tr_ms": p[4],
        "ratio_tm_paper_over_ours": ratio(p[3], tm.get("median")),
        "ratio_tr_paper_over_ours": ratio(p[4], tr.get("median")),
        "machine": machine, "_title": p[0],
    })
    b = json.load(open(os.path.join(work, "before", scene, "summary.json"))) if before else None
    r = rows[-1]
    r["before_tm_mean_ms"] = b["magnetic_ms"].get("mean") if b else None
    r["before_tr_mean_ms"] = b["rigid_ms"].get("mean") if b else None
    r["before_iterations_mean"] = b["iterations"].get("mean") if b else None
    r["before_substeps_mean"] = b["substeps"].get("mean") if b else None
    # The scene's outcome numbers (summary.json "outcomes"), for the tables only.
    r["_outcomes"] = s.get("outcomes", {})
    r["_before_outcomes"] = b.get("outcomes", {}) if b else {}
    r["ratio_tm_before_over_ours"] = ratio(r["before_tm_mean_ms"], tm.get("mean"))
    r["ratio_tr_before_over_ours"] = ratio(r["before_tr_mean_ms"], tr.get("mean"))

def outcomes(o):
    """summary.json's outcome numbers as "name value, ..." (a table cell)."""
    return ", ".join(f"{k} {fmt(v)}" for k, v in o.items())

def fmt(v, digits=3):
    if v is None:
        return ""
    if isinstance(v, float):
        text = f"{v:.{digits}g}"
        return f"{v:.0f}" if "e+" in text else text
    return str(v)

def table(f, header, cells):
    """A Markdown table: the header's columns, then a row per list of cells."""
    f.write("| " + " | ".join(header) + " |\n")
    f.write("|" + "---|" * len(header) + "\n")
    for row in cells:
        f.write("| " + " | ".join(row) + " |\n")

with open(os.path.join(out, "paper_scenes.csv"), "w") as f:
    f.write(",".join(columns) + "\n")
    for r in rows:
        f.write(",".join('"' + r[c] + '"' if c == "machine" else fmt(r[c], 6) for c in columns) + "\n")

mode = (f"{steps} rigid steps per scene" if steps else
        "full scene durations" + (", crane 1 s (--quick)" if quick == "1" else ""))
with open(os.path.join(out, "paper_scenes.md"), "w") as f:
    f.write(f"Machine: {machine}; odemag {commit}; {mode}. Times per rigid step in ms "
            "(T_m summed over the step's substeps); ratio = paper / ours (medians), above 1: odemag is faster; "
            "cores busy: CPU seconds per wall second of the run (below the thread count: shared machine "
            "or serial parts).\n\n")
    table(f, ["scene", "cells", "steps", "substeps mean", "T_m median", "T_m p90", "T_m mean", "T_r median",
              "T_r p90", "T_r mean", "iterations mean", "paper cells", "paper T_m", "paper T_r", "ratio T_m",
              "ratio T_r", "cores busy"],
          [[r["_title"], fmt(r["cells"]), fmt(r["steps"]), fmt(r["substeps_mean"], 3),
            fmt(r["tm_median_ms"]), fmt(r["tm_p90_ms"]), fmt(r["tm_mean_ms"]), fmt(r["tr_median_ms"]),
            fmt(r["tr_p90_ms"]), fmt(r["tr_mean_ms"]), fmt(r["iterations_mean"]), fmt(r["paper_cells"]),
            fmt(r["paper_tm_ms"]), fmt(r["paper_tr_ms"]), fmt(r["ratio_tm_paper_over_ours"], 2),
            fmt(r["ratio_tr_paper_over_ours"], 2), fmt(r["cpu_per_wall"], 2)] for r in rows])
    if before:
        f.write(f"\nBefore and after, each scene run with the earlier program ({before}) just before the "
                "current one: means per rigid step in ms; ratio = before / after (above 1: faster now).\n\n")
        table(f, ["scene", "T_m before", "T_m after", "ratio T_m", "T_r before", "T_r after", "ratio T_r",
                  "iterations before", "iterations after", "substeps before", "substeps after", "outcomes before",
                  "outcomes after"],
              [[r["_title"], fmt(r["before_tm_mean_ms"]), fmt(r["tm_mean_ms"]), fmt(r["ratio_tm_before_over_ours"], 2),
                fmt(r["before_tr_mean_ms"]), fmt(r["tr_mean_ms"]), fmt(r["ratio_tr_before_over_ours"], 2),
                fmt(r["before_iterations_mean"]), fmt(r["iterations_mean"]),
                fmt(r["before_substeps_mean"], 3), fmt(r["substeps_mean"], 3),
                outcomes(r["_before_outcomes"]), outcomes(r["_outcomes"])] for r in rows])
print(open(os.path.join(out, "paper_scenes.md")).read())
EOF
