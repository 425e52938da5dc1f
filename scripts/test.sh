#!/usr/bin/env bash
# Installs dependencies, configures, builds and runs every test with ctest.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"
jobs=$(nproc)

bash "$root/scripts/setup.sh" --fuzz
start=$(date +%s)

# The sanitizer subset (preset asan) and the fuzzers' regression run (docs/development.md)
# start now, beside the main build. Each runs in a session of its own (setsid), so that a failing
# main build stops them with their compilers. Where Linux's autogroup scheduler is on (as on the
# machines this project is built on), each session gets an equal share of the CPU and nice acts
# only within it: the side jobs build and run during the main build and are done before ctest
# ends. Side jobs on idle time only (one session, nice 19) gave no shorter run: their builds
# waited for ctest's end (docs/development.md, "Build and CI cost"). Logs are printed at the end.
logs=$(mktemp -d)
setsid nice -n 19 bash "$root/scripts/sanitize.sh" >"$logs/asan.txt" 2>&1 &
asan_pid=$!
HQP_FUZZ_BUILD_DIR="${HQP_FUZZ_BUILD_DIR:-$root/build-fuzz}" \
  setsid nice -n 19 bash "$root/scripts/fuzz.sh" --ci >"$logs/fuzz.txt" 2>&1 &
fuzz_pid=$!
trap 'kill -- -$asan_pid -$fuzz_pid 2>/dev/null || true' EXIT
# Benchmarks are built and run by scripts/bench.sh (-O3 -march=native builds take ~5 of the
# CI's minutes; docs/development.md "Build and CI cost").
# The tests are compiled with clang-14 (installed by setup.sh --fuzz): their template-heavy units
# compile in about half GCC's CPU time (docs/development.md); so does the sanitizer subset
# (preset asan). GCC still builds the user project of Install.UserProject and the benchmarks.
# A build folder configured with another compiler (e.g. by demo.sh first) is reconfigured;
# demo.sh keeps what it finds.
cc=clang-14 cxx=clang++-14
cache="$build/CMakeCache.txt"
if [ -f "$cache" ] && ! grep -q "^CMAKE_CXX_COMPILER:[A-Z]*=.*$cxx\$" "$cache"; then
  echo "test.sh: $build was configured with another compiler; reconfiguring it for $cxx"
  rm -f "$cache"  # and every target's objects, so that none compiled by the other compiler is kept
  find "$build" -name CMakeFiles -type d -prune -exec rm -rf {} +
fi
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
      -DHQP_BUILD_TESTS=ON -DHQP_BUILD_BENCHMARKS=OFF -DHQP_BUILD_SIM_DEMO=ON
cmake --build "$build" -j"$jobs"
built=$(date +%s)

set +e
ctest --test-dir "$build" --output-on-failure -j"$jobs" --timeout 900
status=$?
tested=$(date +%s)
wait $asan_pid
asan=$?
wait $fuzz_pid
fuzz=$?
set -e
trap - EXIT
end=$(date +%s)
cat "$logs/asan.txt" "$logs/fuzz.txt"
rm -rf "$logs"
echo
echo "== sanitizer tests exit code $asan, fuzz regression exit code $fuzz (done $((end - start)) s after the start, $((end - tested)) s after ctest) =="
echo "== test summary: build $((built - start)) s, tests $((tested - built)) s; ctest exit code $status; total $((end - start)) s =="
[ $status -ne 0 ] || [ $asan -eq 0 ] || status=1
[ $status -ne 0 ] || [ $fuzz -eq 0 ] || status=1
exit $status
