#!/usr/bin/env bash
# Renders the representative frames of each paper scene shown in README.md and
# docs/scenes.md: docs/images/<scene>.png, three or four frames side by side
# (320 x 240 each, captions from the renderer). Needs a build with the renderer
# (bash scripts/build.sh) and ImageMagick's `montage`. Usage:
#   bash docs/images/make_images.sh [SCENE ...]     (default: all scenes)
set -euo pipefail
cd "$(dirname "$0")/../.."
odemag=build/bin/odemag
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
)
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(ball_chain ball_chain_no_induction wood_plate iron_plate thin_iron_plate
                                   thick_iron_plate nail_and_balls nail_no_anisotropy crane)
rate=10
for s in "${scenes[@]}"; do
  echo "== $s"
  "$odemag" run "demos/scenes/$s.json" --out "$work/$s" --frame-rate $rate --width 320 --height 240 \
    --quiet yes
  frames=()
  for t in ${times[$s]}; do
    frames+=("$(printf '%s/%s/frame_%05d.png' "$work" "$s" "$(python3 -c "print(round($t * $rate))")")")
  done
  montage "${frames[@]}" -tile "${#frames[@]}x1" -geometry +2+0 -background white "docs/images/$s.png"
done
