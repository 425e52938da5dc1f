#pragma once
// TaskPlanner: the online task planner of Section III-A of the paper.
//   Foot rule: foot c in contact with its measured ZMP inside the safe region (the sole
//   rectangle shrunk by safe_margin on every side) → r_F,ref = r_F, v_F,ref = v_F; otherwise
//   the previous pose reference is held with zero velocity.
//   CoM: r_CoM,ref(x, y) = mean of the foot references, r_CoM,ref(z) = mean foot z + C,
//   v_CoM,ref = mean of the foot reference velocities (linear part).
//   Torso: upright (r_T,ref = 0 in the paper), turned to the mean heading of the feet so that
//   a robot standing turned in the world is not asked to yaw; zero angular velocity.
//   Forces: F_ref = [0, 0, m g / NC, 0, 0, 0] per contact.
// Allocation-free and exception-free; see docs/tasks.md.

#include <array>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/data.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

struct PlannerParameters {
  double safe_margin = 0.02;  // m, the safe region is the sole rectangle shrunk by this
  // C (m): CoM height above the mean foot reference height. ≤ 0: measured from the state at
  // the first update (the stand pose the robot is started in).
  double com_height = 0.0;
  // Sole rectangle in the sole frame (m): Walker3's 0.22 × 0.10 sole, centred on the sole frame.
  double sole_x_min = -0.11, sole_x_max = 0.11, sole_y_min = -0.05, sole_y_max = 0.05;
  // Yaw of the torso frame relative to the feet's heading when the robot stands straight
  // (0 for Walker3's imu frame; π/2 for the quadruped's imu frame).
  double torso_yaw_offset = 0.0;
};

template <int NC>
class TaskPlanner {
 public:
  void configure(const PlannerParameters& p, double total_mass) {
    params_ = p;
    mass_ = total_mass;
    reset();
  }

  // Next update re-initialises every reference from the state.
  void reset() {
    initialized_ = false;
    safe_.fill(false);
  }

  // cop[c]: measured ZMP of foot c in its sole frame (x, y); in_contact[c]: the estimator's flag.
  template <class Dyn>
  void update(const Dyn& dyn, const std::array<Eigen::Vector2d, NC>& cop,
              const std::array<bool, NC>& in_contact, References<NC>& refs) noexcept {
    if (!initialized_) initialize(dyn, refs);

    for (int c = 0; c < NC; ++c) {
      safe_[c] = in_contact[c] && insideSafeRegion(cop[c]);
      if (safe_[c]) {
        refs.contact_pose[c] = dyn.placement(c);
        refs.contact_velocity[c] = dyn.velocity(c);
      } else {
        refs.contact_velocity[c].setZero();  // hold the previous pose
      }
      refs.contact_acceleration[c].setZero();
    }

    // CoM: midpoint of the feet plus C, mean foot velocity.
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
    Eigen::Vector2d heading = Eigen::Vector2d::Zero();
    for (int c = 0; c < NC; ++c) {
      p += refs.contact_pose[c].translation();
      v += refs.contact_velocity[c].template head<3>();
      const Eigen::Matrix3d& R = refs.contact_pose[c].linear();
      heading += Eigen::Vector2d(R(0, 0), R(1, 0));  // horizontal projection of the foot's x axis
    }
    refs.com = p / NC;
    refs.com.z() += com_height_;
    refs.com_velocity = v / NC;
    refs.com_acceleration.setZero();

    // Torso: upright, at the feet's mean heading (+ the frame's offset); at rest.
    const double yaw =
        (heading.squaredNorm() > 1e-12 ? std::atan2(heading.y(), heading.x()) : 0.0) +
        params_.torso_yaw_offset;
    refs.torso_orientation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    refs.torso_angular_velocity.setZero();
    refs.torso_angular_acceleration.setZero();

    // Forces: the weight shared equally.
    for (int c = 0; c < NC; ++c) {
      refs.contact_force[c].setZero();
      refs.contact_force[c](2) = mass_ * hqp::model::kGravity / NC;
    }
  }

  // Whether the follow rule fired for foot c at the last update.
  bool inSafeRegion(int c) const { return safe_[c]; }
  // C in use (configured, or measured at the first update).
  double comHeight() const { return com_height_; }
  const PlannerParameters& parameters() const { return params_; }

 private:
  bool insideSafeRegion(const Eigen::Vector2d& zmp) const {
    const double m = params_.safe_margin;
    // A NaN ZMP compares false and so is outside.
    return zmp.x() >= params_.sole_x_min + m && zmp.x() <= params_.sole_x_max - m &&
           zmp.y() >= params_.sole_y_min + m && zmp.y() <= params_.sole_y_max - m;
  }

  template <class Dyn>
  void initialize(const Dyn& dyn, References<NC>& refs) {
    double z = 0.0;
    for (int c = 0; c < NC; ++c) {
      refs.contact_pose[c] = dyn.placement(c);
      refs.contact_velocity[c].setZero();
      z += dyn.placement(c).translation().z();
    }
    com_height_ = params_.com_height > 0.0 ? params_.com_height : dyn.com().z() - z / NC;
    initialized_ = true;
  }

  PlannerParameters params_{};
  double mass_ = 0.0;
  double com_height_ = 0.0;
  bool initialized_ = false;
  std::array<bool, NC> safe_{};
};

}  // namespace hqp::tasks
