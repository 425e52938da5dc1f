// HqpWbc on the paper's shape (Table I): Nx = 30, levels (6 eq + 12 two-sided torque rows),
// (12 eq + 18 contact rows), (3 eq), (15 eq), synthetic dynamics-like data with a few
// active constraints. Reports cold and warm solves, per level (prefix hierarchies: the time
// of level p = time(levels ≤ p) − time(levels < p)), WqpWbc, and a peer in the same binary:
// the paper's literal projector cascade N_p = N_{p−1}(I − Â_p⁺ Â_p) on dynamic-size Eigen
// (MatrixXd, Eigen's COD with allocation), every level's QP in all 30 variables
// (peer_cascade.hpp, shared with the corpus benchmark and check).
// Run: bench_hqp --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <Eigen/Dense>

#include <array>
#include <random>
#include <vector>

#include "hqp/hqp_wbc.hpp"
#include "hqp/wqp_wbc.hpp"
#include "peer_cascade.hpp"

namespace {

constexpr int N = 30;
using Dyn = hqp::Level<N, hqp::TaskList<hqp::Task<6, N>>, hqp::ConstraintList<hqp::Constraint<12, N>>>;
using Foot = hqp::Level<N, hqp::TaskList<hqp::Task<12, N>>, hqp::ConstraintList<hqp::Constraint<18, N>>>;
using Com = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>>;
using Low = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>, hqp::Task<12, N>>>;
using Wbc1 = hqp::HqpWbc<N, Dyn>;
using Wbc2 = hqp::HqpWbc<N, Dyn, Foot>;
using Wbc3 = hqp::HqpWbc<N, Dyn, Foot, Com>;
using Wbc4 = hqp::HqpWbc<N, Dyn, Foot, Com, Low>;
using Wqp = hqp::WqpWbc<N, Dyn, Foot, Com, Low>;

// One tick's data, already in the task/constraint form.
struct Tick {
  Eigen::Matrix<double, 6, N> A1;
  Eigen::Matrix<double, 6, 1> b1;
  Eigen::Matrix<double, 12, N> D1;
  Eigen::Matrix<double, 12, 1> lo1, up1;
  Eigen::Matrix<double, 12, N> A2;
  Eigen::Matrix<double, 12, 1> b2;
  Eigen::Matrix<double, 18, N> D2;
  Eigen::Matrix<double, 18, 1> up2;
  Eigen::Matrix<double, 3, N> A3;
  Eigen::Matrix<double, 3, 1> b3;
  Eigen::Matrix<double, 3, N> A4a;
  Eigen::Matrix<double, 3, 1> b4a;
  Eigen::Matrix<double, 12, N> A4b;
  Eigen::Matrix<double, 12, 1> b4b;
};

template <int R, int C>
Eigen::Matrix<double, R, C> randn(std::mt19937& g, double s) {
  std::normal_distribution<double> nd(0.0, s);
  Eigen::Matrix<double, R, C> M;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) M(i, j) = nd(g);
  return M;
}

// Dynamics-like scene: M SPD (heavy floating base, entries of a 40 kg robot's scale),
// contact Jacobians, friction pyramid (μ = 0.6) + CoP box per foot, torque limits ±150 N m,
// a reference force pushing outside the pyramid. `eps` perturbs a base scene (ticks).
struct Scene {
  Eigen::Matrix<double, 18, 18> M;
  Eigen::Matrix<double, 18, 1> h;
  Eigen::Matrix<double, 12, 18> J;
  Eigen::Matrix<double, 3, 18> Jcom, Jtorso;
  Eigen::Matrix<double, 12, 1> a_feet, F_ref;
  Eigen::Matrix<double, 3, 1> a_com, a_torso;
  double tau_max = 150.0;

  static Scene random(std::mt19937& g) {
    Scene s;
    const Eigen::Matrix<double, 18, 18> B = randn<18, 18>(g, 0.6);
    s.M = B * B.transpose();
    s.M.diagonal().head(3).array() += 40.0;
    s.M.diagonal().segment(3, 3).array() += 4.0;
    s.M.diagonal().tail(12).array() += 0.5;
    s.h = randn<18, 1>(g, 5.0);
    s.h(2) += 40.0 * 9.81;
    s.J = randn<12, 18>(g, 0.5);
    s.J.block<3, 3>(0, 0).setIdentity();
    s.J.block<3, 3>(6, 0).setIdentity();
    s.Jcom = randn<3, 18>(g, 0.3);
    s.Jcom.leftCols(3).setIdentity();
    s.Jtorso = randn<3, 18>(g, 0.3);
    s.a_feet = randn<12, 1>(g, 0.5);
    s.a_com = randn<3, 1>(g, 1.0);
    s.a_torso = randn<3, 1>(g, 1.0);
    s.F_ref.setZero();
    s.F_ref(2) = s.F_ref(8) = 0.5 * 40.0 * 9.81;
    s.F_ref.segment<2>(0) = randn<2, 1>(g, 150.0);
    s.F_ref.segment<3>(3) = randn<3, 1>(g, 20.0);
    return s;
  }
  Scene perturbed(std::mt19937& g, double eps) const {
    Scene s = *this;
    const Eigen::Matrix<double, 18, 18> dB = randn<18, 18>(g, eps);
    s.M += dB * dB.transpose();
    s.h += randn<18, 1>(g, 5.0 * eps);
    s.J += randn<12, 18>(g, eps);
    s.a_feet += randn<12, 1>(g, eps);
    s.a_com += randn<3, 1>(g, eps);
    s.F_ref += randn<12, 1>(g, 10.0 * eps);
    return s;
  }
  Tick tick() const {
    Tick t;
    t.A1 << M.topRows(6), -J.leftCols(6).transpose();
    t.b1 = -h.head(6);
    t.D1 << M.bottomRows(12), -J.rightCols(12).transpose();
    t.lo1 = Eigen::Matrix<double, 12, 1>::Constant(-tau_max) - h.tail(12);
    t.up1 = Eigen::Matrix<double, 12, 1>::Constant(tau_max) - h.tail(12);
    t.A2.setZero();
    t.A2.leftCols(18) = J;
    t.b2 = a_feet;
    t.D2.setZero();
    const double mu = 0.6, lx = 0.1, ly = 0.05;
    for (int f = 0; f < 2; ++f) {
      const int c = 18 + 6 * f, r = 9 * f;
      t.D2(r + 0, c + 2) = -1.0;
      t.D2(r + 1, c + 0) = 1.0, t.D2(r + 1, c + 2) = -mu;
      t.D2(r + 2, c + 0) = -1.0, t.D2(r + 2, c + 2) = -mu;
      t.D2(r + 3, c + 1) = 1.0, t.D2(r + 3, c + 2) = -mu;
      t.D2(r + 4, c + 1) = -1.0, t.D2(r + 4, c + 2) = -mu;
      t.D2(r + 5, c + 3) = 1.0, t.D2(r + 5, c + 2) = -ly;
      t.D2(r + 6, c + 3) = -1.0, t.D2(r + 6, c + 2) = -ly;
      t.D2(r + 7, c + 4) = 1.0, t.D2(r + 7, c + 2) = -lx;
      t.D2(r + 8, c + 4) = -1.0, t.D2(r + 8, c + 2) = -lx;
    }
    t.up2.setZero();
    t.A3.setZero();
    t.A3.leftCols(18) = Jcom;
    t.b3 = a_com;
    t.A4a.setZero();
    t.A4a.leftCols(18) = Jtorso;
    t.b4a = a_torso;
    t.A4b.setZero();
    t.A4b.rightCols(12).setIdentity();
    t.b4b = F_ref;
    return t;
  }
};

// A sequence of ticks: slightly perturbed copies of one scene (a random walk).
const std::vector<Tick>& ticks() {
  static const std::vector<Tick> seq = [] {
    std::mt19937 g(42);
    Scene s = Scene::random(g);
    std::vector<Tick> out;
    for (int k = 0; k < 200; ++k) {
      s = s.perturbed(g, 1e-3);
      out.push_back(s.tick());
    }
    return out;
  }();
  return seq;
}
// Independent scenes for the cold benchmarks.
const std::vector<Tick>& scenes() {
  static const std::vector<Tick> seq = [] {
    std::mt19937 g(7);
    std::vector<Tick> out;
    for (int k = 0; k < 200; ++k) out.push_back(Scene::random(g).tick());
    return out;
  }();
  return seq;
}

template <class W>
void fill(W& w, const Tick& t) {
  constexpr int L = W::num_levels;
  w.template level<0>().template task<0>().A = t.A1;
  w.template level<0>().template task<0>().b = t.b1;
  w.template level<0>().template constraint<0>().D = t.D1;
  w.template level<0>().template constraint<0>().lower = t.lo1;
  w.template level<0>().template constraint<0>().upper = t.up1;
  if constexpr (L > 1) {
    w.template level<1>().template task<0>().A = t.A2;
    w.template level<1>().template task<0>().b = t.b2;
    w.template level<1>().template constraint<0>().D = t.D2;
    w.template level<1>().template constraint<0>().setUpperBound(t.up2);
  }
  if constexpr (L > 2) {
    w.template level<2>().template task<0>().A = t.A3;
    w.template level<2>().template task<0>().b = t.b3;
  }
  if constexpr (L > 3) {
    w.template level<3>().template task<0>().A = t.A4a;
    w.template level<3>().template task<0>().b = t.b4a;
    w.template level<3>().template task<1>().A = t.A4b;
    w.template level<3>().template task<1>().b = t.b4b;
  }
}

template <class W>
void reportCounters(benchmark::State& state, const W& w, long failures, double active) {
  state.counters["failures"] = static_cast<double>(failures);
  state.counters["active_rows"] = active / static_cast<double>(state.iterations());
  (void)w;
}

template <class W>
double activeRows(const W& w) {
  double a = 0.0;
  for (const auto& l : w.result().levels) a += l.num_active;
  return a;
}

// Warm: consecutive ticks, each level's working set from the previous tick.
template <class W>
void warmTicks(benchmark::State& state, W& w) {
  const auto& seq = ticks();
  std::size_t k = 0;
  long failures = 0, tried = 0, deferred = 0;
  double active = 0.0;
  for (auto _ : state) {
    fill(w, seq[k]);
    failures += w.solve() != hqp::QpStatus::Optimal;
    benchmark::DoNotOptimize(w.x().data());
    active += activeRows(w);
    tried += w.result().deferred_tried;
    deferred += w.result().deferred;
    k = (k + 1) % seq.size();
  }
  reportCounters(state, w, failures, active);
  // Share of solves that tried the deferred path, and that it held (docs/hqp.md).
  state.counters["deferred_tried"] = static_cast<double>(tried) / static_cast<double>(state.iterations());
  state.counters["deferred"] = static_cast<double>(deferred) / static_cast<double>(state.iterations());
}

template <class W>
void BM_HqpWarm(benchmark::State& state) {
  static W w;
  warmTicks(state, w);
}

// The same with the certificate's KKT residuals computed every solve (HqpSettings::kkt_residuals).
template <class W>
void BM_HqpWarmKkt(benchmark::State& state) {
  static W w;
  w.setKktResiduals(true);
  warmTicks(state, w);
}

// Cold: unrelated scenes, working sets forgotten before every solve.
template <class W>
void BM_HqpCold(benchmark::State& state) {
  static W w;
  const auto& seq = scenes();
  std::size_t k = 0;
  long failures = 0;
  double active = 0.0;
  for (auto _ : state) {
    fill(w, seq[k]);
    w.resetWarmStart();
    failures += w.solve() != hqp::QpStatus::Optimal;
    benchmark::DoNotOptimize(w.x().data());
    active += activeRows(w);
    k = (k + 1) % seq.size();
  }
  reportCounters(state, w, failures, active);
}

// The copy of one tick's data into the tasks (included in the figures above).
void BM_FillOnly(benchmark::State& state) {
  static Wbc4 w;
  const auto& seq = ticks();
  std::size_t k = 0;
  for (auto _ : state) {
    fill(w, seq[k]);
    benchmark::ClobberMemory();
    k = (k + 1) % seq.size();
  }
}

void BM_WqpWarm(benchmark::State& state) {
  static Wqp w;
  const auto& seq = ticks();
  std::size_t k = 0;
  long failures = 0;
  for (auto _ : state) {
    fill(w, seq[k]);
    failures += w.solve() != hqp::QpStatus::Optimal;
    benchmark::DoNotOptimize(w.x().data());
    k = (k + 1) % seq.size();
  }
  state.counters["failures"] = static_cast<double>(failures);
}

// ---- Peer: the literal projector cascade on dynamic-size Eigen (peer_cascade.hpp) ----------
// Each tick stacked once, outside the timed loop (as an instance of the corpus is).
struct StackedTick {
  Eigen::Matrix<double, 36, N> A;
  Eigen::Matrix<double, 36, 1> b, w;
  Eigen::Matrix<double, 30, N> D;
  Eigen::Matrix<double, 30, 1> lo, up;
};
StackedTick stacked(const Tick& t) {
  StackedTick s;
  s.A << t.A1, t.A2, t.A3, t.A4a, t.A4b;
  s.b << t.b1, t.b2, t.b3, t.b4a, t.b4b;
  s.w.setOnes();
  s.D << t.D1, t.D2;
  s.lo << t.lo1, Eigen::Matrix<double, 18, 1>::Constant(-hqp::kInf);
  s.up << t.up1, t.up2;
  return s;
}
const std::vector<StackedTick>& stackedSeq(const std::vector<Tick>& seq) {
  static std::vector<StackedTick> warm, cold;
  auto& out = &seq == &ticks() ? warm : cold;
  if (out.empty())
    for (const Tick& t : seq) out.push_back(stacked(t));
  return out;
}

class TickPeer {
 public:
  int solve(const StackedTick& t, bool warm) {
    return peer_.solve(t.A, t.b, t.w, t.D, t.lo, t.up, {0, 6, 18, 21, 36}, {0, 12, 30, 30, 30}, warm);
  }
  const Eigen::VectorXd& x() const { return peer_.x(); }

 private:
  hqp::bench::PeerCascade<N, 4, 15, 30> peer_;
};

void BM_PeerWarm(benchmark::State& state) {
  static TickPeer peer;
  const auto& seq = stackedSeq(ticks());
  std::size_t k = 0;
  long failures = 0;
  for (auto _ : state) {
    failures += peer.solve(seq[k], true);
    benchmark::DoNotOptimize(peer.x().data());
    k = (k + 1) % seq.size();
  }
  state.counters["failures"] = static_cast<double>(failures);
}

void BM_PeerCold(benchmark::State& state) {
  static TickPeer peer;
  const auto& seq = stackedSeq(scenes());
  std::size_t k = 0;
  long failures = 0;
  for (auto _ : state) {
    failures += peer.solve(seq[k], false);
    benchmark::DoNotOptimize(peer.x().data());
    k = (k + 1) % seq.size();
  }
  state.counters["failures"] = static_cast<double>(failures);
}

}  // namespace

BENCHMARK(BM_FillOnly);
BENCHMARK_TEMPLATE(BM_HqpWarm, Wbc1)->Name("BM_HqpWarm/levels_1");
BENCHMARK_TEMPLATE(BM_HqpWarm, Wbc2)->Name("BM_HqpWarm/levels_1-2");
BENCHMARK_TEMPLATE(BM_HqpWarm, Wbc3)->Name("BM_HqpWarm/levels_1-3");
BENCHMARK_TEMPLATE(BM_HqpWarm, Wbc4)->Name("BM_HqpWarm/levels_1-4");
BENCHMARK_TEMPLATE(BM_HqpWarmKkt, Wbc4)->Name("BM_HqpWarm/levels_1-4/kkt_residuals");
BENCHMARK_TEMPLATE(BM_HqpCold, Wbc1)->Name("BM_HqpCold/levels_1");
BENCHMARK_TEMPLATE(BM_HqpCold, Wbc2)->Name("BM_HqpCold/levels_1-2");
BENCHMARK_TEMPLATE(BM_HqpCold, Wbc3)->Name("BM_HqpCold/levels_1-3");
BENCHMARK_TEMPLATE(BM_HqpCold, Wbc4)->Name("BM_HqpCold/levels_1-4");
BENCHMARK(BM_WqpWarm);
BENCHMARK(BM_PeerWarm);
BENCHMARK(BM_PeerCold);
BENCHMARK_MAIN();
