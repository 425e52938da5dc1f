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
// Two extensions for moving supports (docs/tasks.md, "Moving supports"; both off by default,
// which is the paper's rule exactly):
//   follow_acceleration_cutoff > 0: a following foot also gets the feed-forward acceleration
//     a_F,ref = low-pass(d v_F / dt), so that q̈* (and ∫q̈* dt of eq. 8) carries the motion the
//     support imposes instead of planning the foot to stop;
//   follow_translation: a foot in contact whose ZMP left the safe region keeps its orientation
//     reference (the paper's hold, which stops a tipping foot) but its position, velocity and
//     feed-forward acceleration references follow the foot's translation, so a board that
//     carries the foot away is not fought by the level-2 task;
//   hold_tipping_axis, hold_one_sided: what of the orientation is held (see PlannerParameters).
// One extension beyond the paper for the CoM (docs/tasks.md, "CoM reference on moving supports";
// off by default):
//   com_reference_cutoff > 0: the CoM reference is the midpoint of the foot references after a
//     first-order low-pass at this cutoff (and its velocity the low-passed midpoint's rate), so
//     a board that oscillates one foot does not make the whole body chase the midpoint; a
//     support that moves steadily is still followed, with the filter's lag.
// Allocation-free and exception-free; see docs/tasks.md.

#include <algorithm>
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
  // Hz, cutoff of the first-order low-pass on the finite difference of a foot's measured
  // velocity that feeds a following foot's acceleration reference; 0 = no feed-forward (paper).
  double follow_acceleration_cutoff = 0.0;
  // Cascaded first-order stages of that low-pass (1 or 2). The finite difference turns white
  // velocity noise σ_v into noise of σ_v / dt; one stage passes it with gain ~2π f_c, two roll it
  // off (a third of the noise at 20 Hz, measured in docs/tasks.md).
  int follow_acceleration_order = 1;
  // Soft deadband on the filtered acceleration (linear m/s², angular rad/s²), per component:
  // a_ff = sign(a) max(|a| − d, 0). What encoder noise leaves after the filter is taken off, so a
  // foot on a still support gets no feed-forward (the paper's rule) and a moving one most of it.
  double follow_acceleration_deadband_linear = 0.0;
  double follow_acceleration_deadband_angular = 0.0;
  // A foot whose ZMP left the safe region holds only its orientation; its translation follows.
  bool follow_translation = false;
  // With follow_translation: hold the orientation only about the axis the foot can tip over,
  // the sole edge its ZMP approaches (x edges: pitch, y edges: roll), and follow the rest,
  // yaw always (a foot cannot tip about its normal: holding yaw on a turning support makes it
  // twist on the support).
  bool hold_tipping_axis = false;
  // With hold_tipping_axis: hold that axis only against tipping over the edge the ZMP is at, and
  // follow the foot when it has turned the other way from the held orientation (a support that
  // presses the sole flatter). On still ground the sole cannot turn that way, so this is the
  // hold above; on a tilting support the hold no longer turns the ankle against the board,
  // which pushed the CoP onto the edge that triggered it and kept it there (beyond the paper).
  bool hold_one_sided = false;
  // Hz, low-pass of the feet's midpoint that the CoM reference follows; 0 = the midpoint itself.
  double com_reference_cutoff = 0.0;
  // The linear feed-forward acceleration of a following foot: false = the low-passed finite
  // difference above; true = the state estimator's support acceleration (update()'s
  // support_acceleration argument; the angular part stays the finite difference).
  bool support_acceleration_from_estimator = false;
};

template <int NC>
class TaskPlanner {
 public:
  // dt: the control period (s), for the finite difference of the feet's velocities.
  void configure(const PlannerParameters& p, double total_mass, double dt = 0.001) {
    params_ = p;
    mass_ = total_mass;
    dt_ = dt;
    const double fc = p.follow_acceleration_cutoff;
    alpha_ = (fc > 0.0 && dt > 0.0) ? -std::expm1(-2.0 * kPi * fc * dt) : 0.0;
    const double cc = p.com_reference_cutoff;
    com_alpha_ = (cc > 0.0 && dt > 0.0) ? -std::expm1(-2.0 * kPi * cc * dt) : 0.0;
    reset();
  }

  // Next update re-initialises every reference from the state.
  void reset() {
    initialized_ = false;
    safe_.fill(false);
    have_velocity_.fill(false);
    for (int c = 0; c < NC; ++c) {
      velocity_[c].setZero();
      stage_[c].setZero();
      acceleration_[c].setZero();
      feed_forward_[c].setZero();
    }
  }

  // cop[c]: measured ZMP of foot c in its sole frame (x, y); in_contact[c]: the estimator's flag;
  // support_acceleration[c]: the estimator's world acceleration of what foot c stands on (used
  // with support_acceleration_from_estimator; may be null otherwise).
  template <class Dyn>
  void update(const Dyn& dyn, const std::array<Eigen::Vector2d, NC>& cop,
              const std::array<bool, NC>& in_contact, References<NC>& refs,
              const std::array<Eigen::Vector3d, NC>* support_acceleration = nullptr) noexcept {
    if (!initialized_) initialize(dyn, refs);

    for (int c = 0; c < NC; ++c) {
      const Vector6 v = dyn.velocity(c);
      if (alpha_ > 0.0) {  // a_F ≈ low-pass((v_k − v_{k−1}) / dt); the first tick has no difference
        if (have_velocity_[c]) {
          stage_[c] += alpha_ * ((v - velocity_[c]) / dt_ - stage_[c]);
          acceleration_[c] = params_.follow_acceleration_order >= 2
                                 ? Vector6(acceleration_[c] + alpha_ * (stage_[c] - acceleration_[c]))
                                 : stage_[c];
          feed_forward_[c] = acceleration_[c];
          shrink(feed_forward_[c].template head<3>(), params_.follow_acceleration_deadband_linear);
          shrink(feed_forward_[c].template tail<3>(), params_.follow_acceleration_deadband_angular);
        }
        velocity_[c] = v;
        have_velocity_[c] = true;
        if (params_.support_acceleration_from_estimator && support_acceleration != nullptr)
          feed_forward_[c].template head<3>() = (*support_acceleration)[c];
      }
      safe_[c] = in_contact[c] && insideSafeRegion(cop[c]);
      refs.contact_acceleration[c].setZero();
      if (safe_[c]) {
        refs.contact_pose[c] = dyn.placement(c);
        refs.contact_velocity[c] = v;
        refs.contact_acceleration[c] = feed_forward_[c];
      } else if (params_.follow_translation && in_contact[c]) {
        // Orientation held (previous reference, zero angular velocity); translation followed.
        const auto& X = dyn.placement(c);
        refs.contact_pose[c].translation() = X.translation();
        refs.contact_velocity[c] << v.template head<3>(), Eigen::Vector3d::Zero();
        refs.contact_acceleration[c].template head<3>() = feed_forward_[c].template head<3>();
        if (params_.hold_tipping_axis) {
          // Sole-frame axes: hold x (roll) only near a y edge, y (pitch) only near an x edge.
          Eigen::Vector3d keep(insideBand(cop[c].y(), params_.sole_y_min, params_.sole_y_max) ? 1.0 : 0.0,
                               insideBand(cop[c].x(), params_.sole_x_min, params_.sole_x_max) ? 1.0 : 0.0,
                               1.0);
          const Eigen::Matrix3d R_held = refs.contact_pose[c].linear();
          const Eigen::AngleAxisd d(R_held.transpose() * X.linear());  // held -> measured, held frame
          const Eigen::Vector3d turn = d.angle() * d.axis();
          if (params_.hold_one_sided && cop[c].allFinite()) {  // no ZMP, no edge: hold both
            // Tipping over the edge at ZMP p lifts the sole centre: (−ω × p)_z > 0, i.e. roll
            // ω_x of sign −p_y (side edges), pitch ω_y of sign +p_x (toe, heel).
            const double tip[2] = {cop[c].y() > 0.0 ? -1.0 : 1.0, cop[c].x() > 0.0 ? 1.0 : -1.0};
            for (int k = 0; k < 2; ++k)
              if (keep[k] == 0.0 && turn[k] * tip[k] < 0.0) keep[k] = 1.0;
          }
          const Eigen::Vector3d e = keep.cwiseProduct(turn);
          refs.contact_pose[c].linear() =
              R_held * (e.norm() > 0.0 ? Eigen::AngleAxisd(e.norm(), e / e.norm()).toRotationMatrix()
                                       : Eigen::Matrix3d::Identity());
          const Eigen::Matrix3d& R = X.linear();  // followed angular velocity, sole frame components
          refs.contact_velocity[c].template tail<3>() = R * keep.cwiseProduct(R.transpose() * v.template tail<3>());
        }
      } else {
        refs.contact_velocity[c].setZero();  // hold the previous pose
      }
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
    refs.com_velocity = v / NC;
    if (com_alpha_ > 0.0) {
      // First-order low-pass of the midpoint; the reference velocity is the filter's rate.
      const Eigen::Vector3d step = com_alpha_ * (refs.com - midpoint_);
      midpoint_ += step;
      refs.com = midpoint_;
      refs.com_velocity = step / dt_;
    }
    refs.com.z() += com_height_;
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
  template <class V>
  static void shrink(V&& a, double d) {
    if (!(d > 0.0)) return;
    for (int k = 0; k < 3; ++k) a[k] = std::copysign(std::max(std::abs(a[k]) - d, 0.0), a[k]);
  }

  // The ZMP coordinate inside [lo + safe_margin, hi - safe_margin] (NaN: outside).
  bool insideBand(double z, double lo, double hi) const {
    return z >= lo + params_.safe_margin && z <= hi - params_.safe_margin;
  }

  bool insideSafeRegion(const Eigen::Vector2d& zmp) const {
    return insideBand(zmp.x(), params_.sole_x_min, params_.sole_x_max) &&
           insideBand(zmp.y(), params_.sole_y_min, params_.sole_y_max);
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
    midpoint_.setZero();
    for (int c = 0; c < NC; ++c) midpoint_ += dyn.placement(c).translation() / NC;
    initialized_ = true;
  }

  static constexpr double kPi = 3.14159265358979323846;

  PlannerParameters params_{};
  double mass_ = 0.0;
  double dt_ = 0.001;
  double alpha_ = 0.0;  // low-pass gain per tick, 1 − exp(−2π f_c dt)
  double com_alpha_ = 0.0;  // the same for the CoM reference's midpoint
  Eigen::Vector3d midpoint_ = Eigen::Vector3d::Zero();  // low-passed midpoint of the foot references
  std::array<bool, NC> have_velocity_{};
  // last measured v_F, first filter stage, filtered a_F, a_F after the deadband (fed forward)
  std::array<Vector6, NC> velocity_{}, stage_{}, acceleration_{}, feed_forward_{};
  double com_height_ = 0.0;
  bool initialized_ = false;
  std::array<bool, NC> safe_{};
};

}  // namespace hqp::tasks
