#pragma once
// Tolerances and limits of ActiveSetQp (include/hqp/active_set_qp.hpp).

namespace hqp {

struct QpSettings {
  int max_iterations = 100;       // hard cap on working-set changes per solve (incl. phase 1)
  double feasibility_tol = 1e-9;  // accepted violation of a constraint row scaled to unit norm
  double rank_tol = 1e-12;        // relative rank threshold of the QR / COD factorizations
  double dual_tol = 1e-10;        // multiplier sign threshold (relative to the gradient scale)
};

}  // namespace hqp
