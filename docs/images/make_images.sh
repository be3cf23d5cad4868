#!/usr/bin/env bash
# Renders the representative frames of each paper scene (and of
# examples/horseshoe_lift.json) shown in README.md and
# docs/scenes.md: docs/images/<scene>.png, three or four frames side by side
# (400 x 300 each, with the renderer's caption band and legend: docs/rendering.md).
# Needs a build with the renderer (bash scripts/build.sh; the odemag and
# odemag_png_row targets); no ImageMagick. The crane is shown with 24 field
# lines (a copy of the scene with render.field_lines set; the scene file is
# unchanged). Usage:
#   bash docs/images/make_images.sh [SCENE ...]     (default: all scenes)
# ODEMAG_BUILD=DIR uses another build directory (default: build).
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${ODEMAG_BUILD:-build}
odemag=$build/bin/odemag
row=$build/bin/odemag_png_row
for program in "$odemag" "$row"; do
  [ -x "$program" ] || { echo "make_images.sh: $program not found: build it first" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# scene: times (s) of the frames to show
declare -A times=(
  [ball_chain]="0.5 2.0 4.0"
  [ball_chain_no_induction]="0.5 2.0 4.0"
  [wood_plate]="0.2 1.0 2.0"
  [iron_plate]="0.5 1.4 3.0"
  [thin_iron_plate]="0.2 1.0 2.0"
  [thick_iron_plate]="0.2 1.0 2.0"
  [nail_and_balls]="0.8 2.4 5.0"
  [nail_no_anisotropy]="0.8 2.4 5.0"
  [crane]="1.2 2.9 3.9 5.0"
  [horseshoe_lift]="0.3 1.4 2.8"
)
# scenes drawn with field lines although the scene file has them off: how many
declare -A field_lines=([crane]=24)
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(ball_chain ball_chain_no_induction wood_plate iron_plate thin_iron_plate
                                   thick_iron_plate nail_and_balls nail_no_anisotropy crane horseshoe_lift)
rate=10
for s in "${scenes[@]}"; do
  echo "== $s"
  scene=demos/scenes/$s.json
  [ -f "$scene" ] || scene=examples/$s.json  # the examples (horseshoe_lift: a mesh)
  if [ -n "${field_lines[$s]:-}" ]; then
    python3 - "$scene" "$work/$s.json" "${field_lines[$s]}" <<'EOF'
import json, sys
scene = json.load(open(sys.argv[1]))
scene.setdefault("render", {}).update(field_lines=True, field_line_count=int(sys.argv[3]))
json.dump(scene, open(sys.argv[2], "w"), indent=1)
EOF
    scene=$work/$s.json
  fi
  last=0
  for t in ${times[$s]}; do last=$t; done
  "$odemag" run "$scene" --out "$work/$s" --frame-rate $rate --duration "$last" --width 400 --height 300 \
    --quiet yes
  frames=()
  for t in ${times[$s]}; do
    frames+=("$(printf '%s/%s/frame_%05d.png' "$work" "$s" "$(python3 -c "print(round($t * $rate))")")")
  done
  "$row" "docs/images/$s.png" "${frames[@]}" --gap 4
  ls -l "docs/images/$s.png"
done
