// libFuzzer harness: ActiveSetQp on decoded least-squares QPs (docs/fuzzing.md).
// Every answer is checked independently of the solver:
//  - input outside the contract (NaN or ±inf data, lower > upper, lower = +inf, upper = −inf)
//    is never Optimal;
//  - Optimal: x feasible, the KKT conditions hold with the reported multipliers (stationarity,
//    μ ≥ 0, active rows at their bounds), and on small problems the objective equals the
//    optimum of an enumeration of active sets (tests/support/brute_force_qp.hpp);
//  - Infeasible: no point of the enumeration (small problems) is feasible, and a problem built
//    around a feasible point is never Infeasible;
//  - the same checks after a warm re-solve with a changed b.
#include <vector>

#include "hqp/active_set_qp.hpp"
#include "qp_problem.hpp"
#include "support/brute_force_qp.hpp"

namespace {

using Qp = hqp::ActiveSetQp<6, 8, 3, 8>;

void load(Qp& qp, const hqp::fuzz::QpProblem& p) {
  qp.resize(static_cast<int>(p.A.cols()), static_cast<int>(p.A.rows()), static_cast<int>(p.E.rows()),
            static_cast<int>(p.C.rows()));
  if (p.A.rows() > 0) qp.A() = p.A, qp.b() = p.b;
  if (p.E.rows() > 0) qp.E() = p.E, qp.e() = p.e;
  if (p.C.rows() > 0) qp.C() = p.C, qp.lower() = p.lower, qp.upper() = p.upper;
}

void check(const Qp& qp, hqp::QpStatus s, const hqp::fuzz::QpProblem& p) {
  using hqp::QpStatus;
  using namespace hqp::fuzz;
  if (std::getenv("HQP_FUZZ_VERBOSE")) {
    p.print();
    std::fprintf(stderr, "status %s\n", hqp::toString(s));
    std::cerr.precision(17);
    std::cerr << "x " << qp.x().transpose() << "\nC x " << (p.C * qp.x()).transpose() << "\n";
  }
  if (!p.validInput()) {
    HQP_FUZZ_CHECK(s != QpStatus::Optimal);
    return;
  }
  const bool small = p.A.cols() <= 5 && p.C.rows() <= 7;
  if (s == QpStatus::Optimal) {
    const Eigen::VectorXd x = qp.x();
    checkFeasible(p, x);
    std::vector<ActiveRow> active;
    for (int k = 0; k < qp.numActive(); ++k) active.push_back({qp.activeRow(k), qp.activeAtUpper(k), qp.multiplier(k)});
    const Eigen::VectorXd lambda = p.E.rows() > 0 ? Eigen::VectorXd(qp.equalityMultipliers().head(p.E.rows()))
                                                  : Eigen::VectorXd();
    checkKkt(p, x, lambda, active);
    if (small) {
      const auto ref = hqp::testing::bruteForceQp(p.A, p.b, p.E, p.e, p.C, p.lower, p.upper, 1e-9);
      if (ref.feasible) {
        const double f = objective(p, x);
        const double tol = 1e-6 * (1.0 + ref.objective + 0.5 * p.b.squaredNorm());
        // Not below the enumeration (its faces include x's). Above it only as far as x's
        // Lagrangian bound at the enumerated point allows (qp_problem.hpp): the KKT and
        // feasibility tolerances let a nearly dependent row set or a nearly singular A put the
        // optimum of the tolerance-wide feasible set far away (70.8 above, at 1e-10 apart rows).
        // The two rank decisions differ (solver 1e-12, enumeration 1e-10 relative): with a
        // singular value of A between them the solver may use a direction the enumeration
        // calls null and end lower, at |x| ~ 1e10, beyond where rows can be checked.
        bool gray = false;
        if (p.A.rows() > 0) {
          const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(p.A).singularValues();
          for (int i = 0; i < sv.size(); ++i)
            gray = gray || (sv(i) > 1e-13 * sv(0) && sv(i) < 1e-9 * std::max(1.0, sv(0)));
        }
        if (!gray && !beyondVerifiable(p, x)) HQP_FUZZ_CHECK2(f >= ref.objective - tol, f, ref.objective);
        HQP_FUZZ_CHECK2(ref.objective >= lagrangianBound(p, x, lambda, active, ref.x) - tol, f, ref.objective);
      }
    }
  } else if (s == QpStatus::Infeasible) {
    HQP_FUZZ_CHECK(!p.by_construction);
    if (small) {
      const auto ref = hqp::testing::bruteForceQp(p.A, p.b, p.E, p.e, p.C, p.lower, p.upper, 1e-12);
      HQP_FUZZ_CHECK2(!ref.feasible || beyondVerifiable(p, ref.x), ref.objective, 0.0);
    }
  }
  // IterationLimit and NumericalFailure are allowed outcomes (reported, never Optimal).
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  hqp::fuzz::QpProblem p = hqp::fuzz::decodeQp(in, 6, 8, 3, 8);
  static Qp qp;
  load(qp, p);
  qp.resetWorkingSet();
  check(qp, qp.solve(false), p);
  // Warm start on a changed b (the working set of the solve above).
  if (in.ConsumeBool() && p.A.rows() > 0) {
    for (int i = 0; i < p.b.size(); ++i) p.b(i) += hqp::fuzz::number(in);
    qp.b() = p.b;
    check(qp, qp.solve(true), p);
  }
  return 0;
}
