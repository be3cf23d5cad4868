#!/usr/bin/env bash
# Installs the Debian 12 packages odemag needs, only those that are missing.
# Runs as root (or with sudo).
# Usage: scripts/install-deps.sh [--main | --sanitize] [extra packages...]
# --main: only what the main job builds and runs (scripts/demo.sh: the odemag
# program with the renderer, demo_magnetization_curve and gnuplot for its
# plot; demo.sh adds ffmpeg for its video); without it, also what the tests,
# the benchmarks and the Python package need (scripts/test.sh).
# --sanitize adds what scripts/sanitize.sh needs: clang-14 with libFuzzer and
# the sanitizer runtimes, and clang's OpenMP (libomp) for the fuzz build.
set -euo pipefail

main_only=0
sanitize_packages=()
if [[ "${1:-}" == --main ]]; then
  main_only=1
  shift
elif [[ "${1:-}" == --sanitize ]]; then
  sanitize_packages=(clang-14 libclang-rt-14-dev libomp-14-dev)
  shift
fi

packages=(
  build-essential cmake pkg-config
  libode-dev libeigen3-dev libosmesa6-dev libpng-dev nlohmann-json3-dev libassimp-dev
  libfreetype-dev fonts-dejavu-core
  gnuplot-nox
)
if ((!main_only)); then
  packages+=(
    libgtest-dev libbenchmark-dev
    pybind11-dev python3-dev python3-numpy python3-pytest python3-pyode  # the Python package and its tests (docs/python.md)
    python3-distributed  # the sweep runners (python/odemag/sweeps.py) and their tests
    slurm-wlm  # python/tests/test_slurm.py starts a single-node Slurm (skips where it cannot)
  )
fi
packages+=("${sanitize_packages[@]}" "$@")

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "odemag: installing ${missing[*]}" >&2
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
