#!/usr/bin/env bash
# Builds and runs every benchmark (Release, -O3 -march=native), median of 10 repetitions.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${HQP_BUILD_DIR:-$root/build}"
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DHQP_BUILD_BENCHMARKS=ON
cmake --build "$build" -j"$(nproc)"
for b in "$build"/bench/*/bench_*; do
  [ -x "$b" ] || continue
  echo "== $(basename "$b")"
  # Pinned to one core where taskset is available (util-linux), so the figures are comparable.
  pin=(); command -v taskset >/dev/null && pin=(taskset -c "$(($(nproc) - 1))")
  "${pin[@]}" "$b" --benchmark_repetitions=10 --benchmark_report_aggregates_only=true "$@"
done
