// Single least-squares QP of the size of one HQP level: n = 30 variables,
// 15 objective rows, 6 equalities, 48 one-sided inequality rows (about 8 active
// at the optimum). ActiveSetQp (fixed max sizes, incremental QR) against a
// straightforward dynamic-size Eigen implementation of the same primal active-set
// method (refactorizes every iteration) in the same binary.
// Run: bench_qp --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <limits>
#include <random>
#include <vector>

#include "hqp/active_set_qp.hpp"

namespace {

constexpr int kN = 30, kM = 15, kE = 6, kI = 48;
using Qp = hqp::ActiveSetQp<kN, kM, kE, kI>;

struct Problem {
  Eigen::MatrixXd A, E, C;
  Eigen::VectorXd b, e, lower, upper, x_feasible;
};

// Well-scaled random task; x_f strictly feasible; the first 12 rows cut between
// x_f and the equality-constrained optimum at different fractions of the way, so
// that several (not all) are active; the other 36 rows are inactive.
Problem makeProblem(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  auto randm = [&](int r, int c) {
    return Eigen::MatrixXd(Eigen::MatrixXd::NullaryExpr(r, c, [&] { return N(rng); }));
  };
  Problem p;
  p.A = randm(kM, kN);
  p.b = randm(kM, 1);
  p.E = randm(kE, kN);
  p.x_feasible = 0.1 * randm(kN, 1);
  p.e = p.E * p.x_feasible;
  p.C = randm(kI, kN);
  // Equality-constrained optimum (min-norm), via the KKT system with a pseudo-inverse.
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(kN + kE, kN + kE);
  K.topLeftCorner(kN, kN) = p.A.transpose() * p.A;
  K.topRightCorner(kN, kE) = p.E.transpose();
  K.bottomLeftCorner(kE, kN) = p.E;
  Eigen::VectorXd rhs(kN + kE);
  rhs << p.A.transpose() * p.b, p.e;
  const Eigen::VectorXd xu = K.completeOrthogonalDecomposition().solve(rhs).head(kN);
  const double inf = std::numeric_limits<double>::infinity();
  p.lower = Eigen::VectorXd::Constant(kI, -inf);
  p.upper.resize(kI);
  for (int j = 0; j < kI; ++j) {
    double cf = p.C.row(j).dot(p.x_feasible), cu = p.C.row(j).dot(xu);
    if (cu < cf) {  // orient the row so that the optimum pushes against it
      p.C.row(j) *= -1.0;
      cf = -cf;
      cu = -cu;
    }
    const double frac = 0.3 + 0.6 * std::abs(std::sin(1.7 * j));  // spread, no common vertex
    p.upper(j) = j < 12 ? cf + frac * (cu - cf) : cu + 0.5 + std::abs(N(rng));
  }
  return p;
}

void load(Qp& qp, const Problem& p) {
  qp.resize(kN, kM, kE, kI);
  qp.A() = p.A;
  qp.b() = p.b;
  qp.E() = p.E;
  qp.e() = p.e;
  qp.C() = p.C;
  qp.lower() = p.lower;
  qp.upper() = p.upper;
}

// ---- Peer: the same primal active-set method, dynamic sizes, refactorizing. ----
struct PeerQp {
  Eigen::MatrixXd A, E, C;
  Eigen::VectorXd b, e, lower, upper, x;
  int iterations = 0;
  bool solve(const Eigen::VectorXd& x0, int max_iter = 100) {
    const int n = static_cast<int>(A.cols()), mi = static_cast<int>(C.rows());
    std::vector<int> ws;
    std::vector<bool> up;
    x = x0;
    iterations = 0;
    for (;;) {
      const int k = static_cast<int>(E.rows() + ws.size());
      Eigen::MatrixXd K(k, n);
      Eigen::VectorXd r(k);
      K.topRows(E.rows()) = E;
      r.head(E.rows()) = e;
      for (size_t i = 0; i < ws.size(); ++i) {
        K.row(E.rows() + i) = C.row(ws[i]);
        r(E.rows() + i) = up[i] ? upper(ws[i]) : lower(ws[i]);
      }
      Eigen::HouseholderQR<Eigen::MatrixXd> qr(K.transpose());
      const Eigen::MatrixXd Q = qr.householderQ();
      const Eigen::MatrixXd R = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
      const Eigen::VectorXd y =
          R.transpose().triangularView<Eigen::Lower>().solve(r);
      const Eigen::VectorXd xp = Q.leftCols(k) * y;
      const Eigen::MatrixXd Z = Q.rightCols(n - k);
      const Eigen::VectorXd p = (A * Z).completeOrthogonalDecomposition().solve(b - A * xp);
      const Eigen::VectorXd xs = xp + Z * p;
      const Eigen::VectorXd d = xs - x;
      double alpha = 1.0;
      int block = -1;
      bool bup = false;
      if (d.cwiseAbs().maxCoeff() > 1e-14 * (1.0 + x.cwiseAbs().maxCoeff())) {
        const Eigen::VectorXd cd = C * d, cx = C * x;
        for (int j = 0; j < mi; ++j) {
          if (std::find(ws.begin(), ws.end(), j) != ws.end()) continue;
          const double nrm = C.row(j).norm();
          if (cd(j) > 1e-11 * nrm && upper(j) < 1e300) {
            const double a = std::max(0.0, upper(j) - cx(j)) / cd(j);
            if (a < alpha) alpha = a, block = j, bup = true;
          }
          if (cd(j) < -1e-11 * nrm && lower(j) > -1e300) {
            const double a = std::max(0.0, cx(j) - lower(j)) / -cd(j);
            if (a < alpha) alpha = a, block = j, bup = false;
          }
        }
      }
      x += alpha * d;
      if (block >= 0) {
        if (++iterations > max_iter) return false;
        ws.push_back(block);
        up.push_back(bup);
        continue;
      }
      x = xs;
      const Eigen::VectorXd g = A.transpose() * (A * x - b);
      const Eigen::VectorXd lam =
          R.triangularView<Eigen::Upper>().solve(-(Q.leftCols(k).transpose() * g));
      int drop = -1;
      double worst = -1e-10 * std::max(1.0, lam.cwiseAbs().maxCoeff());
      for (size_t i = 0; i < ws.size(); ++i) {
        const double mu = (up[i] ? 1.0 : -1.0) * lam(E.rows() + i);
        if (mu < worst) worst = mu, drop = static_cast<int>(i);
      }
      if (drop < 0) return true;
      if (++iterations > max_iter) return false;
      ws.erase(ws.begin() + drop);
      up.erase(up.begin() + drop);
    }
  }
};

void BM_ActiveSetQp_ColdFromFeasibleHint(benchmark::State& state) {
  const Problem p = makeProblem(1);
  static Qp qp;
  load(qp, p);
  const Qp::VectorX hint = p.x_feasible;
  for (auto _ : state) {
    qp.solve(hint, false);
    benchmark::DoNotOptimize(qp.x().data());
  }
  state.counters["iterations"] = qp.iterations();
  state.counters["active"] = qp.numActive();
  if (qp.status() != hqp::QpStatus::Optimal) state.SkipWithError("not optimal");
}
BENCHMARK(BM_ActiveSetQp_ColdFromFeasibleHint);

void BM_ActiveSetQp_ColdWithPhase1(benchmark::State& state) {
  const Problem p = makeProblem(1);
  static Qp qp;
  load(qp, p);
  for (auto _ : state) {
    qp.solve(false);
    benchmark::DoNotOptimize(qp.x().data());
  }
  state.counters["iterations"] = qp.iterations();
  state.counters["active"] = qp.numActive();
  if (qp.status() != hqp::QpStatus::Optimal) state.SkipWithError("not optimal");
}
BENCHMARK(BM_ActiveSetQp_ColdWithPhase1);

// Warm: consecutive "ticks" with slightly perturbed b (16 precomputed variants).
void BM_ActiveSetQp_Warm(benchmark::State& state) {
  const Problem p = makeProblem(1);
  static Qp qp;
  load(qp, p);
  std::mt19937 rng(2);
  std::normal_distribution<double> N(0.0, 1e-3);
  std::vector<Qp::VectorRows> bs(16, p.b);
  for (auto& b : bs)
    for (int i = 0; i < kM; ++i) b(i) += N(rng);
  const Qp::VectorX hint = p.x_feasible;
  qp.solve(hint, false);
  size_t k = 0;
  int iters = 0;
  for (auto _ : state) {
    qp.b() = bs[k++ & 15];
    qp.solve(hint, true);
    iters += qp.iterations();
    benchmark::DoNotOptimize(qp.x().data());
  }
  state.counters["iterations"] = static_cast<double>(iters) / state.iterations();
  state.counters["active"] = qp.numActive();
  if (qp.status() != hqp::QpStatus::Optimal) state.SkipWithError("not optimal");
}
BENCHMARK(BM_ActiveSetQp_Warm);

void BM_PeerDynamicEigen_ColdFromFeasibleHint(benchmark::State& state) {
  const Problem p = makeProblem(1);
  PeerQp peer{p.A, p.E, p.C, p.b, p.e, p.lower, p.upper, {}, 0};
  bool ok = true;
  for (auto _ : state) {
    ok = peer.solve(p.x_feasible);
    benchmark::DoNotOptimize(peer.x.data());
  }
  // Same answer as ActiveSetQp (checked once, outside the timing).
  static Qp qp;
  load(qp, p);
  qp.solve(Qp::VectorX(p.x_feasible), false);
  if (!ok || (qp.x() - peer.x).cwiseAbs().maxCoeff() > 1e-9) state.SkipWithError("peer differs");
  state.counters["iterations"] = peer.iterations;
}
BENCHMARK(BM_PeerDynamicEigen_ColdFromFeasibleHint);

}  // namespace

BENCHMARK_MAIN();
