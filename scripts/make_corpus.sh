#!/usr/bin/env bash
# Generates the HqpWbc instance corpus (docs/benchmarks.md, "Instance corpus") into
# $HQP_BUILD_DIR/corpus (default build/corpus), from the seed list bench/data/corpus.txt:
# one sim_demo recording per `scenario` line (family walker3_scenarios), then hqp_corpus
# derives the stress and degenerate families from them and checks the whole corpus.
#   bash scripts/make_corpus.sh            # builds sim_demo and hqp_corpus if needed
#   JOBS=2 bash scripts/make_corpus.sh     # simulations at a time (default: 2)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"
seeds="$root/bench/data/corpus.txt"
out="$build/corpus"
jobs="${JOBS:-2}"
if [ ! -x "$build/sim_demo/sim_demo" ] || [ ! -x "$build/tools/hqp_corpus" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" -j"$jobs" --target sim_demo hqp_corpus
fi
mkdir -p "$out/scenarios"
# One simulation per scenario line: NAME run=S start=S duration=S every=N.
record() {
  local name=$1; shift
  local run="" start="" dur="" every=""
  for kv in "$@"; do
    case $kv in
      run=*) run=${kv#run=} ;; start=*) start=${kv#start=} ;;
      duration=*) dur=${kv#duration=} ;; every=*) every=${kv#every=} ;;
    esac
  done
  ("$build/sim_demo/sim_demo" --scenario "$name" --set duration="$run" --no-video --no-plots \
      --out "$out/scenarios/$name.run" --record "$out/scenarios/$name.hqprec" \
      --record-start "$start" --record-duration "$dur" --record-every "$every") \
    >"$out/scenarios/$name.log" 2>&1 || { echo "sim_demo $name failed: $out/scenarios/$name.log"; return 1; }
  echo "recorded $name"
}
pids=()
while read -r family name rest; do
  [ "$family" = scenario ] || continue
  record "$name" $rest &
  pids+=($!)
  if [ "${#pids[@]}" -ge "$jobs" ]; then wait "${pids[0]}"; pids=("${pids[@]:1}"); fi
done < <(sed 's/#.*//' "$seeds")
for p in "${pids[@]}"; do wait "$p"; done
"$build/tools/hqp_corpus" generate --seeds "$seeds" --scenarios "$out/scenarios" --out "$out"
"$build/tools/hqp_corpus" check "$out"
