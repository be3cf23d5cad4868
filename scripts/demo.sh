#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the default demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build/bin/odemag solve examples/bar_and_ball.json
