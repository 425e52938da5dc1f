#pragma once
// Tolerances and limits of ActiveSetQp and DualActiveSetQp (include/hqp/active_set_qp.hpp,
// include/hqp/dual_active_set_qp.hpp); HqpWbc and WqpWbc pass them to every QP.

#include <Eigen/Core>

#include <cmath>
#include <type_traits>

namespace hqp {

struct QpSettings {
  int max_iterations = 100;       // hard cap on working-set changes per solve (incl. phase 1)
  double feasibility_tol = 1e-9;  // accepted violation of a constraint row scaled to unit norm
  double rank_tol = 1e-12;        // relative rank threshold of the QR / COD factorizations
  double dual_tol = 1e-10;        // multiplier sign threshold (relative to the gradient scale)
  // Input contract: every matrix and right-hand-side entry and every finite bound must have
  // |v| ≤ max_magnitude (squares and products of such numbers stay far from overflow).
  // Larger data, NaN or ±inf data is refused with QpStatus::InvalidInput. Scale the problem
  // (units) rather than raising this.
  double max_magnitude = 1e50;
};

namespace detail {

// Nonzero if some v[0 .. n) is outside |v| ≤ max (NaN fails the test as well). Branch-free,
// so it vectorizes (Eigen's all() tests one entry at a time and stops at the first failure).
inline unsigned outsideMagnitude(const double* v, Eigen::Index n, double max) {
  unsigned bad = 0;
  for (Eigen::Index i = 0; i < n; ++i) bad |= !(std::abs(v[i]) <= max);
  return bad;
}

// True if every entry v of m is finite with |v| ≤ max.
template <class M>
bool withinMagnitude(const M& m, double max) {
  if constexpr (std::is_base_of_v<Eigen::PlainObjectBase<M>, M>) {
    return outsideMagnitude(m.data(), m.size(), max) == 0;  // the whole storage at once
  } else if constexpr ((M::Flags & Eigen::DirectAccessBit) != 0 &&
                       (M::Flags & Eigen::RowMajorBit) == 0 && M::InnerStrideAtCompileTime == 1) {
    unsigned bad = 0;  // a column-major block (the dual QP's D Z rows): column by column
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      bad |= outsideMagnitude(m.data() + j * m.outerStride(), m.rows(), max);
    return bad == 0;
  } else {
    return (m.array().abs() <= max).all();
  }
}

// A bound pair is in the contract if neither is NaN, lower ≠ +inf, upper ≠ −inf and each
// finite side has magnitude ≤ max. (lower > upper is allowed: the row is then infeasible.)
inline bool boundsValid(double lower, double upper, double max) {
  const bool lo_ok = lower == -HUGE_VAL || std::abs(lower) <= max;
  const bool up_ok = upper == HUGE_VAL || std::abs(upper) <= max;
  return lo_ok && up_ok;
}

}  // namespace detail

}  // namespace hqp
