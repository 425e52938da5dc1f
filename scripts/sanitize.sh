#!/usr/bin/env bash
# The sanitizer job of CI (docs/development.md, "Build and CI cost"): the CMake preset `asan`
# (clang-14, -fsanitize=address,undefined at -O1) builds a subset of the test suites (the QP solvers,
# the state estimator) and runs them; the fuzzers cover HqpWbc and the controller tick under
# ASan+UBSan (docs/development.md).
# Any ASan/UBSan report fails the test binary. Extra arguments replace the list of test targets.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(test_qp_dual test_qp_random test_state_estimator)
cd "$root"
bash "$root/scripts/setup.sh" --fuzz >/dev/null   # clang-14 and its sanitizer runtimes
cache=build-asan/CMakeCache.txt   # a folder configured by GCC before the preset named clang-14
if [ -f "$cache" ] && ! grep -q '^CMAKE_CXX_COMPILER:[A-Z]*=.*clang++-14$' "$cache"; then
  rm -rf build-asan
fi
cmake --preset asan >/dev/null
if [ $# -eq 0 ]; then
  cmake --build build-asan -j"$(nproc)" --target hqp_asan_subset   # the targets in parallel
else
  cmake --build build-asan -j"$(nproc)" --target "${targets[@]}"
fi
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The binaries run side by side (each is single-threaded); results are printed in list order.
log=build-asan/sanitize-logs
mkdir -p "$log"
for t in "${targets[@]}"; do
  bin=$(find build-asan/tests -type f -name "$t" -perm -u+x | head -1)
  ( set +e; "$bin" --gtest_brief=1 >"$log/$t.txt" 2>&1; echo $? >"$log/$t.rc" ) &
  while [ "$(jobs -rp | wc -l)" -ge "$(nproc)" ]; do wait -n || true; done
done
wait
status=0
for t in "${targets[@]}"; do
  rc=$(cat "$log/$t.rc")
  echo "== asan $t: $(grep -E '^\[  (PASSED|FAILED) ' "$log/$t.txt" | tr '\n' ' ')exit code $rc"
  if [ "$rc" -ne 0 ]; then
    status=1
    grep -E "ERROR: AddressSanitizer|runtime error|FAILED" "$log/$t.txt" | head -5 | sed 's/^/   /'
  fi
done
exit $status
