#pragma once
// Exit status of the QP solvers (ActiveSetQp, DualActiveSetQp) and of the hierarchies
// (HqpWbc, WqpWbc). Input contracts and what each status means: docs/hqp.md, "Contracts".

namespace hqp {

enum class QpStatus : int {
  Optimal = 0,       // KKT conditions hold to the tolerances of QpSettings; x() meets every row
  Infeasible,        // E x = e inconsistent, or no x meets the inequalities (phase 1 optimum t > tol)
  IterationLimit,    // QpSettings::max_iterations working-set changes; x() is the last feasible iterate
  NumericalFailure,  // a non-finite number appeared, or the result failed its final check
                     // (feasibility / stationarity); x() is finite but not a solution
  InvalidInput,      // the input breaks the contract (NaN, ±inf data, a bound of +inf as lower or
                     // −inf as upper, a magnitude above QpSettings::max_magnitude); x() is 0
  BudgetCut,         // HqpWbc only: the per-solve budget (HqpSettings::budget_us / budget_iterations)
                     // ran out before this level; it and every lower level were skipped and x()
                     // is the higher levels' solution, completed with minimum norm
};

inline const char* toString(QpStatus s) {
  switch (s) {
    case QpStatus::Optimal: return "Optimal";
    case QpStatus::Infeasible: return "Infeasible";
    case QpStatus::IterationLimit: return "IterationLimit";
    case QpStatus::NumericalFailure: return "NumericalFailure";
    case QpStatus::InvalidInput: return "InvalidInput";
    case QpStatus::BudgetCut: return "BudgetCut";
  }
  return "Unknown";
}

}  // namespace hqp
