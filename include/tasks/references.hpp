#pragma once
// References<NC>: what the task planner (Section III-A) hands to the tasks every tick.
// All quantities in world coordinates; wrenches [force; moment] about the contact origin.

#include <array>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/spatial.hpp"

namespace hqp::tasks {

using Vector6 = hqp::model::Vector6;

template <int NC>
struct References {
  std::array<Eigen::Isometry3d, NC> contact_pose;      // r_F,ref: contact frame placement (world)
  std::array<Vector6, NC> contact_velocity;            // v_F,ref = [v; ω] (world)
  std::array<Vector6, NC> contact_acceleration;        // feed-forward [a; α] (zero in the paper)
  Eigen::Vector3d com = Eigen::Vector3d::Zero();                  // r_CoM,ref (m)
  Eigen::Vector3d com_velocity = Eigen::Vector3d::Zero();         // v_CoM,ref (m/s)
  Eigen::Vector3d com_acceleration = Eigen::Vector3d::Zero();     // feed-forward (m/s²)
  Eigen::Matrix3d torso_orientation = Eigen::Matrix3d::Identity();  // r_T,ref = R_world_torso
  Eigen::Vector3d torso_angular_velocity = Eigen::Vector3d::Zero();      // rad/s (world)
  Eigen::Vector3d torso_angular_acceleration = Eigen::Vector3d::Zero();  // feed-forward, rad/s²
  std::array<Vector6, NC> contact_force;               // F_ref = [f; m]; the first CD entries are used
  // Measured normal force per contact (N, sole frame; ∞: unknown), written by the controller from
  // the F/T wrench, not by the planner: caps the CoP moment margin so that a foot the plant is
  // lifting is not held down.
  std::array<double, NC> contact_load;

  References() {
    for (int c = 0; c < NC; ++c) {
      contact_pose[c].setIdentity();
      contact_velocity[c].setZero();
      contact_acceleration[c].setZero();
      contact_force[c].setZero();
      contact_load[c] = std::numeric_limits<double>::infinity();
    }
  }
};

}  // namespace hqp::tasks
