#!/usr/bin/env bash
# Installs dependencies, builds, and runs the main job (see README).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"

bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j"$(nproc)" --target hqp_demo
"$build/sim_demo/hqp_demo" "$@"
