#!/usr/bin/env bash
# Installs dependencies, configures, builds and runs every test with ctest.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"
jobs=$(nproc)

bash "$root/scripts/setup.sh"
start=$(date +%s)
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
      -DHQP_BUILD_TESTS=ON -DHQP_BUILD_BENCHMARKS=ON -DHQP_BUILD_SIM_DEMO=ON
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
