// Real problem instances: replays the HqpWbc problems recorded in a MuJoCo run
// (bench/data/walker3_recording.hqprec, docs/recording.md) through HqpWbc, warm from each
// instance's recorded incoming working sets, as in the run (warm:1), or cold (warm:0), with the
// run's settings but the solver's current path (ProblemFileInfo::shippedSettings).
// Linked into bench_hqp so that the synthetic BM_HqpWarm runs in the same process and minutes:
//   taskset -c 1 bench_hqp --benchmark_filter='HqpReplay|HqpWarm/levels_1-4|FillOnly' \
//       --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Time columns: per iteration, loading the next instance (a 19 kB copy; BM_HqpReplayLoadOnly
// measures it) plus solve(), as BM_HqpWarm's include filling its tasks (BM_FillOnly).
// Counters, from steady_clock around solve() (total_*) and HqpWbc's per-level times
// (levelN_*): *_p50_us / *_p999_us, median and 99.9th percentile over every replayed solve
// (instances × passes; the p99.9 includes preemption of a shared machine); *_inst_p999_us,
// the 99.9th percentile over the instances of each instance's median over its passes (the
// hardest instances, free of preemption; with 200 instances, the slowest one);
// run_levels_sum_p50_us, the median of the level times recorded inside the simulation;
// mismatches, replays whose x* is off the recorded one by more than 1e-9 relative (0).
// Another recording of the same shape: HQP_REPLAY_FILE=path.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "hqp/problem_file.hpp"
#include "hqp/problem_instance.hpp"
#include "tasks/balance_hierarchy.hpp"
#include "walker3_model.hpp"

#ifndef HQP_RECORDING_FILE
#define HQP_RECORDING_FILE ""
#endif

namespace {

// The shape this replays: Walker3's hierarchy as its definition gives it (balance_hierarchy.hpp);
// a recording of another shape is refused by the reader with both shapes in the message.
using Replay = hqp::tasks::StackedHqpOf<hqp::tasks::BalanceHierarchy, hqp::tasks::ContactLayout<walker3::Robot, 2, 6>>;
using Instance = hqp::ProblemInstance<Replay>;
constexpr int L = Replay::num_levels;

struct Recording {
  hqp::ProblemFileInfo info;
  std::vector<Instance> instances;
  std::string error;
};

const Recording& recording() {
  static const Recording r = [] {
    Recording rec;
    const char* env = std::getenv("HQP_REPLAY_FILE");
    const std::string path = env != nullptr && *env != '\0' ? env : HQP_RECORDING_FILE;
    try {
      rec.instances = hqp::readProblemFile<Replay>(path, &rec.info);
      if (rec.instances.empty()) rec.error = path + ": no instances";
    } catch (const std::exception& e) {
      rec.error = e.what();
    }
    return rec;
  }();
  return r;
}

// q-quantile (nearest rank) of v; sorts v.
double quantile(std::vector<double>& v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

// Per-instance medians over the passes, then the q-quantile of those over the instances.
double instanceQuantile(std::vector<std::vector<double>>& per_instance, double q) {
  std::vector<double> med;
  for (auto& t : per_instance)
    if (!t.empty()) med.push_back(quantile(t, 0.5));
  return quantile(med, q);
}

void BM_HqpReplay(benchmark::State& state) {
  const Recording& rec = recording();
  if (!rec.error.empty()) {
    state.SkipWithError(rec.error.c_str());
    for (auto _ : state) {
    }
    return;
  }
  const bool warm = state.range(0) != 0;
  const auto& v = rec.instances;
  const std::size_t n = v.size();
  static std::unique_ptr<Replay> wbc;  // hundreds of KiB (docs/hqp.md): not on the stack
  if (!wbc) wbc = std::make_unique<Replay>(rec.info.shippedSettings());
  // Solve times, pooled (every replayed solve) and per instance; L levels + the whole solve.
  std::array<std::vector<double>, L + 1> pooled;
  std::array<std::vector<std::vector<double>>, L + 1> per_instance;
  const std::size_t expect = static_cast<std::size_t>(state.max_iterations);
  for (int p = 0; p <= L; ++p) {
    pooled[p].reserve(expect);
    per_instance[p].assign(n, {});
    for (auto& t : per_instance[p]) t.reserve(expect / n + 1);
  }
  long mismatches = 0, non_optimal = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    const Instance& in = v[k];
    hqp::loadInstance(in, *wbc, warm);  // counted in the time column: see BM_HqpReplayLoadOnly
    const auto t0 = std::chrono::steady_clock::now();
    const hqp::QpStatus s = wbc->solve();
    const auto t1 = std::chrono::steady_clock::now();
    const auto& r = wbc->result();
    const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
    pooled[L].push_back(us);
    per_instance[L][k].push_back(us);
    for (int p = 0; p < L; ++p) {
      pooled[p].push_back(r.levels[p].time_us);
      per_instance[p][k].push_back(r.levels[p].time_us);
    }
    const double dx = (r.x - in.result.x).lpNorm<Eigen::Infinity>() /
                      std::max(1.0, in.result.x.lpNorm<Eigen::Infinity>());
    if (dx > 1e-9) ++mismatches;
    if (s != hqp::QpStatus::Optimal) ++non_optimal;
    k = (k + 1) % n;
  }
  state.counters["instances"] = static_cast<double>(n);
  state.counters["mismatches"] = static_cast<double>(mismatches);
  state.counters["non_optimal"] = static_cast<double>(non_optimal);
  for (int p = 0; p <= L; ++p) {
    const std::string name = p == L ? std::string("total") : "level" + std::to_string(p + 1);
    state.counters[name + "_p50_us"] = quantile(pooled[p], 0.5);
    state.counters[name + "_p999_us"] = quantile(pooled[p], 0.999);
    state.counters[name + "_inst_p999_us"] = instanceQuantile(per_instance[p], 0.999);
  }
  // The same instances as timed inside the simulation (one solve each, recorded).
  std::vector<double> run_sum;
  for (const Instance& in : v) {
    double s = 0.0;
    for (const auto& l : in.result.levels) s += l.time_us;
    run_sum.push_back(s);
  }
  state.counters["run_levels_sum_p50_us"] = quantile(run_sum, 0.5);
}

// The part of BM_HqpReplay's time column that is not the solve: loading an instance
// (as BM_FillOnly is for BM_HqpWarm).
void BM_HqpReplayLoadOnly(benchmark::State& state) {
  const Recording& rec = recording();
  if (!rec.error.empty()) {
    state.SkipWithError(rec.error.c_str());
    for (auto _ : state) {
    }
    return;
  }
  const auto& v = rec.instances;
  static std::unique_ptr<Replay> wbc;
  if (!wbc) wbc = std::make_unique<Replay>(rec.info.shippedSettings());
  std::size_t k = 0;
  for (auto _ : state) {
    hqp::loadInstance(v[k], *wbc, true);
    benchmark::ClobberMemory();
    k = (k + 1) % v.size();
  }
}

}  // namespace

BENCHMARK(BM_HqpReplay)->ArgName("warm")->Arg(1)->Arg(0)->MinTime(1.0);
BENCHMARK(BM_HqpReplayLoadOnly);
