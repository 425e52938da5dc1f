#pragma once
// KinematicInertialFilter: a linear Kalman filter for the floating base's translation that
// fuses the IMU (process model) with the leg kinematics (measurements), after Bloesch et al.
// (2013) and Rotella et al. (2014), with the orientation taken from the IMU as known (so the
// model is linear) and the feet weighted by how much they are trusted to stand still.
// Choice of method and the measured comparison: docs/controller.md, "State estimator".
//
// Per world axis the state is s = [p, v, b, f_1 … f_NC]:
//   p   world position of the IMU point,       v its world velocity,
//   b   accelerometer bias (world axes),       f_c world position of sole c.
// Process (accelerometer a = R_wi f_meas + g, bias as a random walk, feet as random walks):
//   p⁺ = p + v dt + ½ (a − b) dt²,  v⁺ = v + (a − b) dt,  b⁺ = b,  f_c⁺ = f_c.
// Measurements, every tick:
//   f_c − p = R r_c      (forward kinematics, for every foot, in contact or not)
//   v = −u_c             (zero velocity of foot c, with variance σ_zv² / w_c, only if w_c > 0)
// where u_c is the foot's velocity relative to the IMU point (world axes) and w_c ∈ [0, 1] the
// trust in the foot (contact confidence × stationarity). A trusted foot's position is a slow
// random walk (it anchors the base); an untrusted one is free (it follows the kinematics).
// With isotropic noises the three axes share one (3 + NC)² covariance: a 5 × 5 matrix for two
// feet, a few hundred flops per tick. No heap, no exceptions.

#include <array>
#include <cmath>

#include <Eigen/Core>

namespace hqp::tasks {

struct KinematicInertialNoise {
  double accel = 0.1;             // m/s²/√Hz, accelerometer and attitude-error noise density
  double bias = 1e-3;             // m/s³/√Hz, accelerometer bias random walk
  double foot_stance = 1e-3;      // m/√s, random walk of a trusted foot
  double foot_swing = 10.0;       // m/√s, random walk of an untrusted foot
  double kinematic_position = 2e-3;  // m, forward-kinematics position noise
  double zero_velocity = 0.03;    // m/s, zero-velocity noise of a fully trusted foot
  // m/s, noise of the fallback measurement "the loaded feet do not move on average", used
  // while no foot is trusted (a complementary filter's low-frequency path, ~0.5 Hz at 1 kHz)
  double fallback_velocity = 1.0;
};

template <int NC>
class KinematicInertialFilter {
 public:
  static constexpr int N = 3 + NC;  // states per axis
  using Matrix = Eigen::Matrix<double, N, N>;
  using States = Eigen::Matrix<double, N, 3>;  // one column per world axis
  using Row = Eigen::Matrix<double, 1, N>;

  // p: IMU point, v: its velocity, feet: sole positions (world).
  void reset(const Eigen::Vector3d& p, const Eigen::Vector3d& v,
             const std::array<Eigen::Vector3d, NC>& feet) noexcept {
    s_.setZero();
    s_.row(0) = p.transpose();
    s_.row(1) = v.transpose();
    for (int c = 0; c < NC; ++c) s_.row(3 + c) = feet[c].transpose();
    P_.setZero();
    P_(0, 0) = 1e-6;
    P_(1, 1) = 0.1 * 0.1;
    P_(2, 2) = 0.1 * 0.1;
    for (int c = 0; c < NC; ++c) P_(3 + c, 3 + c) = 1e-6;
  }

  // Moves the whole estimate by d (a new world origin): position and feet.
  void translate(const Eigen::Vector3d& d) noexcept {
    s_.row(0) += d.transpose();
    for (int c = 0; c < NC; ++c) s_.row(3 + c) += d.transpose();
  }

  // a: the accelerometer's world acceleration R_wi f + g (before the bias). The feet's own
  // process noise comes after, from their trust (addFootNoise).
  void predict(const Eigen::Vector3d& a, double dt, const KinematicInertialNoise& n) noexcept {
    const Eigen::RowVector3d ab = a.transpose() - s_.row(2);
    s_.row(0) += dt * s_.row(1) + (0.5 * dt * dt) * ab;
    s_.row(1) += dt * ab;
    // P⁺ = F P Fᵀ + Q with F = I except p ← p + dt v − ½dt² b, v ← v − dt b.
    const double h = 0.5 * dt * dt;
    P_.row(0) += dt * P_.row(1) - h * P_.row(2);
    P_.row(1) -= dt * P_.row(2);
    P_.col(0) += dt * P_.col(1) - h * P_.col(2);
    P_.col(1) -= dt * P_.col(2);
    const double qa = n.accel * n.accel;
    P_(0, 0) += qa * dt * dt * dt / 3.0;
    P_(0, 1) += qa * dt * dt / 2.0;
    P_(1, 0) += qa * dt * dt / 2.0;
    P_(1, 1) += qa * dt;
    P_(2, 2) += n.bias * n.bias * dt;
  }

  // Random walk of each foot over dt: slow if trusted (w_c = 1), free if not (w_c = 0).
  void addFootNoise(double dt, const std::array<double, NC>& trust, const KinematicInertialNoise& n) noexcept {
    for (int c = 0; c < NC; ++c) {
      const double w = trust[c];
      const double sf = w * n.foot_stance + (1.0 - w) * n.foot_swing;
      P_(3 + c, 3 + c) += sf * sf * dt;
    }
  }

  // Forward kinematics of foot c: r = f_c − p (world axes).
  void measureFootPosition(int c, const Eigen::Vector3d& r, const KinematicInertialNoise& n) noexcept {
    Row h = Row::Zero();
    h(3 + c) = 1.0;
    h(0) = -1.0;
    update(h, r, n.kinematic_position * n.kinematic_position);
  }

  // Foot c stands still: v + u = 0, with variance σ_zv² / w (w > 0).
  void measureZeroVelocity(const Eigen::Vector3d& u, double w, const KinematicInertialNoise& n) noexcept {
    measureVelocity(-u, n.zero_velocity * n.zero_velocity / w);
  }

  // v = z with the given variance per axis.
  void measureVelocity(const Eigen::Vector3d& z, double variance) noexcept {
    Row h = Row::Zero();
    h(1) = 1.0;
    update(h, z, variance);
  }

  Eigen::Vector3d position() const noexcept { return s_.row(0).transpose(); }
  Eigen::Vector3d velocity() const noexcept { return s_.row(1).transpose(); }
  Eigen::Vector3d bias() const noexcept { return s_.row(2).transpose(); }
  Eigen::Vector3d foot(int c) const noexcept { return s_.row(3 + c).transpose(); }
  const Matrix& covariance() const noexcept { return P_; }  // per axis

 private:
  // Scalar-row update applied to the three axes at once (they share P).
  void update(const Row& h, const Eigen::Vector3d& z, double r) noexcept {
    const Eigen::Matrix<double, N, 1> Ph = P_ * h.transpose();
    const double S = h * Ph + r;
    if (!(S > 0.0)) return;
    const Eigen::Matrix<double, N, 1> K = Ph / S;
    const Eigen::RowVector3d innovation = z.transpose() - h * s_;
    s_ += K * innovation;
    P_ -= K * Ph.transpose();
    P_ = 0.5 * (P_ + P_.transpose()).eval();
  }

  States s_ = States::Zero();
  Matrix P_ = Matrix::Identity();
};

}  // namespace hqp::tasks
