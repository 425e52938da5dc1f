#pragma once
// A Walker3 standing state whose CoM is exactly above the middle of the sole centres, and the
// sensor readings such a robot at rest produces (for tests and benchmarks of the controller).
// Built with the model layer only (checked against MuJoCo in tests/mujoco), never with the
// controller under test.

#include <Eigen/Geometry>

#include <array>

#include "model/configuration.hpp"
#include "model/robot_dynamics.hpp"
#include "tasks/sensor_data.hpp"
#include "walker3_model.hpp"

namespace hqp::testing {

struct Walker3Standing {
  using Robot = walker3::Robot;
  using Dyn = hqp::model::RobotDynamics<Robot, 5>;  // l_sole, r_sole, imu, l_ft, r_ft
  Eigen::Matrix<double, Robot::nq, 1> q;
  Eigen::Matrix<double, Robot::nv, 1> v;
  double com_height = 0.0;    // CoM height above the soles (the planner's C for this pose)
  double ankle_shift = 0.0;   // δ added to hip pitch and subtracted from ankle pitch
};

inline std::array<int, 5> walker3StandingFrames() {
  using R = walker3::Robot;
  return {R::Frames::l_sole, R::Frames::r_sole, R::Frames::imu, R::Frames::l_ft_sensor,
          R::Frames::r_ft_sensor};
}

// Crouch of robots/walker3/README.md (hip −0.3, knee 0.6, ankle −0.3) with hip + δ, ankle − δ
// (feet stay parallel to the torso), δ found by bisection so that the CoM lies above the
// midpoint of the sole centres; base upright, soles on z = 0; zero velocity.
inline Walker3Standing walker3Standing() {
  using R = walker3::Robot;
  Walker3Standing s;
  auto dyn = Walker3Standing::Dyn(walker3StandingFrames());
  auto pose = [&](double d) {
    auto q = hqp::model::neutralConfiguration<R>();
    const int j[2][3] = {{R::Joints::l_hip_pitch, R::Joints::l_knee, R::Joints::l_ankle_pitch},
                         {R::Joints::r_hip_pitch, R::Joints::r_knee, R::Joints::r_ankle_pitch}};
    for (const auto& leg : j) {
      q(7 + leg[0]) = -0.3 + d;
      q(7 + leg[1]) = 0.6;
      q(7 + leg[2]) = -0.3 - d;
    }
    s.v.setZero();
    dyn.calcWbcDependence(q, s.v);
    q(2) -= 0.5 * (dyn.placement(0).translation().z() + dyn.placement(1).translation().z());
    dyn.calcWbcDependence(q, s.v);
    return q;
  };
  auto offset = [&](double d) {
    pose(d);
    return dyn.com().x() -
           0.5 * (dyn.placement(0).translation().x() + dyn.placement(1).translation().x());
  };
  double lo = -0.3, hi = 0.3;
  const bool increasing = offset(hi) > offset(lo);
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    if ((offset(mid) > 0.0) == increasing) hi = mid;
    else lo = mid;
  }
  s.ankle_shift = 0.5 * (lo + hi);
  s.q = pose(s.ankle_shift);
  s.com_height = dyn.com().z();
  return s;
}

// What the sensors of a robot at rest in `s` read when each sole carries `fz[c]` newtons
// straight up, applied at the sole point `cop[c]` (sole frame, m).
inline hqp::tasks::SensorData<12, 2> walker3RestingSensors(const Walker3Standing& s,
                                                          const std::array<double, 2>& fz,
                                                          const std::array<Eigen::Vector2d, 2>& cop) {
  using R = walker3::Robot;
  auto dyn = Walker3Standing::Dyn(walker3StandingFrames());
  dyn.calcWbcDependence(s.q, s.v);
  hqp::tasks::SensorData<12, 2> out;
  out.time = 0.0;
  out.q = s.q.tail<R::nj>();
  out.dq.setZero();
  const Eigen::Matrix3d R_imu = dyn.placement(2).linear();
  out.imu_orientation = Eigen::Quaterniond(R_imu);
  out.imu_gyro.setZero();
  out.imu_accel = R_imu.transpose() * Eigen::Vector3d(0, 0, 9.81);  // specific force at rest
  for (int c = 0; c < 2; ++c) {
    const Eigen::Isometry3d& sole = dyn.placement(c);
    const Eigen::Isometry3d& sensor = dyn.placement(3 + c);
    const Eigen::Vector3d f = sole.linear() * Eigen::Vector3d(0, 0, fz[c]);
    const Eigen::Vector3d p = sole * Eigen::Vector3d(cop[c].x(), cop[c].y(), 0.0);
    const Eigen::Vector3d m = (p - sensor.translation()).cross(f);
    out.ft[c].head<3>() = sensor.linear().transpose() * f;
    out.ft[c].tail<3>() = sensor.linear().transpose() * m;
  }
  return out;
}

}  // namespace hqp::testing
