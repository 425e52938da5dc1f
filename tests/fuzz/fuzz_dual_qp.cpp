// libFuzzer harness: DualActiveSetQp (Goldfarb–Idnani) cross-checked against ActiveSetQp on
// decoded strictly convex least-squares QPs (docs/fuzzing.md):
//  - input outside the contract (NaN or ±inf data, lower > upper, lower = +inf, upper = −inf)
//    is never Optimal;
//  - Optimal: x feasible, KKT with the reported multipliers, and the objective equal to
//    ActiveSetQp's optimum of the same problem (the optimum of a strictly convex QP is unique);
//  - Infeasible: ActiveSetQp finds no feasible point either (or its answer is checked feasible
//    independently, which makes the dual answer wrong);
//  - factorize() refuses exactly when A is (numerically) rank deficient: when it accepts, σ_min(A)
//    from an SVD is not far below the promised bound.
#include <memory>
#include <vector>

#include "hqp/active_set_qp.hpp"
#include "hqp/dual_active_set_qp.hpp"
#include "qp_problem.hpp"

namespace {

constexpr int kN = 6, kRows = 9, kIneq = 8;
using Dual = hqp::DualActiveSetQp<kN, kRows, kIneq>;
using Primal = hqp::ActiveSetQp<kN, kRows, 1, kIneq>;

// Two rows of C at an angle below ~1e-5 rad (or equal up to a factor).
bool nearlyParallelRows(const Eigen::MatrixXd& C) {
  for (int i = 0; i < C.rows(); ++i)
    for (int j = 0; j < i; ++j) {
      const double ni = C.row(i).norm(), nj = C.row(j).norm();
      if (ni == 0.0 || nj == 0.0) continue;
      if (std::abs(C.row(i).dot(C.row(j))) / (ni * nj) > 1.0 - 1e-10) return true;
    }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using hqp::QpStatus;
  using namespace hqp::fuzz;
  FuzzedDataProvider in(data, size);
  QpProblem p = decodeQp(in, kN, kRows, 0, kIneq, true);
  // Known findings (docs/fuzzing.md): NaN data and bounds, lower > upper, lower = +inf or
  // upper = −inf are not refused by DualActiveSetQp.
  if (skipKnown() && !p.validInput()) return -1;
  const int n = static_cast<int>(p.A.cols()), r = static_cast<int>(p.A.rows()), m = static_cast<int>(p.C.rows());
  const double min_sigma = 1e-9;
  static Dual dual;
  Eigen::Matrix<double, kRows, kN> A = Eigen::Matrix<double, kRows, kN>::Zero();
  Eigen::Matrix<double, kRows, 1> b = Eigen::Matrix<double, kRows, 1>::Zero();
  A.topLeftCorner(r, n) = p.A;
  b.head(r) = p.b;
  Eigen::Matrix<double, kIneq, kN> C = Eigen::Matrix<double, kIneq, kN>::Zero();
  Eigen::Matrix<double, kIneq, 1> lo = Eigen::Matrix<double, kIneq, 1>::Zero(), up = lo;
  C.topLeftCorner(m, n) = p.C;
  lo.head(m) = p.lower;
  up.head(m) = p.upper;

  const bool factorized = dual.factorize(A, b, r, n, min_sigma);
  if (std::getenv("HQP_FUZZ_VERBOSE")) p.print();
  if (!factorized) {
    // Refused: A rank deficient, or data not finite (then it must refuse or later not be Optimal).
    if (p.A.allFinite() && p.b.allFinite()) {
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(p.A);
      const double smin = svd.singularValues()(n - 1), smax = svd.singularValues()(0);
      HQP_FUZZ_CHECK2(smin < 1e3 * min_sigma * std::max(1.0, smax) || smin / smax < 1e-12, smin, smax);
    }
    return 0;
  }
  if (p.A.allFinite() && p.b.allFinite()) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(p.A);
    HQP_FUZZ_CHECK2(svd.singularValues()(n - 1) > 1e-3 * min_sigma, svd.singularValues()(n - 1), 0.0);
  }
  const QpStatus s = dual.solve(C, lo, up, m, hqp::QpSettings{});
  if (std::getenv("HQP_FUZZ_VERBOSE")) std::fprintf(stderr, "dual status %s\n", hqp::toString(s));
  if (!p.validInput()) {
    HQP_FUZZ_CHECK(s != QpStatus::Optimal);
    return 0;
  }

  static Primal primal;
  primal.resize(n, r, 0, m);
  primal.A() = p.A;
  primal.b() = p.b;
  if (m > 0) primal.C() = p.C, primal.lower() = p.lower, primal.upper() = p.upper;
  primal.resetWorkingSet();
  const QpStatus sp = primal.solve(false);
  if (std::getenv("HQP_FUZZ_VERBOSE")) {
    std::fprintf(stderr, "primal status %s, %d iterations\n", hqp::toString(sp), primal.iterations());
    std::cerr << "primal x " << primal.x().transpose() << "\ndual x " << dual.x().transpose() << "\n";
    auto fresh = std::make_unique<Primal>();
    fresh->resize(n, r, 0, m);
    fresh->A() = p.A;
    fresh->b() = p.b;
    if (m > 0) fresh->C() = p.C, fresh->lower() = p.lower, fresh->upper() = p.upper;
    const QpStatus sf = fresh->solve(false);
    std::cerr << "fresh primal " << hqp::toString(sf) << " x " << fresh->x().transpose() << "\n";
  }

  // KKT residuals and the two optima are only compared where A is well conditioned
  // (κ(A) ≤ 1e7): beyond that, correct answers miss any fixed relative tolerance.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(p.A);
  const double kappa = svd.singularValues()(0) / svd.singularValues()(n - 1);
  const bool conditioned = kappa <= 1e7;
  if (sp == QpStatus::Optimal && conditioned) {  // the reference's own answer, checked the same way
    std::vector<ActiveRow> active;
    for (int k = 0; k < primal.numActive(); ++k)
      active.push_back({primal.activeRow(k), primal.activeAtUpper(k), primal.multiplier(k)});
    checkFeasible(p, primal.x());
    checkKkt(p, primal.x(), Eigen::VectorXd(), active);
  }
  if (s == QpStatus::Optimal) {
    const Eigen::VectorXd x = dual.x().head(n);
    // Known finding (docs/fuzzing.md): with κ(A) > 1e7 the answer can violate a row by ~1e-5
    // (the final feasibility test uses the incrementally updated C x).
    if (skipKnown() && !conditioned) return 0;
    checkFeasible(p, x);
    std::vector<ActiveRow> active;
    for (int k = 0; k < dual.numActive(); ++k) active.push_back({dual.activeRow(k), dual.activeAtUpper(k), dual.multiplier(k)});
    if (conditioned) checkKkt(p, x, Eigen::VectorXd(), active);
    // The primal method must not call a problem with a feasible point infeasible (known
    // finding with (nearly) parallel rows, as for the dual method).
    HQP_FUZZ_CHECK(sp != QpStatus::Infeasible || (skipKnown() && nearlyParallelRows(p.C)));
    // Known finding: with (nearly) parallel constraint rows the two methods can stop at
    // different objectives, both within the KKT tolerances (huge opposing multipliers).
    if (sp == QpStatus::Optimal && conditioned && !(skipKnown() && nearlyParallelRows(p.C))) {
      const double f = objective(p, x), fp = objective(p, primal.x());
      HQP_FUZZ_CHECK2(std::abs(f - fp) <= 1e-6 * (1.0 + f + fp + 0.5 * p.b.squaredNorm()), f, fp);
    }
  } else if (s == QpStatus::Infeasible) {
    // Known finding (docs/fuzzing.md): with two (nearly) parallel or duplicate constraint rows
    // the dual method can stop with Infeasible on a feasible problem (HqpWbc then falls back
    // to ActiveSetQp).
    if (skipKnown() && nearlyParallelRows(p.C)) return 0;
    HQP_FUZZ_CHECK(!p.by_construction);
    if (sp == QpStatus::Optimal) {
      // The primal answer, checked independently, is a feasible point: the dual answer is wrong.
      checkFeasible(p, primal.x());
      fail("DualActiveSetQp: Infeasible, but ActiveSetQp found a feasible point");
    }
  }
  return 0;
}
