#!/usr/bin/env bash
# Builds the libFuzzer harnesses of tests/fuzz with clang-14 and runs each for N minutes
# (default 10), one after the other (docs/fuzzing.md). Prints, per fuzzer, the executions,
# the corpus size and any finding (crash-*/leak-*/timeout-* files, kept in the work folder).
#   scripts/fuzz.sh [minutes] [fuzzer...]
#   scripts/fuzz.sh --ci          the CI regression: the fixed seed corpus, then a fixed-seed
#                                 mutation run of a fixed number of inputs per fuzzer (the same
#                                 inputs on every machine, ~20 s each on the 2-core CI machine),
#                                 with the saved findings of tests/fuzz/findings in the corpus
# Exit code 1 if any fuzzer reported a finding. Work folder: $HQP_FUZZ_DIR (default build-fuzz/run).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_FUZZ_BUILD_DIR:-$root/build-fuzz}"
ci=0
minutes=10
if [ "${1:-}" = "--ci" ]; then ci=1; shift; elif [[ "${1:-}" =~ ^[0-9.]+$ ]]; then minutes=$1; shift; fi
all=(fuzz_active_set_qp fuzz_dual_qp fuzz_hqp fuzz_controller_tick fuzz_urdf_generator)
fuzzers=("$@")
[ ${#fuzzers[@]} -gt 0 ] || fuzzers=("${all[@]}")
work="${HQP_FUZZ_DIR:-$build/run}"

bash "$root/scripts/setup.sh" --fuzz
# The preset `fuzz` (CMakePresets.json: clang-14, -O1, fuzzers only) into $build.
cmake -S "$root" --preset fuzz -B "$build" >/dev/null
if [ $# -eq 0 ]; then
  cmake --build "$build" -j"$(nproc)" --target fuzzers   # all of them, in parallel
else
  cmake --build "$build" -j"$(nproc)" --target "${fuzzers[@]}"
fi

# One fuzzer run: prepares its corpus, runs it, leaves log.txt and a one-line result in summary.txt.
run_one() {
  local f=$1 dir="$work/$1" pat p file runs secs execs findings rc start
  mkdir -p "$dir/corpus" "$dir/artifacts"
  rm -f "$dir"/artifacts/* "$dir/summary.txt"
  if [ $ci -eq 1 ]; then
    rm -rf "$dir/corpus" && mkdir -p "$dir/corpus"
  fi
  python3 "$root/tests/fuzz/make_seeds.py" "$f" "$dir/corpus" 300 >/dev/null
  if [ $ci -eq 1 ]; then
    # Every saved finding is replayed by the fuzzer(s) that decode it (docs/fuzzing.md).
    case "$f" in
      fuzz_active_set_qp|fuzz_dual_qp) pat='active_set_qp_* dual_*' ;;
      fuzz_hqp) pat='hqp_*' ;; fuzz_urdf_generator) pat='urdf_generator_*' ;; *) pat='' ;;
    esac
    for p in $pat; do
      for file in "$root"/tests/fuzz/findings/$p; do [ -f "$file" ] && cp "$file" "$dir/corpus/finding_$(basename "$file")"; done
    done
  fi
  local opts=(-artifact_prefix="$dir/artifacts/" -print_final_stats=1 -max_len=4096)
  [ "$f" = fuzz_urdf_generator ] && opts+=(-dict="$root/tests/fuzz/urdf.dict")
  if [ $ci -eq 1 ]; then
    # Deterministic: a count of runs, not a wall time (a slower machine must not reach other inputs).
    case "$f" in
      fuzz_active_set_qp) runs=800 ;; fuzz_dual_qp) runs=20000 ;; fuzz_hqp) runs=400 ;;
      fuzz_controller_tick) runs=600 ;; *) runs=25000 ;;
    esac
    opts+=(-seed=1 -runs="$runs")
  else
    opts+=(-max_total_time="$(python3 -c "print(int(float('$minutes') * 60))")")
  fi
  start=$(date +%s)
  set +e
  "$build/tests/fuzz/$f" "${opts[@]}" "$dir/corpus" >"$dir/log.txt" 2>&1
  rc=$?
  set -e
  secs=$(( $(date +%s) - start ))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log.txt" | tail -1)
  findings=$(find "$dir/artifacts" -type f | wc -l)
  echo "$rc $findings == $f: ${execs:-?} executions in $secs s, corpus $(find "$dir/corpus" -type f | wc -l) files, findings $findings, exit code $rc" >"$dir/summary.txt"
}

# The CI regression runs the fuzzers side by side, one per core (each is single-threaded);
# a timed campaign runs them one after the other so each gets its minutes of a whole core.
parallel=1
[ $ci -eq 1 ] && parallel=$(nproc)
running=0
for f in "${fuzzers[@]}"; do
  run_one "$f" &
  running=$((running + 1))
  if [ $running -ge "$parallel" ]; then wait -n || true; running=$((running - 1)); fi
done
wait

status=0
for f in "${fuzzers[@]}"; do
  dir="$work/$f"
  if [ ! -f "$dir/summary.txt" ]; then
    echo "== $f: did not run to the end (setting up its corpus failed)"; status=1; continue
  fi
  read -r rc findings line <"$dir/summary.txt"
  echo "$line"
  if [ "$rc" -ne 0 ] || [ "$findings" -ne 0 ]; then
    status=1
    grep -m3 -E "FUZZ FINDING|ERROR: AddressSanitizer|runtime error|ERROR: libFuzzer" "$dir/log.txt" | sed 's/^/   /' || true
    find "$dir/artifacts" -type f | sed 's/^/   input: /'
  fi
done
exit $status
