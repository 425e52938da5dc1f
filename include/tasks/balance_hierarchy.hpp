#pragma once
// The balance hierarchy of Table I of the paper, for any ContactLayout:
//   level 1: floating-base dynamics (6)           | joint torque limits (nj, two-sided)
//   level 2: contact pose (NC·CD)                 | CoP (4·NC, flat feet only) + friction (5·NC)
//   level 3: linear momentum (3)                  | —
//   level 4: torso posture (3) + contact force (NC·CD) | —
// Walker3 (NC = 2, CD = 6): 6 | 12, 12 | 8 + 10 = 18, 3, 15 rows over x = [q̈ (18); F (12)].
// updateHierarchy / configureHierarchy visit every task and constraint of every level, so
// they work for HqpWbc and WqpWbc alike.

#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "hqp/hqp_wbc.hpp"
#include "hqp/level.hpp"
#include "hqp/wqp_wbc.hpp"
#include "tasks/balance_parameters.hpp"
#include "tasks/contact_force_task.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/contact_pose_task.hpp"
#include "tasks/cop_constraint.hpp"
#include "tasks/floating_base_dynamics_task.hpp"
#include "tasks/friction_constraint.hpp"
#include "tasks/joint_torque_limits.hpp"
#include "tasks/linear_momentum_task.hpp"
#include "tasks/references.hpp"
#include "tasks/torso_posture_task.hpp"

namespace hqp::tasks {

namespace detail {
// Level-2 constraints: CoP + friction for flat feet, friction alone for point feet.
template <class L, int CD = L::contact_dim>
struct ContactConstraints {
  using type = hqp::ConstraintList<CopConstraint<L>, FrictionConstraint<L>>;
};
template <class L>
struct ContactConstraints<L, 3> {
  using type = hqp::ConstraintList<FrictionConstraint<L>>;
};
}  // namespace detail

template <class L>
using BalanceLevel1 = hqp::Level<L::nx, hqp::TaskList<FloatingBaseDynamicsTask<L>>,
                                 hqp::ConstraintList<JointTorqueLimits<L>>>;
template <class L>
using BalanceLevel2 = hqp::Level<L::nx, hqp::TaskList<ContactPoseTask<L>>,
                                 typename detail::ContactConstraints<L>::type>;
template <class L>
using BalanceLevel3 = hqp::Level<L::nx, hqp::TaskList<LinearMomentumTask<L>>>;
template <class L>
using BalanceLevel4 = hqp::Level<L::nx, hqp::TaskList<TorsoPostureTask<L>, ContactForceTask<L>>>;

template <class L>
using BalanceHqp =
    hqp::HqpWbc<L::nx, BalanceLevel1<L>, BalanceLevel2<L>, BalanceLevel3<L>, BalanceLevel4<L>>;
template <class L>
using BalanceWqp =
    hqp::WqpWbc<L::nx, BalanceLevel1<L>, BalanceLevel2<L>, BalanceLevel3<L>, BalanceLevel4<L>>;

namespace detail {
template <class Level, class F>
void forEachItemOfLevel(Level& level, F& f) {
  std::apply([&](auto&... t) { (f(t), ...); }, level.tasks());
  std::apply([&](auto&... c) { (f(c), ...); }, level.constraints());
}
template <class Wbc, class F, std::size_t... P>
void forEachItemOfLevels(Wbc& wbc, F& f, std::index_sequence<P...>) {
  (forEachItemOfLevel(wbc.template level<static_cast<int>(P)>(), f), ...);
}
template <class T, class = void>
struct HasResetState : std::false_type {};
template <class T>
struct HasResetState<T, std::void_t<decltype(std::declval<T&>().resetState())>> : std::true_type {};
// f(item) for every task and constraint of every level, in priority order.
template <class Wbc, class F>
void forEachItem(Wbc& wbc, F f) {
  forEachItemOfLevels(wbc, f, std::make_index_sequence<static_cast<std::size_t>(Wbc::num_levels)>{});
}
}  // namespace detail

// update(dyn, refs) on every task and constraint of every level of `wbc` (HqpWbc or WqpWbc).
template <class Wbc, class Dyn, int NC>
void updateHierarchy(Wbc& wbc, const Dyn& dyn, const References<NC>& refs) noexcept {
  detail::forEachItem(wbc, [&](auto& item) { item.update(dyn, refs); });
}

// Gains, μ, fz_min, sole rectangle, torque limits and level-4 weights onto every task and
// constraint (set-up time; not in the tick).
template <class Wbc, int NJ>
void configureHierarchy(Wbc& wbc, const BalanceParameters<NJ>& p) {
  detail::forEachItem(wbc, [&](auto& item) { item.configure(p); });
}

// Back to the initial internal state for the items that keep one (an integral); set-up or
// reset time, not in the tick.
template <class Wbc>
void resetHierarchyState(Wbc& wbc) noexcept {
  detail::forEachItem(wbc, [](auto& item) {
    if constexpr (detail::HasResetState<std::decay_t<decltype(item)>>::value) item.resetState();
  });
}

}  // namespace hqp::tasks
