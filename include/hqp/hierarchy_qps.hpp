#pragma once
// The QP types HqpWbc and WqpWbc solve a hierarchy with. Both take them from here, so that a
// unit holding both solvers of one hierarchy (a controller with a weighted fallback, a
// comparison) compiles each solver's code once: every distinct ActiveSetQp or DualActiveSetQp
// shape is a whole instantiation of the solver, and GCC's cost grows faster than the number
// of shapes (docs/development.md, "Build and CI cost"). The sizes are capacities; the
// problems are sized at run time within them.

#include <algorithm>

#include "hqp/active_set_qp.hpp"
#include "hqp/dual_active_set_qp.hpp"
#include "hqp/hqp_types.hpp"
#include "hqp/qp_settings.hpp"

namespace hqp {
namespace detail {

// Stands in for a QP object where a hierarchy needs none (a level without constraints, no
// dual use).
struct NoQp {
  NoQp() = default;
  explicit NoQp(const QpSettings&) {}
};

template <class... Levels>
constexpr int maxTaskRows() {
  int m = 0;
  ((m = std::max(m, Levels::task_rows)), ...);
  return m;
}

template <int Nx, class... Levels>
struct HierarchyQps {
  static constexpr int task_rows = (0 + ... + Levels::task_rows);
  static constexpr int constraint_rows = (0 + ... + Levels::constraint_rows);
  // HqpWbc's level QPs (one level's task rows) and WqpWbc's QP (all of them, stacked).
  using Qp = ActiveSetQp<Nx, capacity(task_rows), 0, capacity(constraint_rows)>;
  // HqpWbc's dual uses (a level's task rows plus one per null-space variable) and WqpWbc's
  // dual method (all task rows).
  static constexpr int dual_rows =
      std::max(capacity(task_rows), Nx + capacity(maxTaskRows<Levels...>()));
  using DualQp = DualActiveSetQp<Nx, dual_rows, capacity(constraint_rows)>;
};

}  // namespace detail
}  // namespace hqp
