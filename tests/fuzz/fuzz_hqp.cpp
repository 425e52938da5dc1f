// libFuzzer harness: HqpWbc in the paper's shape (Nx = 30, four levels: dynamics + torque
// limits, contact + friction/CoP, CoM, posture + forces; tests/hqp/test_hqp_paper.cpp) on
// scenes drawn from the input (docs/fuzzing.md). The first bytes seed the synthetic scene, the
// rest overwrite single entries of any task or constraint (±inf and NaN included).
// Checks, independent of HqpWbc's null-space cascade:
//  - input outside the contract (non-finite data, NaN bounds, lower > upper by more than the
//    feasibility tolerance, lower = +inf, upper = −inf) is never Optimal;
//  - Optimal: x satisfies every constraint that was not dropped, and each level p, solved
//    alone in the full 30 variables by a fresh ActiveSetQp with the higher levels' task values
//    A_k x = A_k x* (k < p) as equalities and the constraints of levels ≤ p, reaches the same
//    residual (HqpWbc's residual is not larger than that optimum). Levels whose constraints
//    HqpWbc reports dropped are solved without them; where the reference gives no answer,
//    the comparison stops.
#include <chrono>
#include <memory>
#include <random>
#include <vector>

#include "fuzz_common.hpp"
#include "hqp/active_set_qp.hpp"
#include "hqp/hqp_wbc.hpp"

namespace {

constexpr int N = 30;
using Dyn = hqp::Level<N, hqp::TaskList<hqp::Task<6, N>>, hqp::ConstraintList<hqp::Constraint<12, N>>>;
using Foot = hqp::Level<N, hqp::TaskList<hqp::Task<12, N>>, hqp::ConstraintList<hqp::Constraint<18, N>>>;
using Com = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>>;
using Low = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>, hqp::Task<12, N>>>;
using Wbc = hqp::HqpWbc<N, Dyn, Foot, Com, Low>;
using RefQp = hqp::ActiveSetQp<N, 15, 21, 30>;

template <int R, int C>
Eigen::Matrix<double, R, C> randn(std::mt19937& g, double s) {
  std::normal_distribution<double> nd(0.0, s);
  Eigen::Matrix<double, R, C> M;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) M(i, j) = nd(g);
  return M;
}

// Dynamics-like data as in tests/hqp/test_hqp_paper.cpp.
void fillScene(Wbc& wbc, std::mt19937& g, double tau_max, double mu) {
  Eigen::Matrix<double, 18, 18> B = randn<18, 18>(g, 0.6);
  Eigen::Matrix<double, 18, 18> M = B * B.transpose();
  M.diagonal().head(3).array() += 40.0;
  M.diagonal().segment(3, 3).array() += 4.0;
  M.diagonal().tail(12).array() += 0.5;
  Eigen::Matrix<double, 18, 1> h = randn<18, 1>(g, 5.0);
  h(2) += 40.0 * 9.81;
  Eigen::Matrix<double, 12, 18> J = randn<12, 18>(g, 0.5);
  J.block<3, 3>(0, 0).setIdentity();
  J.block<3, 3>(6, 0).setIdentity();
  auto& dyn = wbc.level<0>().task<0>();
  dyn.A << M.topRows(6), -J.leftCols(6).transpose();
  dyn.b = -h.head(6);
  auto& tau = wbc.level<0>().constraint<0>();
  tau.D << M.bottomRows(12), -J.rightCols(12).transpose();
  tau.lower = Eigen::Matrix<double, 12, 1>::Constant(-tau_max) - h.tail(12);
  tau.upper = Eigen::Matrix<double, 12, 1>::Constant(tau_max) - h.tail(12);
  auto& feet = wbc.level<1>().task<0>();
  feet.A.setZero();
  feet.A.leftCols(18) = J;
  feet.b = randn<12, 1>(g, 0.5);
  auto& contact = wbc.level<1>().constraint<0>();
  contact.D.setZero();
  const double lx = 0.1, ly = 0.05;
  for (int f = 0; f < 2; ++f) {
    const int c = 18 + 6 * f, r = 9 * f;
    contact.D(r + 0, c + 2) = -1.0;
    contact.D(r + 1, c + 0) = 1.0, contact.D(r + 1, c + 2) = -mu;
    contact.D(r + 2, c + 0) = -1.0, contact.D(r + 2, c + 2) = -mu;
    contact.D(r + 3, c + 1) = 1.0, contact.D(r + 3, c + 2) = -mu;
    contact.D(r + 4, c + 1) = -1.0, contact.D(r + 4, c + 2) = -mu;
    contact.D(r + 5, c + 3) = 1.0, contact.D(r + 5, c + 2) = -ly;
    contact.D(r + 6, c + 3) = -1.0, contact.D(r + 6, c + 2) = -ly;
    contact.D(r + 7, c + 4) = 1.0, contact.D(r + 7, c + 2) = -lx;
    contact.D(r + 8, c + 4) = -1.0, contact.D(r + 8, c + 2) = -lx;
  }
  contact.setUpperBound(Eigen::Matrix<double, 18, 1>::Zero());
  auto& com = wbc.level<2>().task<0>();
  com.A.setZero();
  com.A.leftCols(18) = randn<3, 18>(g, 0.3);
  com.A.leftCols(3).setIdentity();
  com.b = randn<3, 1>(g, 1.0);
  auto& torso = wbc.level<3>().task<0>();
  torso.A.setZero();
  torso.A.leftCols(18) = randn<3, 18>(g, 0.3);
  torso.b = randn<3, 1>(g, 1.0);
  auto& force = wbc.level<3>().task<1>();
  force.A.setZero();
  force.A.rightCols(12).setIdentity();
  force.b.setZero();
  force.b(2) = force.b(8) = 0.5 * 40.0 * 9.81;
  force.b.segment<2>(0) = randn<2, 1>(g, 150.0);
}

// A level as dynamic matrices: stacked tasks and the level's own constraints.
struct DynLevel {
  Eigen::MatrixXd A, D;
  Eigen::VectorXd b, lower, upper;
};

template <class T>
void appendTask(DynLevel& L, const T& t) {
  const Eigen::Index r = L.A.rows();
  L.A.conservativeResize(r + t.A.rows(), N);
  L.b.conservativeResize(r + t.A.rows());
  L.A.bottomRows(t.A.rows()) = t.A;
  L.b.tail(t.A.rows()) = t.b;
}
template <class C>
void appendConstraint(DynLevel& L, const C& c) {
  const Eigen::Index r = L.D.rows();
  L.D.conservativeResize(r + c.D.rows(), N);
  L.lower.conservativeResize(r + c.D.rows());
  L.upper.conservativeResize(r + c.D.rows());
  L.D.bottomRows(c.D.rows()) = c.D;
  L.lower.tail(c.D.rows()) = c.lower;
  L.upper.tail(c.D.rows()) = c.upper;
}

std::vector<DynLevel> levels(Wbc& w) {
  std::vector<DynLevel> L(4);
  for (auto& l : L) l.A.resize(0, N), l.D.resize(0, N);
  appendTask(L[0], w.level<0>().task<0>());
  appendConstraint(L[0], w.level<0>().constraint<0>());
  appendTask(L[1], w.level<1>().task<0>());
  appendConstraint(L[1], w.level<1>().constraint<0>());
  appendTask(L[2], w.level<2>().task<0>());
  appendTask(L[3], w.level<3>().task<0>());
  appendTask(L[3], w.level<3>().task<1>());
  return L;
}

// One entry of the data, chosen by the input, overwritten.
void overwrite(Wbc& w, FuzzedDataProvider& in) {
  const int which = in.ConsumeIntegralInRange<int>(0, 7);
  const int i = in.ConsumeIntegralInRange<int>(0, 29), j = in.ConsumeIntegralInRange<int>(0, N - 1);
  const bool special = in.ConsumeIntegralInRange<int>(0, 3) == 0;
  const double v = hqp::fuzz::number(in, special);
  auto task = [&](auto& t) {
    if (in.ConsumeBool()) t.A(i % t.A.rows(), j) = v * (special ? 1.0 : 10.0);
    else t.b(i % t.b.size()) = v * 10.0;
  };
  auto cons = [&](auto& c) {
    switch (in.ConsumeIntegralInRange<int>(0, 2)) {
      case 0: c.D(i % c.D.rows(), j) = v; break;
      case 1: c.lower(i % c.lower.size()) = v * 50.0; break;
      default: c.upper(i % c.upper.size()) = v * 50.0; break;
    }
  };
  switch (which) {
    case 0: task(w.level<0>().task<0>()); break;
    case 1: cons(w.level<0>().constraint<0>()); break;
    case 2: task(w.level<1>().task<0>()); break;
    case 3: cons(w.level<1>().constraint<0>()); break;
    case 4: task(w.level<2>().task<0>()); break;
    case 5: task(w.level<3>().task<0>()); break;
    default: task(w.level<3>().task<1>()); break;
  }
}

double rowTol(const Eigen::VectorXd& c, const Eigen::VectorXd& x, double bound) {
  return 1e-8 * std::max(c.norm(), 1.0) + 1e-7 * (c.cwiseAbs().dot(x.cwiseAbs()) + (std::isfinite(bound) ? std::abs(bound) : 0.0));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using hqp::QpStatus;
  FuzzedDataProvider in(data, size);
  static Wbc wbc;
  std::mt19937 g(in.ConsumeIntegral<uint32_t>());
  const double tau_max = 20.0 + in.ConsumeIntegralInRange<int>(0, 280);
  const double mu = in.ConsumeIntegralInRange<int>(1, 12) / 10.0;
  fillScene(wbc, g, tau_max, mu);
  const int edits = in.ConsumeIntegralInRange<int>(0, 8);
  for (int k = 0; k < edits; ++k) overwrite(wbc, in);
  if (in.ConsumeBool()) wbc.resetWarmStart();

  const std::vector<DynLevel> L = levels(wbc);
  bool finite = true, inverted = false, impossible = false;
  double crossing = 0.0;  // largest lower − upper on a unit row (printed with HQP_FUZZ_VERBOSE)
  for (const DynLevel& l : L) {
    finite = finite && l.A.allFinite() && l.b.allFinite() && l.D.allFinite() && !l.lower.hasNaN() && !l.upper.hasNaN();
    for (int r = 0; r < l.D.rows(); ++r) {
      // The documented rule (docs/hqp.md, "Contracts"): a row is empty when its bounds cross
      // by more than feasibility_tol on the unit-norm row; a smaller crossing is a row
      // held at (lower + upper) / 2 within the tolerance, as every solver treats it.
      const double nrm = l.D.row(r).norm();
      const double cross = (l.lower(r) - l.upper(r)) / (nrm > 1e-300 ? nrm : 1.0);
      crossing = std::max(crossing, cross);
      inverted = inverted || cross > hqp::QpSettings{}.feasibility_tol;
      impossible = impossible || l.lower(r) == hqp::fuzz::kInf || l.upper(r) == -hqp::fuzz::kInf;
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  const QpStatus s = wbc.solve();
  const double solve_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  const auto& res = wbc.result();
  if (std::getenv("HQP_FUZZ_STATS")) {  // iterations per level and solve time over a corpus (docs/realtime.md)
    std::fprintf(stderr, "stats:");
    for (const auto& l : res.levels) std::fprintf(stderr, " %d", l.iterations);
    std::fprintf(stderr, " %s %.2f\n", hqp::toString(s), solve_us);
  }
  if (std::getenv("HQP_FUZZ_VERBOSE")) {
    std::fprintf(stderr, "finite %d inverted %d (largest crossing %.3g on a unit row) impossible %d status %s\n", finite,
                 inverted, crossing, impossible, hqp::toString(s));
    for (int p = 0; p < 4; ++p)
      std::fprintf(stderr, "level %d: %s residual %.17g dropped %d dual %d\n", p, hqp::toString(res.levels[p].status),
                   res.levels[p].residual, res.levels[p].constraints_dropped, res.levels[p].dual);
  }
  if (!finite || inverted || impossible) {
    // Invalid input: some level must say so. A level whose own rows are empty or inverted may
    // drop them (HqpWbc's documented policy for infeasible constraints), so inverted bounds
    // are acceptable when the level reports its constraints dropped.
    bool dropped = false;
    for (const auto& l : res.levels) dropped = dropped || l.constraints_dropped;
    HQP_FUZZ_CHECK(s != QpStatus::Optimal || (finite && !impossible && dropped));
    if (!finite || impossible) return 0;
  }
  if (s != QpStatus::Optimal) return 0;
  const Eigen::VectorXd x = res.x;
  HQP_FUZZ_CHECK(x.allFinite());

  // Each level alone in the full space.
  auto ref = std::make_unique<RefQp>();
  Eigen::MatrixXd E(0, N), C(0, N);
  Eigen::VectorXd e(0), lo(0), up(0);
  for (int p = 0; p < 4; ++p) {
    const DynLevel& l = L[static_cast<size_t>(p)];
    const bool dropped = res.levels[static_cast<size_t>(p)].constraints_dropped;
    if (!dropped && l.D.rows() > 0) {
      const Eigen::Index r = C.rows();
      C.conservativeResize(r + l.D.rows(), N);
      lo.conservativeResize(r + l.D.rows());
      up.conservativeResize(r + l.D.rows());
      C.bottomRows(l.D.rows()) = l.D;
      lo.tail(l.D.rows()) = l.lower;
      up.tail(l.D.rows()) = l.upper;
    }
    // x satisfies every constraint kept so far.
    for (int r = 0; r < C.rows(); ++r) {
      const Eigen::VectorXd c = C.row(r).transpose();
      const double cx = c.dot(x);
      HQP_FUZZ_CHECK2(lo(r) - cx <= rowTol(c, x, lo(r)) && cx - up(r) <= rowTol(c, x, up(r)), cx, static_cast<double>(p));
    }
    ref->resize(N, static_cast<int>(l.A.rows()), static_cast<int>(E.rows()), static_cast<int>(C.rows()));
    ref->A() = l.A;
    ref->b() = l.b;
    if (E.rows() > 0) ref->E() = E, ref->e() = e;
    if (C.rows() > 0) ref->C() = C, ref->lower() = lo, ref->upper() = up;
    ref->resetWorkingSet();
    const QpStatus sr = ref->solve(false);
    if (sr == QpStatus::Optimal) {
      const double mine = res.levels[static_cast<size_t>(p)].residual, best = 2.0 * ref->objective();
      if (std::getenv("HQP_FUZZ_VERBOSE")) std::fprintf(stderr, "level %d: reference residual %.17g\n", p, best);
      HQP_FUZZ_CHECK2(mine <= best + 1e-6 * (1.0 + best + l.b.squaredNorm()), mine, best);
    } else if (sr == QpStatus::Infeasible && !dropped) {
      // The reference calls the level's constraints infeasible although x meets them (checked
      // above): nothing to compare.
    } else if (sr != QpStatus::Optimal) {
      break;  // the reference gave no answer; lower levels are not compared either
    }
    // Lock this level's task values for the lower levels.
    const Eigen::Index r = E.rows();
    E.conservativeResize(r + l.A.rows(), N);
    e.conservativeResize(r + l.A.rows());
    E.bottomRows(l.A.rows()) = l.A;
    e.tail(l.A.rows()) = l.A * x;
  }
  return 0;
}
