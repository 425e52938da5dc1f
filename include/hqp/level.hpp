#pragma once
// One priority level: the tasks and constraints stacked into eq. (3) of the paper,
//   A_p x − b_p = 0 (least squares),   lower_p ≤ D_p x ≤ upper_p,
// with all row counts known at compile time so the solvers stack them without allocation.

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstddef>
#include <tuple>
#include <utility>

#include "hqp/constraint.hpp"

namespace hqp {

template <class... Ts>
struct TaskList {};
template <class... Cs>
struct ConstraintList {};

namespace detail {

// Offsets of consecutive row blocks: {0, r0, r0 + r1, ...}.
template <int... Rows>
constexpr std::array<int, sizeof...(Rows) + 1> rowOffsets() {
  std::array<int, sizeof...(Rows) + 1> out{};
  const int rows[] = {0, Rows...};
  for (std::size_t i = 1; i < out.size(); ++i) out[i] = out[i - 1] + rows[i];
  return out;
}

}  // namespace detail

// Slack = true marks a level whose own constraints HqpWbc may relax minimally when they
// cannot be met (the slack option, off by default as in the paper); it is a compile-time
// flag so that hierarchies without slack levels do not carry (or compile) the slack QP.
template <int Nx, class Tasks, class Constraints = ConstraintList<>, bool Slack = false>
class Level;

// Level<Nx, TaskList<Task<6, Nx>, ...>, ConstraintList<Constraint<12, Nx>, ...>>.
// Element types only need the members of Task / Constraint (derived types are fine).
template <int Nx, class... Ts, class... Cs, bool Slack>
class Level<Nx, TaskList<Ts...>, ConstraintList<Cs...>, Slack> {
  static_assert(sizeof...(Ts) > 0, "a level has at least one task");
  static_assert(((Ts::cols == Nx) && ...), "every task of a level has Nx columns");
  static_assert(((Cs::cols == Nx) && ...), "every constraint of a level has Nx columns");

 public:
  static constexpr int nx = Nx;
  static constexpr bool slack = Slack;  // own constraints may be relaxed (HqpWbc slack option)
  static constexpr int num_tasks = static_cast<int>(sizeof...(Ts));
  static constexpr int num_constraints = static_cast<int>(sizeof...(Cs));
  static constexpr int task_rows = (0 + ... + Ts::rows);
  static constexpr int constraint_rows = (0 + ... + Cs::rows);
  static constexpr std::array<int, sizeof...(Ts) + 1> task_offsets = detail::rowOffsets<Ts::rows...>();
  static constexpr std::array<int, sizeof...(Cs) + 1> constraint_offsets =
      detail::rowOffsets<Cs::rows...>();

  using TaskTuple = std::tuple<Ts...>;
  using ConstraintTuple = std::tuple<Cs...>;

  template <int K>
  auto& task() { return std::get<K>(tasks_); }
  template <int K>
  const auto& task() const { return std::get<K>(tasks_); }
  template <int K>
  auto& constraint() { return std::get<K>(constraints_); }
  template <int K>
  const auto& constraint() const { return std::get<K>(constraints_); }

  TaskTuple& tasks() { return tasks_; }
  ConstraintTuple& constraints() { return constraints_; }

  // Writes [A_p] into A.middleRows(row0, task_rows), b_p and the row weights likewise.
  template <class MatA, class VecB, class VecW>
  void stackTasks(MatA& A, VecB& b, VecW& w, int row0) const {
    stackTasksImpl(A, b, w, row0, std::index_sequence_for<Ts...>{});
  }

  // Writes [D_p] into D.middleRows(row0, constraint_rows), the bounds likewise, each read by
  // interpretBound (|bound| ≥ kInfBound is ±inf): the one place the hierarchies take bounds in,
  // so everything downstream sees exactly what ±inf would give.
  template <class MatD, class VecL, class VecU>
  void stackConstraints(MatD& D, VecL& lower, VecU& upper, int row0) const {
    stackConstraintsImpl(D, lower, upper, row0, std::index_sequence_for<Cs...>{});
  }

  // Σ over the level's tasks of ‖A x − b‖² (unweighted) at x.
  template <class VecX>
  double residual(const VecX& x) const {
    return std::apply([&](const auto&... t) { return (0.0 + ... + (t.A * x - t.b).squaredNorm()); },
                      tasks_);
  }

 private:
  template <class MatA, class VecB, class VecW, std::size_t... I>
  void stackTasksImpl(MatA& A, VecB& b, VecW& w, int row0, std::index_sequence<I...>) const {
    ((A.template middleRows<Ts::rows>(row0 + task_offsets[I]) = std::get<I>(tasks_).A,
      b.template segment<Ts::rows>(row0 + task_offsets[I]) = std::get<I>(tasks_).b,
      w.template segment<Ts::rows>(row0 + task_offsets[I]) = std::get<I>(tasks_).weight),
     ...);
  }
  template <class MatD, class VecL, class VecU, std::size_t... I>
  void stackConstraintsImpl(MatD& D, VecL& lower, VecU& upper, int row0,
                            std::index_sequence<I...>) const {
    static_cast<void>(D), static_cast<void>(lower), static_cast<void>(upper);  // empty lists
    static_cast<void>(row0);
    ((D.template middleRows<Cs::rows>(row0 + constraint_offsets[I]) = std::get<I>(constraints_).D,
      lower.template segment<Cs::rows>(row0 + constraint_offsets[I]) =
          std::get<I>(constraints_).lower.unaryExpr([](double v) { return interpretBound(v); }),
      upper.template segment<Cs::rows>(row0 + constraint_offsets[I]) =
          std::get<I>(constraints_).upper.unaryExpr([](double v) { return interpretBound(v); })),
     ...);
  }

  TaskTuple tasks_;
  ConstraintTuple constraints_;
};

// A level with the slack option available (see HqpWbc::setSlack).
template <int Nx, class Tasks, class Constraints>
using SoftLevel = Level<Nx, Tasks, Constraints, true>;

}  // namespace hqp
