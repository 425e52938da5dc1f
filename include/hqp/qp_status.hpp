#pragma once
// Exit status of ActiveSetQp::solve() (include/hqp/active_set_qp.hpp).

namespace hqp {

enum class QpStatus : int {
  Optimal = 0,       // KKT conditions hold to the tolerances of QpSettings
  Infeasible,        // E x = e inconsistent, or no x meets the inequalities (phase 1 optimum t > tol)
  IterationLimit,    // QpSettings::max_iterations working-set changes; x() is the last feasible iterate
  NumericalFailure,  // a non-finite number appeared; x() is the last feasible iterate (or 0)
};

inline const char* toString(QpStatus s) {
  switch (s) {
    case QpStatus::Optimal: return "Optimal";
    case QpStatus::Infeasible: return "Infeasible";
    case QpStatus::IterationLimit: return "IterationLimit";
    case QpStatus::NumericalFailure: return "NumericalFailure";
  }
  return "Unknown";
}

}  // namespace hqp
