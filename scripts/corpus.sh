#!/usr/bin/env bash
# The HqpWbc instance corpus (docs/benchmarks.md, "Instance corpus").
#   bash scripts/corpus.sh make      # generate into $HQP_BUILD_DIR/corpus (default build/corpus)
#                                    # from bench/data/corpus.txt, then check it (about 1 min)
#   bash scripts/corpus.sh check     # exactness only: hqp_corpus check build/corpus
#   bash scripts/corpus.sh oracle    # every level against an independent optimum (scipy,
#                                    # tools/hqp_oracle.py; about 1 min)
#   bash scripts/corpus.sh bench [ARGS]   # BM_Corpus + BM_PeerWarm, pinned, 5 repetitions
#   bash scripts/corpus.sh compare OLD_BENCH_HQP NEW_BENCH_HQP [ROUNDS]
#       two bench_hqp binaries (e.g. before and after a change) alternated ROUNDS times
#       (default 5) on one pinned core; prints per family the medians over the rounds and
#       old/new, and the peers of each binary (BM_PeerWarm, and the corpus peer) as a check
#       that the machine did not drift between them. OLD_CORPUS_DIR=DIR gives the old binary
#       another copy of the corpus (below), NEW_CORPUS_DIR=DIR the new one (e.g. steady).
#   bash scripts/corpus.sh steady DIR   # the families into DIR with each instance warm-started
#       from the working sets its own solve ends with (a controller's next tick on an unchanged
#       problem; docs/hqp-tuning.md, "The steady state")
#   bash scripts/corpus.sh reformulate DIR [SEED]  # the families into DIR written as another
#       formulation of the same hierarchies: variables permuted, rows rescaled (same optima up
#       to the permutation, other rounding; docs/hqp-tuning.md, "Reformulated corpus"). Then
#       `hqp_corpus check DIR`, or compare with NEW_CORPUS_DIR=DIR (OLD_CORPUS_DIR: its v2 copy)
#   bash scripts/corpus.sh v2 DIR [SRC]  # the corpus (or the files in SRC) as format version 2
#       into DIR, for a bench_hqp from before version 3 (e.g. 3c579bd, before the deferred
#       path): the same instances without the header's defer_constraints field
#       (docs/recording.md)
# make: one sim_demo recording per `scenario` line (family walker3_scenarios), then hqp_corpus
# derives the stress and degenerate families from them. JOBS=N simulations at a time (2).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"
seeds="$root/bench/data/corpus.txt"
out="$build/corpus"
jobs="${JOBS:-2}"
cmd="${1:-make}"; shift || true
cpu=$(($(nproc) - 1))
pin=(); command -v taskset >/dev/null && pin=(taskset -c "$cpu")
need() {  # build the targets that are missing
  local missing=()
  for t in "$@"; do
    case $t in sim_demo) f="$build/sim_demo/sim_demo" ;; hqp_corpus) f="$build/tools/hqp_corpus" ;;
      bench_hqp) f="$build/bench/hqp/bench_hqp" ;; esac
    [ -x "$f" ] || missing+=("$t")
  done
  [ "${#missing[@]}" -eq 0 ] && return
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DHQP_BUILD_BENCHMARKS=ON >/dev/null
  cmake --build "$build" -j"$jobs" --target "${missing[@]}"
}
filter='Corpus|PeerWarm'
case $cmd in
  check)
    need hqp_corpus
    exec "$build/tools/hqp_corpus" check "$out" ;;
  oracle)
    need hqp_corpus
    tmp=$(mktemp -d)
    rc=0
    for f in walker3_scenarios stress degenerate; do
      [ -f "$out/$f.hqprec" ] || continue
      "$build/tools/hqp_corpus" dump "$out/$f.hqprec" "$tmp/$f.json" >/dev/null
      /usr/bin/python3 "$root/tools/hqp_oracle.py" "$tmp/$f.json" || rc=1
    done
    rm -rf "$tmp"
    exit $rc ;;
  bench)
    need bench_hqp
    [ -f "$out/stress.hqprec" ] || bash "$0" make
    exec "${pin[@]}" "$build/bench/hqp/bench_hqp" --benchmark_filter="$filter" --benchmark_repetitions=5 \
      --benchmark_report_aggregates_only=true "$@" ;;
  compare)
    old=$1 new=$2 rounds=${3:-5}
    need hqp_corpus
    [ -f "$out/stress.hqprec" ] || bash "$0" make
    tmp=$(mktemp -d)
    for r in $(seq 1 "$rounds"); do
      for which in old new; do
        bin=$old; [ $which = new ] && bin=$new
        dir=${NEW_CORPUS_DIR:-$out}; [ $which = old ] && dir=${OLD_CORPUS_DIR:-$out}
        HQP_CORPUS_DIR="$dir" "${pin[@]}" "$bin" --benchmark_filter="$filter" \
          --benchmark_format=json --benchmark_out="$tmp/$which.$r.json" >/dev/null
        echo "round $r: $which done"
      done
    done
    python3 - "$tmp" "$rounds" <<'PY'
import json, statistics, sys
tmp, rounds = sys.argv[1], int(sys.argv[2])
runs = {w: [json.load(open(f"{tmp}/{w}.{r}.json"))["benchmarks"] for r in range(1, rounds + 1)] for w in ("old", "new")}
def med(w, name, key):
    v = [b[key] for run in runs[w] for b in run if b["name"] == name and key in b]
    return statistics.median(v) if v else float("nan")
names = [b["name"] for b in runs["old"][0]]
print(f"{'benchmark':49} {'counter':14} {'old':>10} {'new':>10} {'old/new':>8}")
for n in names:
    keys = ["hqp_p50_us", "hqp_p99_us", "peer_p50_us"] if "Corpus" in n else ["real_time"]
    for k in keys:
        o, w = med("old", n, k), med("new", n, k)
        print(f"{n.replace('/min_time:1.000', ''):49} {k:14} {o:10.2f} {w:10.2f} {o / w:8.3f}")
PY
    rm -rf "$tmp"
    exit 0 ;;
  steady)
    dest=${1:?usage: corpus.sh steady DIR}
    need hqp_corpus
    [ -f "$out/stress.hqprec" ] || bash "$0" make
    exec "$build/tools/hqp_corpus" steady "$out" "$dest" ;;
  reformulate)
    dest=${1:?usage: corpus.sh reformulate DIR [SEED]}
    need hqp_corpus
    [ -f "$out/stress.hqprec" ] || bash "$0" make
    exec "$build/tools/hqp_corpus" reformulate "$out" "$dest" --seed "${2:-1}" ;;
  v2)
    dest=${1:?usage: corpus.sh v2 DIR [SRC]}
    src=${2:-$out}
    if [ -n "${2:-}" ]; then [ -f "$src/stress.hqprec" ] || { echo "$src: no stress.hqprec" >&2; exit 2; }
    else [ -f "$out/stress.hqprec" ] || bash "$0" make; fi
    mkdir -p "$dest"
    python3 - "$src" "$dest" <<'PY'
import glob, os, struct, sys
src, dest = sys.argv[1], sys.argv[2]
for f in sorted(glob.glob(f"{src}/*.hqprec")):
    d = open(f, "rb").read()
    version, _, levels = struct.unpack_from("<Iii", d, 8)
    if d[:8] != b"HQPPROB\n" or version != 3:
        sys.exit(f"{f}: not a version 3 recording")
    # magic, version, nx, levels, task and constraint rows per level, rank_tol, warm_start,
    # dual_last_level; then version 3's defer_constraints (4 bytes), dropped.
    at = 8 + 12 + 8 * levels + 8 + 4 + 4
    open(os.path.join(dest, os.path.basename(f)), "wb").write(
        d[:8] + struct.pack("<I", 2) + d[12:at] + d[at + 4:])
    print(f"{dest}/{os.path.basename(f)}: version 2")
PY
    exit 0 ;;
  make) ;;
  *) echo "usage: corpus.sh make|check|oracle|bench [ARGS]|compare OLD NEW [ROUNDS]|steady DIR|reformulate DIR [SEED]|v2 DIR [SRC]" >&2; exit 2 ;;
esac
need sim_demo hqp_corpus
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
# Mismatches are findings about the solver, not a failed generation: reported, exit 0.
"$build/tools/hqp_corpus" check "$out" || echo "corpus written to $out; the check above lists mismatches"
