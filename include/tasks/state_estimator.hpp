#pragma once
// Floating-base state estimation from the robot's sensors (assumptions, the choice of method
// and its measured accuracy: docs/controller.md, "State estimator"):
// - base orientation from the IMU, with the fixed imu → base rotation of the model; the IMU
//   quaternion must be a unit quaternion to quaternion_tolerance (overflow-safe norm);
// - base angular velocity from the gyro (base frame, docs/conventions.md);
// - joint q, q̇ from the encoders;
// - contact per foot from the F/T normal force in the sole frame, with hysteresis and a
//   confidence (contact_estimator.hpp);
// - base position and linear velocity by one of two methods (EstimatorParameters::method):
//   KinematicInertial (kinematic_inertial_filter.hpp): the accelerometer drives a Kalman
//     filter whose measurements are the feet's forward kinematics and a zero velocity for each
//     foot in contact, weighted by its contact confidence, and only if the foot's world
//     velocity v_c predicted from the IMU passes the gate |v_c|² ≤ γ² P_vv + v_s² (a
//     Mahalanobis test with a floor), agrees with the stillest loaded foot, and shows no motion
//     in its velocity from the accelerometer's integral and the kinematics alone, high-passed
//     (a test the filter's own state cannot bias). A foot on a
//     moving board fails it, so it does not drag the base; while no foot passes, or the feet
//     move against each other with no clear stillest one, the IMU carries the estimate, held
//     by a weak measurement that the loaded feet do not move on average (fallback_velocity). The same velocity gives each loaded foot's
//     support velocity, and a loaded foot faster than moving_velocity is flagged as moving
//     (slip, or a moving support).
//   Stance: every foot in contact is assumed not to move: a foot that touches down has its
//     world position latched, so p_base = p_foot,latched − R_world_base p_base_foot and
//     v_base = −ω_base × p_base_foot − ṗ_base_foot (all foot-relative terms from forward
//     kinematics with the base at the identity); several feet are averaged; without contact
//     the IMU point's world velocity integrates the accelerometer (a = R_world_imu f + g).
// The first update places the world origin under the base with the lowest sole
// at z = 0, unless setBasePosition() was called.
// Wrenches: the F/T wrench (sensor frame, about the sensor origin) is moved to
// the sole frame about the sole origin; CoP = (−m_y / f_z, m_x / f_z).
// No heap, no exceptions: all scratch lives in a model Data member.

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/data.hpp"
#include "model/frames.hpp"
#include "model/kinematics.hpp"
#include "tasks/contact_estimator.hpp"
#include "tasks/kinematic_inertial_filter.hpp"
#include "tasks/sensor_data.hpp"

namespace hqp::tasks {

struct EstimatorParameters {
  double contact_threshold = 30.0;  // N, a foot leaves contact below this sole-frame normal force
  enum class Method { Stance, KinematicInertial };
  Method method = Method::Stance;
  double contact_on = 0.0;          // N, and enters above this (≤ contact_threshold: no hysteresis)
  double contact_full = 0.0;        // N, contact confidence 1 from here (ramp from contact_threshold)
  // KinematicInertial only:
  KinematicInertialNoise noise;
  // A loaded foot is still if |v_c|² ≤ γ² P_vv + v_s² (v_c: its predicted world velocity) and
  // agrees with the stillest loaded foot to relative_velocity_gate (both from u_c low-passed
  // at gate_cutoff).
  double zero_velocity_gate = 3.4;     // γ (χ²₃ 99 %: 3.37)
  double stationary_velocity = 0.05;   // m/s, v_s
  double relative_velocity_gate = 0.05;  // m/s
  double gate_cutoff = 20.0;           // Hz
  double trust_delay = 0.1;            // s, an untrusted foot passes the gate this long first
  // and |high-pass(∫a dt + u_c)| ≤ motion_gate: the foot's velocity change seen by the IMU and the
  // kinematics alone, high-passed at motion_cutoff (a still foot has none).
  double motion_gate = 0.05;           // m/s
  double motion_cutoff = 0.5;          // Hz
  double moving_velocity = 0.1;       // m/s, a loaded foot faster than this is flagged as moving
  double support_acceleration_cutoff = 20.0;  // Hz, low-pass of the support acceleration estimate
  // |‖q_imu‖ − 1| above this is an invalid IMU packet (update() refuses it).
  double quaternion_tolerance = 0.01;
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
      contact_[c].reset();
      foot_world_[c].setZero();
      p_b_sole_[c].setZero();
      wrench_[c].setZero();
      cop_[c].setZero();
      support_velocity_[c].setZero();
      support_acceleration_[c].setZero();
      u_gate_[c].setZero();
      motion_[c].setZero();
      motion_hp_[c].setZero();
      u_last_[c].setZero();
      still_time_[c] = 0.0;
      trust_[c] = 0.0;
    }
  }

  // Sets the world position of the base; feet in contact are re-latched to it.
  void setBasePosition(const Eigen::Vector3d& p) noexcept {
    if (initialized_ && p_.method == EstimatorParameters::Method::KinematicInertial)
      filter_.translate(p - q_.template head<3>());
    q_.template head<3>() = p;
    position_given_ = true;
    for (int c = 0; c < NC; ++c) {
      if (contact_[c].inContact()) foot_world_[c] = p + R_wb_ * p_b_sole_[c];
    }
  }

  // false, and the state untouched, if the frames are invalid or any input is non-finite (or
  // dt < 0, or the IMU quaternion is not a unit quaternion to quaternion_tolerance).
  bool update(const Sensors& s, double dt) noexcept {
    if (!valid_ || !inputFinite(s, dt)) return false;
    // stableNorm: a component of 1e200 must not overflow to inf and be normalized to "upright".
    const double qn = s.imu_orientation.coeffs().stableNorm();
    if (!(std::abs(qn - 1.0) <= p_.quaternion_tolerance)) return false;

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

    // Sole wrenches, contacts and the feet's kinematics relative to the base.
    std::array<bool, NC> was_in_contact;
    std::array<Eigen::Vector3d, NC> p_bs;  // sole origin, base frame
    std::array<Eigen::Vector3d, NC> v_bs;  // its velocity relative to the base, base axes
    const ContactParameters cp{p_.contact_threshold, p_.contact_on, p_.contact_full};
    for (int c = 0; c < NC; ++c) {
      const Eigen::Isometry3d X_bo = hqp::model::framePlacement<Robot>(d_, sole_[c]);
      const Eigen::Isometry3d X_bf = hqp::model::framePlacement<Robot>(d_, ft_[c]);
      const Eigen::Matrix3d R_of = X_bo.linear().transpose() * X_bf.linear();
      const Eigen::Vector3d p_of = X_bo.linear().transpose() * (X_bf.translation() - X_bo.translation());
      Vector6 w;
      w.template head<3>() = R_of * s.ft[c].template head<3>();
      w.template tail<3>() = R_of * s.ft[c].template tail<3>() + p_of.cross(w.template head<3>());
      wrench_[c] = w;
      was_in_contact[c] = initialized_ && contact_[c].inContact();
      contact_[c].update(w[2], cp);
      if (contact_[c].inContact()) {
        cop_[c] << -w[4] / w[2], w[3] / w[2];
      } else {
        cop_[c].setZero();
      }
      p_bs[c] = X_bo.translation();
      v_bs[c] = hqp::model::frameVelocity<Robot>(d_, sole_[c]).template head<3>();
    }

    const Eigen::Vector3d p_bi = X_bi.translation();
    const Eigen::Vector3d v_bi = V_bi.template head<3>();
    Eigen::Vector3d p_wb, v_b;
    if (p_.method == EstimatorParameters::Method::KinematicInertial) {
      fuse(s, dt, quat_wi, R_wb, w_b, p_bi, v_bi, p_bs, v_bs, p_wb, v_b);
    } else {
      stance(s, dt, quat_wi, R_wb, w_b, p_bi, v_bi, p_bs, v_bs, was_in_contact, p_wb, v_b);
    }
    for (int c = 0; c < NC; ++c) p_b_sole_[c] = p_bs[c];

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
  bool inContact(int c) const noexcept { return contact_[c].inContact(); }
  int numContacts() const noexcept {
    int n = 0;
    for (const auto& k : contact_) n += k.inContact() ? 1 : 0;
    return n;
  }
  // Contact confidence in [0, 1] (normal force ramp, contact_estimator.hpp).
  double contactConfidence(int c) const noexcept { return contact_[c].confidence(); }
  // KinematicInertial: a loaded foot that moves in the world (slip or a moving support); the
  // weight it had as a zero-velocity measurement; the world velocity and (low-passed)
  // acceleration of what it stands on (zero when not in contact). Stance: never moving, trust
  // 1 in contact, the loaded foot's estimated velocity, zero acceleration.
  bool footMoving(int c) const noexcept { return contact_[c].moving(); }
  double footTrust(int c) const noexcept { return trust_[c]; }
  const Eigen::Vector3d& supportVelocity(int c) const noexcept { return support_velocity_[c]; }
  const Eigen::Vector3d& supportAcceleration(int c) const noexcept { return support_acceleration_[c]; }
  // KinematicInertial: the accelerometer bias estimate (world axes, m/s²).
  Eigen::Vector3d accelerometerBias() const noexcept { return filter_.bias(); }
  // Measured wrench [f; m] in the sole frame, moment about the sole origin.
  const Vector6& soleWrench(int c) const noexcept { return wrench_[c]; }
  // Measured CoP (ZMP) in the sole frame; (0, 0) when not in contact.
  const Eigen::Vector2d& cop(int c) const noexcept { return cop_[c]; }
  // World position latched at foot c's touch-down (meaningful while in contact).
  // (KinematicInertial: the filter's estimate of the sole's world position.)
  Eigen::Vector3d latchedFootPosition(int c) const noexcept {
    return p_.method == EstimatorParameters::Method::KinematicInertial ? filter_.foot(c) : foot_world_[c];
  }

 private:
  static bool inRange(int k) noexcept { return k >= 0 && k < Robot::nframes; }

  // First update: world origin below the base, lowest (contact) sole at z = 0.
  Eigen::Vector3d initialPosition(const Eigen::Matrix3d& R_wb,
                                  const std::array<Eigen::Vector3d, NC>& p_bs) const noexcept {
    if (position_given_) return q_.template head<3>();
    const int ncontact = numContacts();
    double zmin = 0.0;
    bool first = true;
    for (int c = 0; c < NC; ++c) {
      if (ncontact > 0 && !contact_[c].inContact()) continue;
      const double z = (R_wb * p_bs[c]).z();
      if (first || z < zmin) zmin = z;
      first = false;
    }
    return Eigen::Vector3d(0.0, 0.0, -zmin);
  }

  // The Kalman filter of kinematic_inertial_filter.hpp; p_wb, v_b (base frame) out.
  void fuse(const Sensors& s, double dt, const Eigen::Quaterniond& quat_wi, const Eigen::Matrix3d& R_wb,
            const Eigen::Vector3d& w_b, const Eigen::Vector3d& p_bi, const Eigen::Vector3d& v_bi,
            const std::array<Eigen::Vector3d, NC>& p_bs, const std::array<Eigen::Vector3d, NC>& v_bs,
            Eigen::Vector3d& p_wb, Eigen::Vector3d& v_b) noexcept {
    // u_c: foot c's world velocity relative to the IMU point's.
    std::array<Eigen::Vector3d, NC> u;
    const Eigen::Vector3d v_rel_i = w_b.cross(p_bi) + v_bi;
    for (int c = 0; c < NC; ++c) u[c] = R_wb * (w_b.cross(p_bs[c]) + v_bs[c] - v_rel_i);
    if (!initialized_) {
      // Start at rest unless the feet in contact say otherwise (they stand still at start).
      const Eigen::Vector3d p0 = initialPosition(R_wb, p_bs);
      Eigen::Vector3d v_imu = Eigen::Vector3d::Zero();
      int n = 0;
      for (int c = 0; c < NC; ++c) {
        if (!contact_[c].inContact()) continue;
        v_imu -= u[c];
        ++n;
      }
      if (n > 0) v_imu /= n;
      std::array<Eigen::Vector3d, NC> feet;
      for (int c = 0; c < NC; ++c) feet[c] = p0 + R_wb * p_bs[c];
      filter_.reset(p0 + R_wb * p_bi, v_imu, feet);
      for (int c = 0; c < NC; ++c) {
        u_gate_[c] = u[c];
        motion_[c].setZero();
        motion_hp_[c].setZero();
        u_last_[c] = u[c];
        trust_[c] = contact_[c].confidence();  // standing still at start
        still_time_[c] = 0.0;
      }
    } else {
      const Eigen::Vector3d g(0.0, 0.0, -hqp::model::kGravity);
      const Eigen::Vector3d a_world = quat_wi * s.imu_accel + g;  // before the bias
      const Eigen::Vector3d dv = dt * (a_world - filter_.bias());   // this tick's velocity change
      // Trust from the predicted velocity, before this tick's measurements.
      const Eigen::Vector3d v_pred = filter_.velocity() + dv;
      filter_.predict(a_world, dt, p_.noise);
      const double gate2 = p_.zero_velocity_gate * p_.zero_velocity_gate * filter_.covariance()(1, 1) +
                           p_.stationary_velocity * p_.stationary_velocity;
      // Loaded feet that pass the gate and agree with the stillest loaded foot (relative
      // velocity within the gate of two zero-velocity measurements). A loaded foot that
      // disagrees with the stillest one but is less than twice as fast makes the choice
      // ambiguous: then no foot is used (two boards moving against each other), and the IMU
      // carries the estimate.
      // The tests use u_c low-passed at gate_cutoff (encoder noise would blur them).
      std::array<double, NC> speed;
      int best = -1;
      // Independent of the filter's state (so a trusted foot cannot vouch for itself): the
      // foot's world velocity from the accelerometer's integral and the kinematics, high-passed
      // at motion_cutoff (then low-passed like u_c); a still foot keeps it near zero, a board
      // that accelerates does not.
      const double ag = lowPassGain(p_.gate_cutoff, dt);
      const double hp = 1.0 - lowPassGain(p_.motion_cutoff, dt);
      for (int c = 0; c < NC; ++c) {
        u_gate_[c] += ag * (u[c] - u_gate_[c]);
        motion_hp_[c] = hp * (motion_hp_[c] + dv + u[c] - u_last_[c]);
        u_last_[c] = u[c];
        motion_[c] += ag * (motion_hp_[c] - motion_[c]);
        speed[c] = (v_pred + u_gate_[c]).norm();
        if (contact_[c].confidence() > 0.0 && (best < 0 || speed[c] < speed[best])) best = c;
      }
      const double rel2 = p_.relative_velocity_gate * p_.relative_velocity_gate;
      // A foot that was not trusted must pass for trust_delay first: a board passing through
      // zero velocity at a reversal is not a still support.
      // Without a trusted foot the filter's velocity rests on the fallback (the feet's mean), so
      // the absolute test would reject a still foot beside a moving one: only the motion and
      // agreement tests decide then.
      bool anchored = false;
      for (int c = 0; c < NC; ++c) anchored = anchored || trust_[c] > 0.0;
      const double gate_abs2 = anchored ? gate2 : std::numeric_limits<double>::infinity();
      bool ambiguous = best < 0 || speed[best] * speed[best] > gate_abs2;
      std::array<bool, NC> still{};
      for (int c = 0; c < NC; ++c) {
        if (best < 0 || !(contact_[c].confidence() > 0.0)) continue;
        if ((u_gate_[c] - u_gate_[best]).squaredNorm() <= rel2) {
          still[c] = speed[c] * speed[c] <= gate_abs2 && motion_[c].norm() <= p_.motion_gate;
        } else if (speed[c] < 2.0 * speed[best]) {
          ambiguous = true;
        }
      }
      for (int c = 0; c < NC; ++c) {
        const bool pass = still[c] && !ambiguous;
        still_time_[c] = pass ? still_time_[c] + dt : 0.0;
        const bool keep = pass && (trust_[c] > 0.0 || still_time_[c] >= p_.trust_delay);
        trust_[c] = keep ? contact_[c].confidence() : 0.0;
      }
      filter_.addFootNoise(dt, trust_, p_.noise);
      for (int c = 0; c < NC; ++c) filter_.measureFootPosition(c, R_wb * (p_bs[c] - p_bi), p_.noise);
      bool any = false;
      for (int c = 0; c < NC; ++c) {
        if (trust_[c] > 1e-3) {
          filter_.measureZeroVelocity(u[c], trust_[c], p_.noise);
          any = true;
        }
      }
      // No still foot (two boards, a seesaw): the loaded feet do not move on average, as a
      // weak measurement, so that the IMU's integration cannot drift away.
      double wsum = 0.0;
      Eigen::Vector3d umean = Eigen::Vector3d::Zero();
      for (int c = 0; c < NC; ++c) {
        wsum += contact_[c].confidence();
        umean += contact_[c].confidence() * u[c];
      }
      if (!any && wsum > 0.0 && p_.noise.fallback_velocity > 0.0)
        filter_.measureVelocity(-umean / wsum, p_.noise.fallback_velocity * p_.noise.fallback_velocity);
    }
    const Eigen::Vector3d v_imu = filter_.velocity();
    p_wb = filter_.position() - R_wb * p_bi;
    v_b = R_wb.transpose() * v_imu - v_rel_i;
    v_imu_world_ = v_imu;
    // Supports: a loaded foot's world velocity is its support's (a rigid, non-slipping contact).
    const double alpha = lowPassGain(p_.support_acceleration_cutoff, dt);
    for (int c = 0; c < NC; ++c) {
      const Eigen::Vector3d vf = v_imu + u[c];
      const bool loaded = contact_[c].inContact();
      contact_[c].setMoving(loaded && vf.norm() > p_.moving_velocity);
      const Eigen::Vector3d vs_new = loaded ? vf : Eigen::Vector3d::Zero();
      if (initialized_ && dt > 0.0) {
        support_acceleration_[c] += alpha * ((vs_new - support_velocity_[c]) / dt - support_acceleration_[c]);
      }
      support_velocity_[c] = vs_new;
    }
  }

  // The stance-foot estimator (the feet in contact stand still); p_wb, v_b (base frame) out.
  void stance(const Sensors& s, double dt, const Eigen::Quaterniond& quat_wi, const Eigen::Matrix3d& R_wb,
              const Eigen::Vector3d& w_b, const Eigen::Vector3d& p_bi, const Eigen::Vector3d& v_bi,
              const std::array<Eigen::Vector3d, NC>& p_bs, const std::array<Eigen::Vector3d, NC>& v_bs,
              const std::array<bool, NC>& was_in_contact, Eigen::Vector3d& p_wb, Eigen::Vector3d& v_b) noexcept {
    int ncontact = 0;
    Eigen::Vector3d v_sum = Eigen::Vector3d::Zero();
    for (int c = 0; c < NC; ++c) {
      trust_[c] = contact_[c].inContact() ? 1.0 : 0.0;
      if (!contact_[c].inContact()) continue;
      v_sum += -w_b.cross(p_bs[c]) - v_bs[c];  // sole at rest in the world
      ++ncontact;
    }
    // Base linear velocity (base frame) and the IMU point's world velocity.
    if (ncontact > 0) {
      v_b = v_sum / ncontact;
      v_imu_world_ = R_wb * (v_b + w_b.cross(p_bi) + v_bi);
    } else {
      const Eigen::Vector3d g(0.0, 0.0, -hqp::model::kGravity);
      v_imu_world_ += (quat_wi * s.imu_accel + g) * dt;
      v_b = R_wb.transpose() * v_imu_world_ - w_b.cross(p_bi) - v_bi;
    }
    // Base position: feet that stay in contact, else integration.
    p_wb.setZero();
    int nstance = 0;
    for (int c = 0; c < NC; ++c) {
      if (contact_[c].inContact() && was_in_contact[c]) {
        p_wb += foot_world_[c] - R_wb * p_bs[c];
        ++nstance;
      }
    }
    if (nstance > 0) {
      p_wb /= nstance;
    } else if (initialized_) {
      p_wb = q_.template head<3>() + R_wb * v_b * dt;
    } else {
      p_wb = initialPosition(R_wb, p_bs);
    }
    // Touch-down: latch the foot where the current estimate puts it. The support velocity is
    // the loaded foot's estimated world velocity (zero by assumption unless the feet disagree).
    for (int c = 0; c < NC; ++c) {
      if (contact_[c].inContact() && !was_in_contact[c]) foot_world_[c] = p_wb + R_wb * p_bs[c];
      support_velocity_[c] = contact_[c].inContact()
                                 ? Eigen::Vector3d(R_wb * (v_b + w_b.cross(p_bs[c]) + v_bs[c]))
                                 : Eigen::Vector3d::Zero();
    }
  }

  static constexpr double kPi = 3.14159265358979323846;
  // Gain per tick of a first-order low-pass at fc (Hz); 1 (no filter) for fc ≤ 0.
  static double lowPassGain(double fc, double dt) noexcept {
    return (fc > 0.0 && dt > 0.0) ? -std::expm1(-2.0 * kPi * fc * dt) : 1.0;
  }

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
  std::array<ContactEstimator, NC> contact_{};
  KinematicInertialFilter<NC> filter_;
  std::array<double, NC> trust_{};                     // weight of each foot's zero velocity
  std::array<Eigen::Vector3d, NC> u_gate_;             // low-passed u_c for the gate (world)
  std::array<double, NC> still_time_{};                // s, time a foot has passed the gate
  std::array<Eigen::Vector3d, NC> motion_hp_, motion_;  // high-passed IMU + kinematic foot velocity, low-passed
  std::array<Eigen::Vector3d, NC> u_last_;             // u_c of the previous tick
  std::array<Eigen::Vector3d, NC> support_velocity_;   // world (m/s)
  std::array<Eigen::Vector3d, NC> support_acceleration_;  // world (m/s²), low-passed
  std::array<Eigen::Vector3d, NC> foot_world_;  // latched sole positions (world)
  std::array<Eigen::Vector3d, NC> p_b_sole_;    // last sole positions in the base frame
  std::array<Vector6, NC> wrench_;
  std::array<Eigen::Vector2d, NC> cop_;
};

}  // namespace hqp::tasks
