#pragma once
// What a hierarchy definition gives. A definition is a type with one member template,
//   template <class L> using Levels = LevelList<hqp::Level<L::nx, TaskList<...>, ConstraintList<...>>, ...>;
// the levels in priority order for a ContactLayout L (balance_hierarchy.hpp holds Table I).
// Everything else is derived from it here, so adding a task is writing its class and naming it
// in a definition (docs/adding-a-task.md): the solvers (HqpWbc, WqpWbc), the row shape of a
// recorded problem (StackedHqp), the layout of the per-level task errors of the diagnostics, and
// the visitors that update, configure and reset every task and constraint.
//
// What a task or constraint class must have: rows, cols, A/b/weight (hqp::Task) or D/lower/upper
// (hqp::Constraint), and update(dyn, refs) or update(dyn, refs, state). Optional: configure(p)
// (p = BalanceParameters), resetState(), error() (an Eigen vector with a compile-time size; it is
// reported in the diagnostics).

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "hqp/hqp_wbc.hpp"
#include "hqp/level.hpp"
#include "hqp/problem_instance.hpp"
#include "hqp/wqp_wbc.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

// The levels of a hierarchy, highest priority first.
template <class... Levels>
struct LevelList {};

// The estimated state of this tick, for tasks that need more than the dynamics (a joint-space
// task needs q); handed to update(dyn, refs, state).
template <class Robot>
struct RobotState {
  const Eigen::Matrix<double, Robot::nq, 1>& q;  // [base position; base quaternion (x, y, z, w); joints]
  const Eigen::Matrix<double, Robot::nv, 1>& v;  // [base twist (body frame); joint rates]
};

namespace detail {

// Rows of T::error(), 0 for an item without error().
template <class T, class = void>
struct ErrorRows : std::integral_constant<int, 0> {};
template <class T>
struct ErrorRows<T, std::void_t<decltype(std::declval<const T&>().error())>>
    : std::integral_constant<int, std::decay_t<decltype(std::declval<const T&>().error())>::RowsAtCompileTime> {};

template <class Tuple>
struct TupleErrorRows;
template <class... Ts>
struct TupleErrorRows<std::tuple<Ts...>> : std::integral_constant<int, (0 + ... + ErrorRows<Ts>::value)> {};

template <class List>
struct LevelPack;
template <class... Ls>
struct LevelPack<LevelList<Ls...>> {
  static_assert(sizeof...(Ls) > 0, "a hierarchy has at least one level");
  template <int Nx>
  using Hqp = hqp::HqpWbc<Nx, Ls...>;
  template <int Nx>
  using Wqp = hqp::WqpWbc<Nx, Ls...>;
  // One plain task and at most one constraint per level with the same rows: what a recorded
  // problem is replayed with (hqp/problem_instance.hpp).
  template <int Nx>
  using Stacked = hqp::StackedHqp<Nx, hqp::LevelRows<Ls::task_rows, Ls::constraint_rows>...>;
  static constexpr std::array<int, sizeof...(Ls) + 1> error_offset =
      hqp::detail::rowOffsets<TupleErrorRows<typename Ls::TaskTuple>::value...>();
};

template <class T, class P, class = void>
struct HasConfigure : std::false_type {};
template <class T, class P>
struct HasConfigure<T, P, std::void_t<decltype(std::declval<T&>().configure(std::declval<const P&>()))>>
    : std::true_type {};
template <class T, class = void>
struct HasResetState : std::false_type {};
template <class T>
struct HasResetState<T, std::void_t<decltype(std::declval<T&>().resetState())>> : std::true_type {};
template <class T, class Dyn, class Refs, class State, class = void>
struct TakesState : std::false_type {};
template <class T, class Dyn, class Refs, class State>
struct TakesState<T, Dyn, Refs, State,
                  std::void_t<decltype(std::declval<T&>().update(std::declval<const Dyn&>(),
                                                                 std::declval<const Refs&>(),
                                                                 std::declval<const State&>()))>>
    : std::true_type {};

template <class Level, class F>
void forEachItemOfLevel(Level& level, F& f) {
  std::apply([&](auto&... t) { (f(t), ...); }, level.tasks());
  std::apply([&](auto&... c) { (f(c), ...); }, level.constraints());
}
template <class Wbc, class F, std::size_t... P>
void forEachItemOfLevels(Wbc& wbc, F& f, std::index_sequence<P...>) {
  (forEachItemOfLevel(wbc.template level<static_cast<int>(P)>(), f), ...);
}
// f(item) for every task and constraint of every level, in priority order.
template <class Wbc, class F>
void forEachItem(Wbc& wbc, F f) {
  forEachItemOfLevels(wbc, f, std::make_index_sequence<static_cast<std::size_t>(Wbc::num_levels)>{});
}

// f(p, task) for every task of every level (const), p = 0-based level.
template <class Level, class F, std::size_t... K>
void forEachTaskOfLevel(const Level& level, int p, F& f, std::index_sequence<K...>) {
  (f(p, level.template task<static_cast<int>(K)>()), ...);
}
template <class Wbc, class F, std::size_t... P>
void forEachTaskImpl(const Wbc& wbc, F& f, std::index_sequence<P...>) {
  (forEachTaskOfLevel(wbc.template level<static_cast<int>(P)>(), static_cast<int>(P), f,
                      std::make_index_sequence<static_cast<std::size_t>(
                          Wbc::template LevelType<static_cast<int>(P)>::num_tasks)>{}),
   ...);
}
template <class Wbc, class F>
void forEachTask(const Wbc& wbc, F f) {
  forEachTaskImpl(wbc, f, std::make_index_sequence<static_cast<std::size_t>(Wbc::num_levels)>{});
}

}  // namespace detail

// The types and row layouts a definition gives for layout L.
template <class Definition, class L>
struct Hierarchy {
  using Levels = typename Definition::template Levels<L>;
  using Hqp = typename detail::LevelPack<Levels>::template Hqp<L::nx>;
  using Wqp = typename detail::LevelPack<Levels>::template Wqp<L::nx>;
  using Stacked = typename detail::LevelPack<Levels>::template Stacked<L::nx>;
  static constexpr int num_levels = Hqp::num_levels;
  // Level p's task errors are rows [error_offset[p], error_offset[p + 1]) of the stacked errors.
  static constexpr std::array<int, num_levels + 1> error_offset = detail::LevelPack<Levels>::error_offset;
  static constexpr int error_rows = error_offset[num_levels];
};

template <class Definition, class L>
using HqpOf = typename Hierarchy<Definition, L>::Hqp;
template <class Definition, class L>
using WqpOf = typename Hierarchy<Definition, L>::Wqp;
// The shape a recording of HqpOf<Definition, L> is replayed with (hqp_replay, the benchmark).
template <class Definition, class L>
using StackedHqpOf = typename Hierarchy<Definition, L>::Stacked;

// update(dyn, refs) — or update(dyn, refs, state) where the item takes the state — on every
// task and constraint of every level of `wbc` (HqpWbc or WqpWbc).
template <class Wbc, class Dyn, int NC, class State>
void updateHierarchy(Wbc& wbc, const Dyn& dyn, const References<NC>& refs, const State& state) noexcept {
  detail::forEachItem(wbc, [&](auto& item) {
    using T = std::decay_t<decltype(item)>;
    if constexpr (detail::TakesState<T, Dyn, References<NC>, State>::value) item.update(dyn, refs, state);
    else item.update(dyn, refs);
  });
}
template <class Wbc, class Dyn, int NC>
void updateHierarchy(Wbc& wbc, const Dyn& dyn, const References<NC>& refs) noexcept {
  detail::forEachItem(wbc, [&](auto& item) { item.update(dyn, refs); });
}

// configure(p) on every item that has it (set-up time; not in the tick).
template <class Wbc, class Params>
void configureHierarchy(Wbc& wbc, const Params& p) {
  detail::forEachItem(wbc, [&](auto& item) {
    using T = std::decay_t<decltype(item)>;
    if constexpr (detail::HasConfigure<T, Params>::value) item.configure(p);
  });
}

// Back to the initial internal state for the items that keep one (an integral); set-up or
// reset time, not in the tick.
template <class Wbc>
void resetHierarchyState(Wbc& wbc) noexcept {
  detail::forEachItem(wbc, [](auto& item) {
    if constexpr (detail::HasResetState<std::decay_t<decltype(item)>>::value) item.resetState();
  });
}

// f(item) on every task and constraint of type T (wherever its level is).
template <class T, class Wbc, class F>
void forEachItemOfType(Wbc& wbc, F f) {
  detail::forEachItem(wbc, [&](auto& item) {
    if constexpr (std::is_same_v<std::decay_t<decltype(item)>, T>) f(item);
  });
}

// The first task of type T in priority order, nullptr if the hierarchy has none.
template <class T, class Wbc>
const T* findTask(const Wbc& wbc) {
  const T* found = nullptr;
  detail::forEachTask(wbc, [&](int, const auto& t) {
    if constexpr (std::is_same_v<std::decay_t<decltype(t)>, T>)
      if (found == nullptr) found = &t;
  });
  return found;
}

// Every task's error() stacked in priority order (level p from offset[p]; tasks without error()
// take no rows). `out` needs at least Hierarchy::error_rows rows.
template <class Wbc, class Vec>
void stackTaskErrors(const Wbc& wbc, Vec& out) noexcept {
  int row = 0;
  detail::forEachTask(wbc, [&](int, const auto& t) {
    constexpr int r = detail::ErrorRows<std::decay_t<decltype(t)>>::value;
    if constexpr (r > 0) {
      out.template segment<r>(row) = t.error();
      row += r;
    }
  });
}

}  // namespace hqp::tasks
