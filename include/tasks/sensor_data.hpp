#pragma once
// What the controller reads from the robot each tick, and what it sends back.
// Conventions: docs/conventions.md (SI units, quaternions w x y z, wrenches
// [force; torque]). Joint order is the model's (Robot::Joints).

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/spatial.hpp"

namespace hqp::tasks {

using Vector6 = hqp::model::Vector6;

template <int NJ, int NC>
struct SensorData {
  double time = 0.0;                       // s
  Eigen::Matrix<double, NJ, 1> q = Eigen::Matrix<double, NJ, 1>::Zero();   // encoders (rad)
  Eigen::Matrix<double, NJ, 1> dq = Eigen::Matrix<double, NJ, 1>::Zero();  // encoders (rad/s)
  Eigen::Quaterniond imu_orientation = Eigen::Quaterniond::Identity();     // R_world_imu
  Eigen::Vector3d imu_gyro = Eigen::Vector3d::Zero();   // angular velocity, imu frame (rad/s)
  Eigen::Vector3d imu_accel = Eigen::Vector3d::Zero();  // specific force R_world_imuᵀ (a − g), imu frame (m/s²)
  // [force; torque] exerted BY the support ON the foot, in the F/T sensor
  // frame, torque about the sensor origin.
  std::array<Vector6, NC> ft = filledZero();

 private:
  static std::array<Vector6, NC> filledZero() noexcept {
    std::array<Vector6, NC> a;
    for (auto& w : a) w.setZero();
    return a;
  }
};

template <int NJ>
struct ActuatorCommand {
  Eigen::Matrix<double, NJ, 1> current = Eigen::Matrix<double, NJ, 1>::Zero();  // i_cmd (A), eq. 5
  // The torque the current asks for: k_t i_cmd, i.e. τ_opt + k_f τ_f + τ_q̇ (eq. 5)
  // after the current clamp (joint_controller.hpp).
  Eigen::Matrix<double, NJ, 1> torque = Eigen::Matrix<double, NJ, 1>::Zero();  // N·m
  bool safe_mode = false;
};

}  // namespace hqp::tasks
