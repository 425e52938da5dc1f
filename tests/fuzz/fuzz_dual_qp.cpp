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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using hqp::QpStatus;
  using namespace hqp::fuzz;
  FuzzedDataProvider in(data, size);
  QpProblem p = decodeQp(in, kN, kRows, 0, kIneq, true);
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
  std::vector<ActiveRow> pactive;
  for (int k = 0; k < primal.numActive(); ++k)
    pactive.push_back({primal.activeRow(k), primal.activeAtUpper(k), primal.multiplier(k)});
  if (sp == QpStatus::Optimal && conditioned) {  // the reference's own answer, checked the same way
    checkFeasible(p, primal.x());
    checkKkt(p, primal.x(), Eigen::VectorXd(), pactive);
  }
  if (s == QpStatus::Optimal) {
    const Eigen::VectorXd x = dual.x().head(n);
    checkFeasible(p, x);
    std::vector<ActiveRow> active;
    for (int k = 0; k < dual.numActive(); ++k) active.push_back({dual.activeRow(k), dual.activeAtUpper(k), dual.multiplier(k)});
    if (conditioned) checkKkt(p, x, Eigen::VectorXd(), active);
    // The primal method must not call a problem with a feasible point infeasible (unless the
    // point lies beyond where feasibility can be verified in double precision).
    HQP_FUZZ_CHECK(sp != QpStatus::Infeasible || beyondVerifiable(p, x));
    // The optimum of a strictly convex QP is unique, but both answers are only feasible to the
    // tolerance: each objective is at least the other's Lagrangian bound (qp_problem.hpp).
    if (sp == QpStatus::Optimal && conditioned) {
      const Eigen::VectorXd xp = primal.x();
      const double f = objective(p, x), fp = objective(p, xp);
      const double tol = 1e-6 * (1.0 + f + fp + 0.5 * p.b.squaredNorm());
      const Eigen::VectorXd none;
      HQP_FUZZ_CHECK2(f >= lagrangianBound(p, xp, none, pactive, x) - tol, f, fp);
      HQP_FUZZ_CHECK2(fp >= lagrangianBound(p, x, none, active, xp) - tol, fp, f);
    }
  } else if (s == QpStatus::Infeasible) {
    // Only with a certificate: never for a problem built around a feasible point, and the
    // primal method finds no feasible point either.
    HQP_FUZZ_CHECK(!p.by_construction);
    if (sp == QpStatus::Optimal && !beyondVerifiable(p, primal.x())) {
      // The primal answer, checked independently, is a feasible point: the dual answer is wrong.
      checkFeasible(p, primal.x());
      fail("DualActiveSetQp: Infeasible, but ActiveSetQp found a feasible point");
    }
  }
  return 0;
}
