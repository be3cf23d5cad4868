#!/usr/bin/env bash
# Configures and builds odemag (Release) into BUILD_DIR (default: build).
# Usage: scripts/build.sh [extra cmake arguments...] [-- TARGET...]
# Without targets it builds everything, the tests, the benchmarks and the
# Python package included (also in a build/ that scripts/demo.sh configured
# without them); with targets after "--", only those (the main job).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build}"
configure=()
targets=()
while (($#)); do
  if [[ "$1" == -- ]]; then
    shift
    targets=("$@")
    break
  fi
  configure+=("$1")
  shift
done
if ((${#targets[@]} == 0)); then
  configure=(-DODEMAG_BUILD_TESTS=ON -DODEMAG_BUILD_BENCHMARKS=ON -DODEMAG_BUILD_PYTHON=ON "${configure[@]}")
fi
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "${configure[@]}" >/dev/null
if ((${#targets[@]})); then
  cmake --build "$build_dir" -j "$(nproc)" --target "${targets[@]}"
else
  cmake --build "$build_dir" -j "$(nproc)"
fi
