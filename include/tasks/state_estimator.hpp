#pragma once
// Floating-base state estimation from the robot's sensors (issue 4; assumptions
// and limits in docs/controller.md, "State estimator"):
// - base orientation from the IMU, with the fixed imu → base rotation of the model;
// - base angular velocity from the gyro (base frame, docs/conventions.md);
// - joint q, q̇ from the encoders;
// - contact c when the F/T normal force, in the sole frame, exceeds contact_threshold;
// - base position and linear velocity from the stance feet: a foot that touches
//   down has its world position latched; while it stays in contact it is assumed
//   not to move, so p_base = p_foot,latched − R_world_base p_base_foot and
//   v_base = −ω_base × p_base_foot − ṗ_base_foot (all foot-relative terms from
//   forward kinematics with the base at the identity); with several feet in
//   contact the estimates are averaged;
// - without contact, the IMU point's world velocity integrates the accelerometer
//   (a = R_world_imu f + g) and the base position integrates the base velocity.
// The first update places the world origin under the base with the lowest sole
// at z = 0, unless setBasePosition() was called.
// Wrenches: the F/T wrench (sensor frame, about the sensor origin) is moved to
// the sole frame about the sole origin; CoP = (−m_y / f_z, m_x / f_z).
// No heap, no exceptions: all scratch lives in a model Data member.

#include <array>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/data.hpp"
#include "model/frames.hpp"
#include "model/kinematics.hpp"
#include "tasks/sensor_data.hpp"

namespace hqp::tasks {

struct EstimatorParameters {
  double contact_threshold = 30.0;  // N, normal force in the sole frame above which a foot is in contact
};

template <class Robot, int NC>
class StateEstimator {
 public:
  static_assert(Robot::floating_base, "the estimator reconstructs a floating base");
  static constexpr int nq = Robot::nq, nv = Robot::nv, nj = Robot::nj;
  using VectorQ = Eigen::Matrix<double, nq, 1>;
  using VectorV = Eigen::Matrix<double, nv, 1>;
  using Sensors = SensorData<nj, NC>;

  // Frames by index into Robot::frames. valid() is false if one is out of range.
  StateEstimator(const std::array<int, NC>& sole_frames, const std::array<int, NC>& ft_frames,
                 int imu_frame) noexcept
      : sole_(sole_frames), ft_(ft_frames), imu_(imu_frame) {
    valid_ = inRange(imu_);
    for (int c = 0; c < NC; ++c) valid_ = valid_ && inRange(sole_[c]) && inRange(ft_[c]);
    reset();
  }

  bool valid() const noexcept { return valid_; }
  void configure(const EstimatorParameters& p) { p_ = p; }
  const EstimatorParameters& parameters() const noexcept { return p_; }

  // Forget contacts, latches and the base position: the next update re-initialises.
  void reset() noexcept {
    q_.setZero();
    q_[3] = 1.0;
    v_.setZero();
    v_imu_world_.setZero();
    R_wb_.setIdentity();
    initialized_ = false;
    position_given_ = false;
    for (int c = 0; c < NC; ++c) {
      contact_[c] = false;
      foot_world_[c].setZero();
      p_b_sole_[c].setZero();
      wrench_[c].setZero();
      cop_[c].setZero();
    }
  }

  // Sets the world position of the base; feet in contact are re-latched to it.
  void setBasePosition(const Eigen::Vector3d& p) noexcept {
    q_.template head<3>() = p;
    position_given_ = true;
    for (int c = 0; c < NC; ++c) {
      if (contact_[c]) foot_world_[c] = p + R_wb_ * p_b_sole_[c];
    }
  }

  // false, and the state untouched, if the frames are invalid or any input is
  // non-finite (or dt < 0, or a zero quaternion).
  bool update(const Sensors& s, double dt) noexcept {
    if (!valid_ || !inputFinite(s, dt)) return false;
    const double qn = s.imu_orientation.norm();
    if (!(qn > 1e-6)) return false;

    // Kinematics relative to the base: base at the origin, identity, at rest.
    VectorQ qr = VectorQ::Zero();
    VectorV vr = VectorV::Zero();
    qr[3] = 1.0;
    qr.template tail<nj>() = s.q;
    vr.template tail<nj>() = s.dq;
    hqp::model::forwardKinematics<Robot>(d_, qr, vr);

    // Orientation and angular velocity from the IMU.
    const Eigen::Isometry3d X_bi = hqp::model::framePlacement<Robot>(d_, imu_);
    const Vector6 V_bi = hqp::model::frameVelocity<Robot>(d_, imu_);  // relative, base axes
    const Eigen::Quaterniond quat_wi(s.imu_orientation.coeffs() / qn);
    const Eigen::Quaterniond quat_bi(X_bi.linear());
    Eigen::Quaterniond quat_wb = quat_wi * quat_bi.conjugate();
    quat_wb.normalize();
    const Eigen::Matrix3d R_wb = quat_wb.toRotationMatrix();
    const Eigen::Vector3d w_b = X_bi.linear() * s.imu_gyro - V_bi.template tail<3>();

    // Sole wrenches, contacts and stance-foot kinematics.
    std::array<bool, NC> contact;
    std::array<Eigen::Vector3d, NC> p_bs;  // sole origin, base frame
    std::array<Eigen::Vector3d, NC> v_bs;  // its velocity relative to the base, base axes
    int ncontact = 0;
    Eigen::Vector3d v_sum = Eigen::Vector3d::Zero();
    for (int c = 0; c < NC; ++c) {
      const Eigen::Isometry3d X_bo = hqp::model::framePlacement<Robot>(d_, sole_[c]);
      const Eigen::Isometry3d X_bf = hqp::model::framePlacement<Robot>(d_, ft_[c]);
      const Eigen::Matrix3d R_of = X_bo.linear().transpose() * X_bf.linear();
      const Eigen::Vector3d p_of = X_bo.linear().transpose() * (X_bf.translation() - X_bo.translation());
      Vector6 w;
      w.template head<3>() = R_of * s.ft[c].template head<3>();
      w.template tail<3>() = R_of * s.ft[c].template tail<3>() + p_of.cross(w.template head<3>());
      wrench_[c] = w;
      contact[c] = w[2] > p_.contact_threshold;
      if (contact[c]) {
        cop_[c] << -w[4] / w[2], w[3] / w[2];
      } else {
        cop_[c].setZero();
      }
      p_bs[c] = X_bo.translation();
      v_bs[c] = hqp::model::frameVelocity<Robot>(d_, sole_[c]).template head<3>();
      if (contact[c]) {
        v_sum += -w_b.cross(p_bs[c]) - v_bs[c];  // sole at rest in the world
        ++ncontact;
      }
    }

    // Base linear velocity (base frame) and the IMU point's world velocity.
    const Eigen::Vector3d p_bi = X_bi.translation();
    const Eigen::Vector3d v_bi = V_bi.template head<3>();
    Eigen::Vector3d v_b;
    if (ncontact > 0) {
      v_b = v_sum / ncontact;
      v_imu_world_ = R_wb * (v_b + w_b.cross(p_bi) + v_bi);
    } else {
      const Eigen::Vector3d g(0.0, 0.0, -hqp::model::kGravity);
      v_imu_world_ += (quat_wi * s.imu_accel + g) * dt;
      v_b = R_wb.transpose() * v_imu_world_ - w_b.cross(p_bi) - v_bi;
    }

    // Base position: feet that stay in contact, else integration.
    Eigen::Vector3d p_wb = Eigen::Vector3d::Zero();
    int nstance = 0;
    if (initialized_) {
      for (int c = 0; c < NC; ++c) {
        if (contact[c] && contact_[c]) {
          p_wb += foot_world_[c] - R_wb * p_bs[c];
          ++nstance;
        }
      }
    }
    if (nstance > 0) {
      p_wb /= nstance;
    } else if (initialized_) {
      p_wb = q_.template head<3>() + R_wb * v_b * dt;
    } else if (position_given_) {
      p_wb = q_.template head<3>();
    } else {
      // First update: world origin below the base, lowest (contact) sole at z = 0.
      double zmin = 0.0;
      bool first = true;
      for (int c = 0; c < NC; ++c) {
        if (ncontact > 0 && !contact[c]) continue;
        const double z = (R_wb * p_bs[c]).z();
        if (first || z < zmin) zmin = z;
        first = false;
      }
      p_wb << 0.0, 0.0, -zmin;
    }
    // Touch-down: latch the foot where the current estimate puts it.
    for (int c = 0; c < NC; ++c) {
      const bool stays = initialized_ && contact_[c];
      if (contact[c] && !stays) foot_world_[c] = p_wb + R_wb * p_bs[c];
      contact_[c] = contact[c];
      p_b_sole_[c] = p_bs[c];
    }

    q_.template head<3>() = p_wb;
    q_[3] = quat_wb.w();
    q_[4] = quat_wb.x();
    q_[5] = quat_wb.y();
    q_[6] = quat_wb.z();
    q_.template tail<nj>() = s.q;
    v_.template head<3>() = v_b;
    v_.template segment<3>(3) = w_b;
    v_.template tail<nj>() = s.dq;
    R_wb_ = R_wb;
    initialized_ = true;
    return true;
  }

  const VectorQ& q() const noexcept { return q_; }
  const VectorV& v() const noexcept { return v_; }
  bool inContact(int c) const noexcept { return contact_[c]; }
  int numContacts() const noexcept {
    int n = 0;
    for (bool b : contact_) n += b ? 1 : 0;
    return n;
  }
  // Measured wrench [f; m] in the sole frame, moment about the sole origin.
  const Vector6& soleWrench(int c) const noexcept { return wrench_[c]; }
  // Measured CoP (ZMP) in the sole frame; (0, 0) when not in contact.
  const Eigen::Vector2d& cop(int c) const noexcept { return cop_[c]; }
  // World position latched at foot c's touch-down (meaningful while in contact).
  const Eigen::Vector3d& latchedFootPosition(int c) const noexcept { return foot_world_[c]; }

 private:
  static bool inRange(int k) noexcept { return k >= 0 && k < Robot::nframes; }

  static bool inputFinite(const Sensors& s, double dt) noexcept {
    bool ok = std::isfinite(dt) && dt >= 0.0 && s.q.allFinite() && s.dq.allFinite() &&
              s.imu_orientation.coeffs().allFinite() && s.imu_gyro.allFinite() &&
              s.imu_accel.allFinite();
    for (int c = 0; c < NC; ++c) ok = ok && s.ft[c].allFinite();
    return ok;
  }

  std::array<int, NC> sole_;
  std::array<int, NC> ft_;
  int imu_;
  bool valid_ = false;
  EstimatorParameters p_{};
  hqp::model::Data<Robot> d_;

  VectorQ q_;
  VectorV v_;
  Eigen::Matrix3d R_wb_;
  Eigen::Vector3d v_imu_world_;  // world velocity of the IMU origin (integrated without contact)
  bool initialized_ = false;
  bool position_given_ = false;
  std::array<bool, NC> contact_{};
  std::array<Eigen::Vector3d, NC> foot_world_;  // latched sole positions (world)
  std::array<Eigen::Vector3d, NC> p_b_sole_;    // last sole positions in the base frame
  std::array<Vector6, NC> wrench_;
  std::array<Eigen::Vector2d, NC> cop_;
};

}  // namespace hqp::tasks
