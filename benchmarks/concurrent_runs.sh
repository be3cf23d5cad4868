#!/usr/bin/env bash
# Two `odemag run`s at once against one alone, for each odemag program given
# (docs/benchmarks.md "Threads and waiting"): crane_small shortened to
# DURATION s of simulated time, --frames no, each run with its default threads.
# Usage: benchmarks/concurrent_runs.sh [--duration S] [--out DIR] NAME=PROGRAM...
# Writes DIR/concurrent_runs.csv and .md (default benchmarks/results).
set -euo pipefail
cd "$(dirname "$0")/.."
duration=0.5
out=benchmarks/results
programs=()
while (($#)); do
  case "$1" in
    --duration) duration="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *=*) programs+=("$1"); shift ;;
    *) echo "concurrent_runs.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
((${#programs[@]})) || { echo "concurrent_runs.sh: give NAME=PROGRAM" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$duration" "$work/crane_small.json" <<'PY'
import json, sys
s = json.load(open("demos/scenes/crane_small.json"))
s["simulation"]["duration"] = float(sys.argv[1])
json.dump(s, open(sys.argv[2], "w"))
PY
csv="$out/concurrent_runs.csv"
echo "build,case,run,wall_s,magnetic_ms_mean,rigid_ms_mean" >"$csv"
one() {  # PROGRAM DIR: runs, then prints wall_s,T_m,T_r
  local start end
  start=$(date +%s.%N)
  "$1" run "$work/crane_small.json" --out "$2" --frames no --quiet yes --backend cpu >/dev/null 2>&1
  end=$(date +%s.%N)
  python3 -c "import json,sys; s=json.load(open('$2/summary.json')); print('%.3f,%.3f,%.3f' % ($end-$start, s['magnetic_ms']['mean'], s['rigid_ms']['mean']))"
}
for entry in "${programs[@]}"; do
  name=${entry%%=*}
  program=${entry#*=}
  for repeat in 1 2; do
    echo "$name,alone,$repeat,$(one "$program" "$work/$name-alone")" >>"$csv"
    one "$program" "$work/$name-a" >"$work/a.txt" &
    a=$!
    one "$program" "$work/$name-b" >"$work/b.txt" &
    b=$!
    wait $a $b
    echo "$name,together,${repeat}a,$(cat "$work/a.txt")" >>"$csv"
    echo "$name,together,${repeat}b,$(cat "$work/b.txt")" >>"$csv"
  done
done
python3 - "$csv" "$out/concurrent_runs.md" "$duration" <<'PY'
import csv, sys, platform, os
rows = list(csv.DictReader(open(sys.argv[1])))
builds = []
for r in rows:
    if r["build"] not in builds:
        builds.append(r["build"])
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
lines = ["# Two runs at once against one alone", "",
         "`benchmarks/concurrent_runs.sh` on %s (%d cores), crane_small shortened to %s s, "
         "`--frames no --backend cpu`, default threads; wall time per run (s), T_m and T_r means (ms)." %
         (cpu, os.cpu_count(), sys.argv[3]), "",
         "| build | alone wall (s) | together wall (s), each | together / alone | T_m alone | T_m together |",
         "|---|---|---|---|---|---|"]
for b in builds:
    alone = [float(r["wall_s"]) for r in rows if r["build"] == b and r["case"] == "alone"]
    together = [float(r["wall_s"]) for r in rows if r["build"] == b and r["case"] == "together"]
    tm_a = [float(r["magnetic_ms_mean"]) for r in rows if r["build"] == b and r["case"] == "alone"]
    tm_t = [float(r["magnetic_ms_mean"]) for r in rows if r["build"] == b and r["case"] == "together"]
    ma, mt = min(alone), max(together)
    lines.append("| %s | %s | %s | %.2f (worst) | %.2f | %.2f |" % (
        b, ", ".join("%.2f" % x for x in alone), ", ".join("%.2f" % x for x in together), mt / ma,
        sum(tm_a) / len(tm_a), sum(tm_t) / len(tm_t)))
open(sys.argv[2], "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
