#!/usr/bin/env bash
# Installs what is missing, builds everything (scripts/build.sh: the tests,
# the benchmarks and the Python package too, also in a build/ that
# scripts/demo.sh configured without them), and runs the test suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
(cd build && ctest --output-on-failure -j "$(nproc)")
