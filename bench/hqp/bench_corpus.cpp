// The instance corpus (docs/benchmarks.md, "Instance corpus"): HqpWbc and the peer cascade
// (peer_cascade.hpp, BM_PeerWarm's solver) on every instance of a family, alternately, warm
// (each instance's recorded incoming working sets, given to both) or cold. Generate the
// corpus first: bash scripts/corpus.sh make (into build/corpus; HQP_CORPUS_DIR=path for
// another folder). Linked into bench_hqp, so BM_HqpWarm and BM_PeerWarm run in the same process:
//   taskset -c 1 bench_hqp --benchmark_filter='Corpus|PeerWarm|HqpWarm/levels_1-4' \
//       --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// One iteration = one pass over the family (each instance: load, HqpWbc solve(), peer solve).
// Counters (µs, steady_clock around each solve): hqp_p50_us / hqp_p99_us, the median and 99th
// percentile over the instances of each instance's median over the passes (an instance
// property, free of preemption); hqp_pooled_p99_us over every solve (includes preemption);
// peer_* the same for the peer; ratio_p50 / ratio_p99 = peer / hqp; instances (not solves):
// mismatches, HqpWbc's x* off the instance's stored one (the generator's cold solve, or the
// run's) by more than 1e-6 relative where the level objectives differ too; non_optimal, a
// level's status not as stored; peer_failures, a peer level not Optimal.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hqp/problem_file.hpp"
#include "hqp/problem_instance.hpp"
#include "peer_cascade.hpp"
#include "tasks/balance_hierarchy.hpp"
#include "walker3_model.hpp"

#ifndef HQP_CORPUS_DIR
#define HQP_CORPUS_DIR ""
#endif

namespace {

using Wbc = hqp::tasks::StackedHqpOf<hqp::tasks::BalanceHierarchy, hqp::tasks::ContactLayout<walker3::Robot, 2, 6>>;
using Instance = hqp::ProblemInstance<Wbc>;
constexpr int NX = Wbc::nx, L = Wbc::num_levels;
using Peer = hqp::bench::PeerCascade<NX, L, Wbc::max_task_rows, Wbc::total_constraint_rows>;

struct Family {
  hqp::ProblemFileInfo info;
  std::vector<Instance> instances;
  std::string error;
};

const Family& family(const std::string& name) {
  static std::map<std::string, Family> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Family f;
  const char* env = std::getenv("HQP_CORPUS_DIR");
  const std::string dir = env != nullptr && *env != '\0' ? env : HQP_CORPUS_DIR;
  const std::string path = dir + "/" + name + ".hqprec";
  try {
    f.instances = hqp::readProblemFile<Wbc>(path, &f.info);
    if (f.instances.empty()) f.error = path + ": no instances";
  } catch (const std::exception& e) {
    f.error = std::string(e.what()) + " (generate the corpus: bash scripts/corpus.sh make)";
  }
  return cache.emplace(name, std::move(f)).first->second;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

// Over the instances, of each instance's median over the passes.
double instanceQuantile(const std::vector<std::vector<double>>& per, double q) {
  std::vector<double> med;
  for (const auto& t : per)
    if (!t.empty()) med.push_back(quantile(t, 0.5));
  return quantile(med, q);
}

double objectivesDiff(const Instance& in, const Wbc::VectorX& x) {
  double worst = 0.0;
  for (int p = 0; p < L; ++p) {
    double f = 0.0, g = 0.0;
    for (int i = Wbc::task_offset[p]; i < Wbc::task_offset[p + 1]; ++i) {
      const double e = in.A.row(i).dot(x) - in.b(i), e0 = in.A.row(i).dot(in.result.x) - in.b(i);
      f += in.w(i) * e * e;
      g += in.w(i) * e0 * e0;
    }
    worst = std::max(worst, std::abs(f - g) / (1.0 + std::max(f, g)));
  }
  return worst;
}

void BM_Corpus(benchmark::State& state, const char* name, bool warm) {
  const Family& fam = family(name);
  if (!fam.error.empty()) {
    state.SkipWithError(fam.error.c_str());
    for (auto _ : state) {
    }
    return;
  }
  const auto& v = fam.instances;
  const std::size_t n = v.size();
  auto wbc = std::make_unique<Wbc>(fam.info.shippedSettings());  // hundreds of KiB (docs/hqp.md): not on the stack
  auto peer = std::make_unique<Peer>();
  std::vector<std::vector<double>> th(n), tp(n);
  std::vector<double> pooled_h, pooled_p;
  // Per instance (counted once however many passes): a solve that mismatched / failed.
  std::vector<char> mismatch(n, 0), non_optimal(n, 0), peer_failed(n, 0);
  std::array<Peer::WorkingSet, L> ws{};
  for (auto _ : state) {
    for (std::size_t k = 0; k < n; ++k) {
      const Instance& in = v[k];
      hqp::loadInstance(in, *wbc, warm);
      const auto t0 = std::chrono::steady_clock::now();
      wbc->solve();
      const auto t1 = std::chrono::steady_clock::now();
      const auto& r = wbc->result();
      bool as_stored = true;
      for (int p = 0; p < L; ++p) as_stored = as_stored && r.levels[p].status == in.result.levels[p].status;
      non_optimal[k] |= !as_stored;
      const double dx = (r.x - in.result.x).lpNorm<Eigen::Infinity>() / std::max(1.0, in.result.x.lpNorm<Eigen::Infinity>());
      if (dx > 1e-6 && objectivesDiff(in, r.x) > 1e-6) mismatch[k] = 1;
      // The peer from the same working sets (its rows index the same stacked constraint rows).
      for (int p = 0; p < L; ++p) {
        const auto& w = in.warm[static_cast<std::size_t>(p)];
        ws[p] = {w.num_active, w.row.data(), w.upper.data()};
      }
      const auto t2 = std::chrono::steady_clock::now();
      peer_failed[k] |= peer->solve(in.A, in.b, in.w, in.D, in.lower, in.upper, Wbc::task_offset,
                                   Wbc::constraint_offset, warm, ws.data()) > 0;
      const auto t3 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(peer->x().data());
      const double uh = std::chrono::duration<double, std::micro>(t1 - t0).count();
      const double up = std::chrono::duration<double, std::micro>(t3 - t2).count();
      th[k].push_back(uh);
      tp[k].push_back(up);
      pooled_h.push_back(uh);
      pooled_p.push_back(up);
    }
  }
  const double h50 = instanceQuantile(th, 0.5), h99 = instanceQuantile(th, 0.99);
  const double p50 = instanceQuantile(tp, 0.5), p99 = instanceQuantile(tp, 0.99);
  state.counters["instances"] = static_cast<double>(n);
  state.counters["hqp_p50_us"] = h50;
  state.counters["hqp_p99_us"] = h99;
  state.counters["hqp_pooled_p99_us"] = quantile(pooled_h, 0.99);
  state.counters["peer_p50_us"] = p50;
  state.counters["peer_p99_us"] = p99;
  state.counters["ratio_p50"] = h50 > 0.0 ? p50 / h50 : 0.0;
  state.counters["ratio_p99"] = h99 > 0.0 ? p99 / h99 : 0.0;
  const auto count = [](const std::vector<char>& f) { return static_cast<double>(std::count(f.begin(), f.end(), 1)); };
  state.counters["mismatches"] = count(mismatch);
  state.counters["non_optimal"] = count(non_optimal);
  state.counters["peer_failures"] = count(peer_failed);
}

}  // namespace

BENCHMARK_CAPTURE(BM_Corpus, walker3_scenarios/warm, "walker3_scenarios", true)->MinTime(1.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Corpus, walker3_scenarios/cold, "walker3_scenarios", false)->MinTime(1.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Corpus, stress/warm, "stress", true)->MinTime(1.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Corpus, stress/cold, "stress", false)->MinTime(1.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Corpus, degenerate/warm, "degenerate", true)->MinTime(1.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Corpus, degenerate/cold, "degenerate", false)->MinTime(1.0)->Unit(benchmark::kMillisecond);
