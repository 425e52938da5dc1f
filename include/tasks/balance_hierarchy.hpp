#pragma once
// The definition of the balance hierarchy (Table I of the paper), for any ContactLayout: the one
// place that says which levels there are and which tasks and constraints each holds. The
// Controller, its diagnostics, the recording, hqp_replay and the replay benchmark take their
// types and row shapes from it (tasks/hierarchy.hpp); docs/adding-a-task.md extends it.
//   level 1: floating-base dynamics (6)           | joint torque limits (nj, two-sided)
//   level 2: contact pose (NC·CD)                 | CoP (4·NC, flat feet only) + friction (5·NC)
//   level 3: linear momentum (3)                  | —
//   level 4: torso posture (3) + contact force (NC·CD) | —
// Walker3 (NC = 2, CD = 6): 6 | 12, 12 | 8 + 10 = 18, 3, 15 rows over x = [q̈ (18); F (12)].

#include "hqp/level.hpp"
#include "tasks/balance_parameters.hpp"
#include "tasks/contact_force_task.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/contact_pose_task.hpp"
#include "tasks/cop_constraint.hpp"
#include "tasks/floating_base_dynamics_task.hpp"
#include "tasks/friction_constraint.hpp"
#include "tasks/hierarchy.hpp"
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

// Table I: Walker3's hierarchy (and the quadruped's, with point feet).
struct BalanceHierarchy {
  template <class L>
  using Levels = LevelList<BalanceLevel1<L>, BalanceLevel2<L>, BalanceLevel3<L>, BalanceLevel4<L>>;
};

template <class L>
using BalanceHqp = HqpOf<BalanceHierarchy, L>;
template <class L>
using BalanceWqp = WqpOf<BalanceHierarchy, L>;

}  // namespace hqp::tasks
