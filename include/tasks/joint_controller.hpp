#pragma once
// Joint-level control, Sec. V-A of the paper: the motor current command
//
//   i_cmd = k_i (τ_opt + k_f τ_f + τ_q̇)                      (eq. 5)
//   τ_f   = friction compensation at q̇_des                  (eq. 7, friction_model.hpp)
//   τ_q̇   = k_q̇ (q̇_des − q̇)                                (eq. 8)
//   q̇_des = ∫ q̈* dt                                         (eqs. 7, 8)
//
// with τ_opt from eq. 6 (inverse_dynamics.hpp) and k_i = 1 / k_t, k_t the
// joint-side torque constant (N·m/A, gear ratio included).
//
// Integrator policy (the paper gives none; a pure ∫q̈* dt drifts because q̈* is
// never exactly the robot's acceleration):
//   1. q̇_des ← q̇_des + q̈* dt                       (explicit Euler)
//   2. q̇_des ← q̇_des + α (q̇ − q̇_des), α = 1 − exp(−dt / T_leak)
// i.e. a first-order leak toward the measured velocity with time constant
// T_leak (`leak_time`); T_leak = 0 or ∞ disables the leak (pure integral).
// A joint may have its own T_leak (`joint_leak_time`, NaN = leak_time): on a moving
// support the ankles turn at the support's rate, which ∫q̈* dt does not contain, and
// eq. 7 needs that velocity's sign (docs/controller.md).
// reset(q̇) sets q̇_des := q̇ (at start-up and when leaving safe mode).
// The current is clamped to ±current_limit per joint (reported in status()).
// A non-finite input (τ_opt, q̈*, q̇, dt) commands zero current, sets
// status().input_finite = false and out.safe_mode = true, and leaves q̇_des as
// it was; nothing non-finite ever reaches `out`. No heap, no exceptions.

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "tasks/friction_model.hpp"
#include "tasks/sensor_data.hpp"

namespace hqp::tasks {

template <int NJ>
struct JointControlParameters {
  using VectorJ = Eigen::Matrix<double, NJ, 1>;
  VectorJ k_f = VectorJ::Ones();              // friction compensation coefficient (eq. 5), 0..1
  VectorJ k_dq = VectorJ::Zero();             // k_q̇ (N·m·s/rad), eq. 8
  VectorJ torque_constant = VectorJ::Ones();  // k_t (N·m/A), k_i = 1 / k_t; > 0
  VectorJ current_limit = VectorJ::Constant(std::numeric_limits<double>::infinity());  // A, > 0
  std::array<JointFriction, NJ> friction{};   // eq. 7 per joint
  double leak_time = 0.0;                     // s; 0 or ∞ = no leak
  // s per joint, overriding leak_time; NaN = leak_time (beyond the paper, docs/controller.md)
  VectorJ joint_leak_time = VectorJ::Constant(std::numeric_limits<double>::quiet_NaN());
};

// What the last compute() did.
template <int NJ>
struct JointControlStatus {
  bool input_finite = true;          // false: zero current was commanded
  int num_saturated = 0;             // joints whose current was clamped
  std::array<bool, NJ> saturated{};  // per joint
};

template <int NJ>
class JointController {
 public:
  using VectorJ = Eigen::Matrix<double, NJ, 1>;

  JointController() noexcept { dq_des_.setZero(); }

  void configure(const JointControlParameters<NJ>& p) { p_ = p; }
  const JointControlParameters<NJ>& parameters() const noexcept { return p_; }

  // q̇_des := q̇ (a non-finite entry becomes 0).
  void reset(const VectorJ& dq_measured) noexcept {
    for (int j = 0; j < NJ; ++j) dq_des_[j] = std::isfinite(dq_measured[j]) ? dq_measured[j] : 0.0;
  }

  void compute(const VectorJ& tau_opt, const VectorJ& ddq_opt, const VectorJ& dq_measured,
               double dt, ActuatorCommand<NJ>& out) noexcept {
    status_.num_saturated = 0;
    status_.saturated.fill(false);
    status_.input_finite = std::isfinite(dt) && dt >= 0.0 && tau_opt.allFinite() &&
                           ddq_opt.allFinite() && dq_measured.allFinite();
    if (!status_.input_finite) {
      out.current.setZero();
      out.torque.setZero();
      out.safe_mode = true;
      return;
    }
    const auto leak = [dt](double T) { return (T > 0.0 && std::isfinite(T)) ? -std::expm1(-dt / T) : 0.0; };
    const double alpha_all = leak(p_.leak_time);  // one expm1 per tick unless a joint has its own T
    for (int j = 0; j < NJ; ++j) {
      const double alpha = std::isnan(p_.joint_leak_time[j]) ? alpha_all : leak(p_.joint_leak_time[j]);
      double dq_des = dq_des_[j] + ddq_opt[j] * dt;
      dq_des += alpha * (dq_measured[j] - dq_des);
      const double tau_f = frictionTorque(p_.friction[static_cast<std::size_t>(j)], dq_des);  // eq. 7
      const double tau_dq = p_.k_dq[j] * (dq_des - dq_measured[j]);                         // eq. 8
      const double tau = tau_opt[j] + p_.k_f[j] * tau_f + tau_dq;                           // eq. 5
      const double kt = p_.torque_constant[j];
      const double lim = p_.current_limit[j];
      double i = tau / kt;
      if (std::isnan(i)) i = 0.0;  // only with a bad k_t (configure() inputs are validated at load)
      const bool clamped = i > lim || i < -lim;
      if (clamped) {
        i = i > 0.0 ? lim : -lim;
        status_.saturated[static_cast<std::size_t>(j)] = true;
        ++status_.num_saturated;
      }
      double t = kt * i;
      if (!std::isfinite(i) || !std::isfinite(t)) i = t = 0.0;
      dq_des_[j] = std::isfinite(dq_des) ? dq_des : dq_measured[j];
      out.current[j] = i;
      out.torque[j] = t;
    }
  }

  const VectorJ& desiredVelocity() const noexcept { return dq_des_; }
  const JointControlStatus<NJ>& status() const noexcept { return status_; }

 private:
  JointControlParameters<NJ> p_{};
  JointControlStatus<NJ> status_{};
  VectorJ dq_des_;
};

}  // namespace hqp::tasks
