#!/usr/bin/env bash
# The main job (see README): installs the Debian packages, builds, and runs Walker3 in MuJoCo 2.2
# under the balance controller: 10 s of quiet standing, then a 10 N·s push along +X with a
# headless MP4. Outputs (CSV logs, summary, video) go to out/. Extra arguments go to both runs.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"
out="${HQP_OUT_DIR:-$root/out}"

bash "$root/scripts/setup.sh" --demo
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j"$(nproc)" --target hqp_sim hqp_demo

echo "== Walker3 model =="
"$build/sim_demo/hqp_demo" --iterations 1000 | tail -n 4
echo "== stand: 10 s of quiet standing =="
"$build/sim_demo/hqp_sim" --scenario stand --duration 10 --out "$out/stand" "$@"
echo "== push: 10 N·s along +X at t = 1 s (video in $out/push_x_10) =="
"$build/sim_demo/hqp_sim" --scenario stand --duration 4 --push 1:10:0 --out "$out/push_x_10" --video "$@"
