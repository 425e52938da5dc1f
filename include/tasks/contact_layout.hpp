#pragma once
// ContactLayout: the sizes of the decision vector x = [q̈ (nv); F (NC·CD)] of the
// balance hierarchy (Section III-B of the paper) for a robot with NC contacts of
// dimension CD: CD = 6 is a flat foot ([force; moment] about the sole origin),
// CD = 3 a point foot (force only). Wrenches are world-aligned (docs/tasks.md).

#include "model/robot_dynamics.hpp"

namespace hqp::tasks {

template <class Robot, int NC, int CD>
struct ContactLayout {
  static_assert(NC >= 1, "at least one contact");
  static_assert(CD == 3 || CD == 6, "a contact is a point (3) or a flat foot (6)");
  static_assert(Robot::floating_base, "the balance hierarchy needs a floating base");

  using robot = Robot;
  static constexpr int nv = Robot::nv;          // generalized velocities
  static constexpr int nj = Robot::nj;          // actuated joints
  static constexpr int num_contacts = NC;
  static constexpr int contact_dim = CD;
  static constexpr int nf = NC * CD;            // contact force variables
  static constexpr int nx = nv + nf;            // all decision variables

  // First index of contact c's wrench in x.
  static constexpr int forceIndex(int c) { return nv + CD * c; }

  // Task frames of the dynamics object: 0 .. NC−1 the contact (sole) frames, NC the torso frame.
  using Dynamics = hqp::model::RobotDynamics<Robot, NC + 1>;
  static constexpr int torso_frame = NC;
};

}  // namespace hqp::tasks
