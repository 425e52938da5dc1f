#pragma once
// One tick's problem of an HqpWbc, as a fixed-size value: the stacked rows of every level
// (eq. 3: A, b, row weights; D, lower, upper), the working set each level's QP started from
// (the warm start), and the run's outcome (x*, per level status, residual, active set, time).
// Recording (docs/recording.md): captureWarmStart() before solve(), captureProblem() after it,
// into a preallocated instance; both copy fixed-size blocks only (no heap, no exceptions).
// Replay: loadInstance() puts an instance back into an HqpWbc of the same shape, then solve().
// Files of instances: hqp/problem_file.hpp (not real-time).

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <type_traits>
#include <utility>

#include "hqp/constraint.hpp"
#include "hqp/hqp_types.hpp"
#include "hqp/hqp_wbc.hpp"
#include "hqp/level.hpp"
#include "hqp/task.hpp"

namespace hqp {

// The row counts of one level of a stacked problem.
template <int TaskRows, int ConstraintRows>
struct LevelRows {};

namespace detail {
template <int Nx, class Rows>
struct StackedLevel;
template <int Nx, int T, int C>
struct StackedLevel<Nx, LevelRows<T, C>> {
  using type = Level<Nx, TaskList<Task<T, Nx>>, ConstraintList<Constraint<C, Nx>>>;
};
template <int Nx, int T>
struct StackedLevel<Nx, LevelRows<T, 0>> {
  using type = Level<Nx, TaskList<Task<T, Nx>>>;
};
}  // namespace detail

// An HqpWbc with one task and at most one constraint per level: replays any recorded
// hierarchy of the same row counts (stacking is all that distinguishes the two), without
// the robot code that filled the original, e.g. the paper's Table I:
//   StackedHqp<30, LevelRows<6, 12>, LevelRows<12, 18>, LevelRows<3, 0>, LevelRows<15, 0>>.
template <int Nx, class... Rows>
using StackedHqp = HqpWbc<Nx, typename detail::StackedLevel<Nx, Rows>::type...>;

// The working set level p's QP starts the solve from.
template <int MaxActive>
struct LevelWarmStart {
  int variables = 0;   // n of the QP it belongs to (a QP of another size starts cold)
  int num_active = 0;  // 0: the level starts cold (also for a level without a QP)
  std::array<int, MaxActive> row{};     // stacked constraint row (as HqpLevelResult::active_row)
  std::array<bool, MaxActive> upper{};  // side
};

// Wbc: an HqpWbc. Instances of two HqpWbc types with the same Nx and the same task and
// constraint rows per level are interchangeable (the stacked problem is all that matters).
template <class Wbc>
struct ProblemInstance {
  static constexpr int nx = Wbc::nx;
  static constexpr int num_levels = Wbc::num_levels;
  static constexpr int task_rows = Wbc::total_task_rows;
  static constexpr int constraint_rows = Wbc::total_constraint_rows;
  static constexpr int max_active = Wbc::max_active;
  using Result = typename Wbc::Result;
  using MatrixA = Eigen::Matrix<double, capacity(task_rows), nx>;
  using VectorA = Eigen::Matrix<double, capacity(task_rows), 1>;
  using MatrixD = Eigen::Matrix<double, capacity(constraint_rows), nx>;
  using VectorD = Eigen::Matrix<double, capacity(constraint_rows), 1>;

  std::int64_t tick = 0;  // tick index in the run
  double time = 0.0;      // s, time of the tick in the run

  // All levels stacked in priority order (level p from Wbc::task_offset[p] /
  // constraint_offset[p]); only the first task_rows / constraint_rows rows are used.
  MatrixA A = MatrixA::Zero();   // task rows                (task_rows x nx)
  VectorA b = VectorA::Zero();   // references               (task_rows)
  VectorA w = VectorA::Ones();   // row weights              (task_rows)
  MatrixD D = MatrixD::Zero();   // constraint rows          (constraint_rows x nx)
  VectorD lower = VectorD::Zero();  // lower bounds, −inf: none (constraint_rows)
  VectorD upper = VectorD::Zero();  // upper bounds, +inf: none (constraint_rows)

  std::array<LevelWarmStart<max_active>, num_levels> warm{};  // incoming working sets
  Result result{};  // what the run's solve() returned (x*, statuses, active sets, times)
};

namespace detail {

template <class Wbc, std::size_t... P>
void captureWarmStartImpl(const Wbc& wbc, ProblemInstance<Wbc>& out,
                          std::index_sequence<P...>) noexcept {
  const auto one = [&](const auto& qp, auto& ws) {
    ws = {};
    using Qp = std::remove_cv_t<std::remove_reference_t<decltype(qp)>>;
    if constexpr (std::is_same_v<Qp, typename Wbc::Qp>) {
      ws.variables = qp.variables();
      if (!qp.hasWorkingSet()) return;
      const int na = qp.numActive() < Wbc::max_active ? qp.numActive() : Wbc::max_active;
      for (int k = 0; k < na; ++k) {
        ws.row[static_cast<std::size_t>(k)] = qp.activeRow(k);
        ws.upper[static_cast<std::size_t>(k)] = qp.activeAtUpper(k);
      }
      ws.num_active = na;
    }
  };
  (one(wbc.template levelQp<static_cast<int>(P)>(), out.warm[P]), ...);
}

template <class Level, class Instance, std::size_t... I>
void loadTasks(Level& level, const Instance& in, int t0, std::index_sequence<I...>) noexcept {
  auto& tasks = level.tasks();
  ((std::get<I>(tasks).A =
        in.A.template middleRows<std::tuple_element_t<I, typename Level::TaskTuple>::rows>(
            t0 + Level::task_offsets[I]),
    std::get<I>(tasks).b =
        in.b.template segment<std::tuple_element_t<I, typename Level::TaskTuple>::rows>(
            t0 + Level::task_offsets[I]),
    std::get<I>(tasks).weight =
        in.w.template segment<std::tuple_element_t<I, typename Level::TaskTuple>::rows>(
            t0 + Level::task_offsets[I])),
   ...);
}

template <class Level, class Instance, std::size_t... I>
void loadConstraints(Level& level, const Instance& in, int c0, std::index_sequence<I...>) noexcept {
  auto& cons = level.constraints();
  static_cast<void>(cons), static_cast<void>(in), static_cast<void>(c0);  // levels without any
  ((std::get<I>(cons).D =
        in.D.template middleRows<std::tuple_element_t<I, typename Level::ConstraintTuple>::rows>(
            c0 + Level::constraint_offsets[I]),
    std::get<I>(cons).lower =
        in.lower.template segment<std::tuple_element_t<I, typename Level::ConstraintTuple>::rows>(
            c0 + Level::constraint_offsets[I]),
    std::get<I>(cons).upper =
        in.upper.template segment<std::tuple_element_t<I, typename Level::ConstraintTuple>::rows>(
            c0 + Level::constraint_offsets[I])),
   ...);
}

template <class Wbc, std::size_t... P>
void loadInstanceImpl(const ProblemInstance<Wbc>& in, Wbc& wbc, std::index_sequence<P...>) noexcept {
  const auto one = [&](auto& level, int t0, int c0) {
    using L = std::remove_reference_t<decltype(level)>;
    loadTasks(level, in, t0, std::make_index_sequence<std::tuple_size_v<typename L::TaskTuple>>{});
    loadConstraints(level, in, c0,
                    std::make_index_sequence<std::tuple_size_v<typename L::ConstraintTuple>>{});
  };
  (one(wbc.template level<static_cast<int>(P)>(), Wbc::task_offset[P], Wbc::constraint_offset[P]),
   ...);
}

template <class Wbc, std::size_t... P>
void captureBounds(const Wbc& wbc, ProblemInstance<Wbc>& out, std::index_sequence<P...>) noexcept {
  // From the levels (as solve() stacked them): solve() overwrites the stacked bounds of an
  // infeasible level, so its own copy would not replay the tick.
  (wbc.template level<static_cast<int>(P)>().stackConstraints(out.D, out.lower, out.upper,
                                                              Wbc::constraint_offset[P]),
   ...);
}

}  // namespace detail

// Before wbc.solve(): the working set each level's QP will start from.
template <class Wbc>
void captureWarmStart(const Wbc& wbc, ProblemInstance<Wbc>& out) noexcept {
  detail::captureWarmStartImpl(wbc, out, std::make_index_sequence<Wbc::num_levels>{});
}

// After wbc.solve(): the stacked problem it solved and its result (tick and time: the caller).
template <class Wbc>
void captureProblem(const Wbc& wbc, ProblemInstance<Wbc>& out) noexcept {
  constexpr int T = Wbc::total_task_rows;
  out.A.template topRows<T>() = wbc.stackedA().template topRows<T>();
  out.b.template head<T>() = wbc.stackedB().template head<T>();
  out.w.template head<T>() = wbc.stackedWeights().template head<T>();
  detail::captureBounds(wbc, out, std::make_index_sequence<Wbc::num_levels>{});
  out.result = wbc.result();
}

// Replay: the instance's rows into wbc's tasks and constraints, and (warm) each level's
// recorded incoming working set, or (cold) none. The next wbc.solve() solves the instance.
template <class Wbc>
void loadInstance(const ProblemInstance<Wbc>& in, Wbc& wbc, bool warm) noexcept {
  detail::loadInstanceImpl(in, wbc, std::make_index_sequence<Wbc::num_levels>{});
  wbc.resetWarmStart();
  if (!warm) return;
  for (int p = 0; p < Wbc::num_levels; ++p) {
    const auto& ws = in.warm[static_cast<std::size_t>(p)];
    wbc.setWorkingSet(p, ws.variables, ws.num_active, ws.row.data(), ws.upper.data());
  }
}

}  // namespace hqp
