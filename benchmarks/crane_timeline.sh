#!/usr/bin/env bash
# The crane step by step, an earlier build against the current one, one after
# the other on the same machine (docs/benchmarks.md):
#
#   benchmarks/crane_timeline.sh --before PATH [--after PATH] [--duration T] [--out DIR]
#                                [--before-scene FILE] [--after-scene FILE]
#
# PATH: a crane_timeline program (benchmarks/crane_timeline.cpp); --after
# defaults to build-bench/bin/crane_timeline (built when missing). The scenes
# default to each program's own demos/scenes/crane.json. Writes
# DIR/crane_timeline.csv (rows labelled "before" and "after"),
# DIR/crane_phases.md (each run's phase table) and DIR/crane_timeline.png
# (gnuplot). DIR defaults to benchmarks/results. Each full run takes 5-12 min
# on the 2-core development VM.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out="$root/benchmarks/results"
before="" after="" duration="" before_scene="" after_scene=""
usage() { sed -n '2,14p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
source "$root/benchmarks/bench_common.sh"
read_options "before after duration out before-scene after-scene" "" "$@"
[ -n "$before" ] || { echo "crane_timeline.sh: --before PATH is required" >&2; usage >&2; exit 2; }
if [ -z "$after" ]; then
  bench_program crane_timeline after
fi
for p in "$before" "$after"; do
  [ -x "$p" ] || { echo "crane_timeline.sh: $p is not an executable" >&2; exit 2; }
done
export OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
args=(--threads 2)
[ -z "$duration" ] || args+=(--duration "$duration")
before_args=("${args[@]}")
after_args=("${args[@]}")
[ -z "$before_scene" ] || before_args+=(--scene "$before_scene")
[ -z "$after_scene" ] || after_args+=(--scene "$after_scene")
"$before" "${before_args[@]}" --label before --csv "$work/before.csv" > "$work/before.md"
"$after" "${after_args[@]}" --label after --csv "$work/after.csv" > "$work/after.md"
{ cat "$work/before.csv"; tail -n +2 "$work/after.csv"; } > "$out/crane_timeline.csv"
model=$(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')
{
  echo "Machine: $model, $(nproc) logical CPUs, 2 OpenMP threads (OMP_WAIT_POLICY=passive). Per rigid step (1 ms), means over each phase of the crane's time line; times in ms; dense evaluation: one responsive-field evaluation of the same cells (MagneticBackend::responsive_field) measured in the same run every 50 steps; T_m / evaluation: T_m in units of it."
  echo
  echo "Before ($before${before_scene:+, $before_scene}):"
  echo
  cat "$work/before.md"
  echo
  echo "After ($after${after_scene:+, $after_scene}):"
  echo
  cat "$work/after.md"
} > "$out/crane_phases.md"
if command -v gnuplot >/dev/null; then
  (cd "$root" && gnuplot -e "R='$out/'" benchmarks/plot_crane_timeline.gp)
fi
cat "$out/crane_phases.md"
