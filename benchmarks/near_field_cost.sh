#!/usr/bin/env bash
# What the near-field corrections cost (docs/benchmarks.md): each scene run
# with solver.near_field false (point dipoles, labelled "old" in the tables)
# and true (the default, labelled "new"), one after the other on the same
# machine and build, full durations, frames off; T_m per rigid step (median,
# mean) and the ratio new / old.
#
#   benchmarks/near_field_cost.sh [--odemag PATH] [--threads N] [--scenes "ball_chain crane"]
#                                 [--duration S] [--out DIR]
#
# Writes DIR/near_field_cost.csv and .md (DIR defaults to benchmarks/results).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
odemag="$root/build/bin/odemag"
threads=2
scenes="ball_chain crane"
duration=""
out="$root/benchmarks/results"
while [ $# -gt 0 ]; do
  case "$1" in
    --odemag) odemag=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,10p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "near_field_cost.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$odemag" ] || { echo "near_field_cost.sh: $odemag is not an executable (build first)" >&2; exit 2; }
export OMP_NUM_THREADS=$threads OMP_WAIT_POLICY=passive
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
args=()
[ -n "$duration" ] && args+=(--duration "$duration")
for scene in $scenes; do
  for near in false true; do
    python3 -c "
import json, sys
d = json.load(open(sys.argv[1])); d.setdefault('solver', {})['near_field'] = sys.argv[2] == 'true'
json.dump(d, open(sys.argv[3], 'w'))" "$root/demos/scenes/$scene.json" "$near" "$work/${scene}_$near.json"
    echo "near_field_cost.sh: $scene near_field=$near" >&2
    "$odemag" run "$work/${scene}_$near.json" --out "$work/${scene}_$near" --frames no --quiet yes \
      --backend cpu --threads "$threads" "${args[@]}" 2>/dev/null
  done
done
python3 - "$work" "$out" "$threads" "$(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)" $scenes <<'PY'
import json, os, sys
work, out, threads, commit = sys.argv[1:5]
scenes = sys.argv[5:]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "unknown CPU")
machine = f"{cpu}, {os.cpu_count()} logical CPUs, {threads} OpenMP threads"
rows = []
for s in scenes:
    old = json.load(open(os.path.join(work, f"{s}_false", "summary.json")))
    new = json.load(open(os.path.join(work, f"{s}_true", "summary.json")))
    r = {"scene": s, "steps": new["steps"]}
    for k in ("median", "mean", "p90"):
        r[f"tm_{k}_old_ms"] = old["magnetic_ms"][k]
        r[f"tm_{k}_new_ms"] = new["magnetic_ms"][k]
        r[f"ratio_{k}"] = new["magnetic_ms"][k] / old["magnetic_ms"][k]
    r["iterations_mean_old"] = old["iterations"]["mean"]
    r["iterations_mean_new"] = new["iterations"]["mean"]
    r["outcomes_old"] = json.dumps(old["outcomes"], sort_keys=True)
    r["outcomes_new"] = json.dumps(new["outcomes"], sort_keys=True)
    rows.append(r)
cols = list(rows[0].keys())
with open(os.path.join(out, "near_field_cost.csv"), "w") as f:
    f.write(",".join(cols) + ",machine\n")
    for r in rows:
        f.write(",".join('"' + str(r[c]).replace('"', "'") + '"' if c.startswith("outcomes") else f"{r[c]:.6g}" if isinstance(r[c], float) else str(r[c]) for c in cols) + f',"{machine}"\n')
with open(os.path.join(out, "near_field_cost.md"), "w") as f:
    f.write(f"Machine: {machine}; odemag {commit}; old = solver.near_field false, new = true, run one after the other. T_m per rigid step in ms; ratio = new / old.\n\n")
    f.write("| scene | steps | T_m median old | new | ratio | T_m mean old | new | ratio | iterations mean old / new | outcomes old | outcomes new |\n|---|---|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        f.write(f"| {r['scene']} | {r['steps']} | {r['tm_median_old_ms']:.3g} | {r['tm_median_new_ms']:.3g} | {r['ratio_median']:.2f} | "
                f"{r['tm_mean_old_ms']:.3g} | {r['tm_mean_new_ms']:.3g} | {r['ratio_mean']:.2f} | "
                f"{r['iterations_mean_old']:.3g} / {r['iterations_mean_new']:.3g} | {r['outcomes_old']} | {r['outcomes_new']} |\n")
print(open(os.path.join(out, "near_field_cost.md")).read())
PY
