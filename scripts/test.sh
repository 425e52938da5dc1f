#!/usr/bin/env bash
# Installs dependencies, configures, builds and runs every test with ctest.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"
jobs=$(nproc)

bash "$root/scripts/setup.sh"
start=$(date +%s)
# Benchmarks are built and run by scripts/bench.sh (-O3 -march=native builds take ~5 of the
# CI's minutes; docs/development.md "Build and CI cost").
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
      -DHQP_BUILD_TESTS=ON -DHQP_BUILD_BENCHMARKS=OFF -DHQP_BUILD_SIM_DEMO=ON
cmake --build "$build" -j"$jobs"
built=$(date +%s)

set +e
ctest --test-dir "$build" --output-on-failure -j"$jobs" --timeout 900
status=$?
set -e
end=$(date +%s)
echo
echo "== test summary: build $((built - start)) s, tests $((end - built)) s; ctest exit code $status =="
exit $status
