#pragma once
// Level 3 task, eq. 2 with the centroidal momentum matrix (Wensing & Orin 2016):
//   Ṗ = A_G,lin q̈ + (Ȧ_G v)_lin = m a,   a = a_ff + kp e + kd ė,
//   e = r_CoM,ref − r_CoM,  ė = v_CoM,ref − v_CoM,
// Three extensions beyond the paper on the horizontal rows, all off by default (docs/tasks.md):
//   ki ∫e dt, the integral clamped per axis and, optionally, reset to 0 on an axis whose error
//   has the opposite sign of its integral (a Clegg integrator): what it stored while the push
//   carried the CoM away then cannot carry the CoM past its reference on the way back;
//   a capture-point gain schedule: per axis the gains blend from (kp, kd) to (kp_high, kd_high)
//   as the capture-point error |e + ė/ω| (ω = √(g / CoM height above the feet)) grows from
//   dcm_low to dcm_high, so soft gains ride out what the ankles can absorb and stiff ones act
//   when the capture point nears the sole edge;
//   a hip-strategy budget: the horizontal demand is clamped to what the CoP region can give plus
//   the angular momentum the torso may still take. With the net CoP p on the soles and f_z ≈ m g,
//   L̇_G = (p − c) × f gives a_x = ω²(c_x − p_x) − L̇_y/(m h), a_y = ω²(c_y − p_y) + L̇_x/(m h)
//   (h = CoM height above the soles); L̇ is allowed within [−K (θ + θ_max) − D L, K (θ_max − θ) − D L]
//   per axis, θ the torso's tilt from its reference: a spring-damper that gives the hip strategy
//   its full rate while the torso is upright and stops the torso before θ_max.
// so [A_G,lin 0] x = m a − (Ȧ_G v)_lin (3 rows, N).
// The vertical row has its own gains (`vertical`): the CoM height does not matter for balance,
// and a stiff height loop straightens the knees when the torso leans (docs/tasks.md).

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "hqp/task.hpp"
#include "model/data.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/cop_constraint.hpp"
#include "tasks/orientation_error.hpp"
#include "tasks/pd_gains.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

template <class Layout>
class LinearMomentumTask : public hqp::Task<3, Layout::nx> {
 public:
  using layout = Layout;
  static constexpr int nv = Layout::nv, NC = Layout::num_contacts;

  PdGains gains{9.0, 6.0};     // horizontal rows (x, y)
  PdGains vertical{1.0, 2.0};  // vertical row (z)

  LinearMomentumTask() { this->name = "linear_momentum"; }

  template <class Dyn>
  void update(const Dyn& dyn, const References<NC>& refs) noexcept {
    error_ = refs.com - dyn.com();
    const Eigen::Vector3d derr = refs.com_velocity - dyn.vcom();
    Eigen::Vector3d a = refs.com_acceleration + gains.kp * error_ + gains.kd * derr;
    if (dcm_high_ > dcm_low_) {
      const double omega = std::sqrt(hqp::model::kGravity / std::max(0.1, refs.com.z() - feetHeight(refs)));
      for (int i = 0; i < 2; ++i) {
        const double xi = std::abs(error_[i] + derr[i] / omega);
        const double s = std::clamp((xi - dcm_low_) / (dcm_high_ - dcm_low_), 0.0, 1.0);
        a[i] = refs.com_acceleration[i] + ((1.0 - s) * gains.kp + s * high_.kp) * error_[i] +
               ((1.0 - s) * gains.kd + s * high_.kd) * derr[i];
      }
    }
    if (ki_ > 0.0) {
      if (reset_on_crossing_) {
        for (int i = 0; i < 2; ++i) {
          if (error_[i] * integral_[i] < 0.0) integral_[i] = 0.0;
        }
      }
      integral_ = (integral_ + dt_ * error_.head<2>()).cwiseMax(-integral_limit_).cwiseMin(integral_limit_);
      a.head<2>() += ki_ * integral_;
    }
    if (hip_tilt_ < std::numeric_limits<double>::infinity()) clampToHipBudget(dyn, refs, a);
    a.z() = refs.com_acceleration.z() + vertical.kp * error_.z() + vertical.kd * derr.z();
    this->A.template leftCols<nv>() = dyn.Ag().template topRows<3>();
    this->b = dyn.mass() * a - dyn.dAg_v().template head<3>();
  }

  template <class P>
  void configure(const P& p) noexcept {
    gains = p.com;
    vertical = p.com_vertical;
    ki_ = p.com_ki;
    integral_limit_ = p.com_integral_limit;
    reset_on_crossing_ = p.com_integral_reset;
    dt_ = p.dt;
    high_ = p.com_high;
    dcm_low_ = p.com_dcm_low;
    dcm_high_ = p.com_dcm_high;
    hip_tilt_ = p.hip_max_tilt;
    hip_stiffness_ = p.hip_stiffness;
    hip_damping_ = p.hip_damping;
    cop_lo_ = {p.sole_x_min, p.sole_y_min};
    cop_hi_ = {p.sole_x_max, p.sole_y_max};
    cop_moment_margin_ = p.cop_moment_margin;
    resetState();
  }

  // The integral back to zero (Controller::reset()).
  void resetState() noexcept { integral_.setZero(); }

  // ∫e dt of the horizontal rows (m·s), as the last update left it.
  const Eigen::Vector2d& integral() const { return integral_; }

  // r_CoM,ref − r_CoM at the last update (m).
  const Eigen::Vector3d& error() const { return error_; }

 private:
  // Mean height of the reference contacts (m): the LIP's ground.
  static double feetHeight(const References<NC>& refs) noexcept {
    double z = 0.0;
    for (int c = 0; c < NC; ++c) z += refs.contact_pose[c].translation().z() / NC;
    return z;
  }

  // The horizontal rows of `a` clamped to the CoP region's range plus the hip-strategy budget.
  template <class Dyn>
  void clampToHipBudget(const Dyn& dyn, const References<NC>& refs, Eigen::Vector3d& a) const noexcept {
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int c = 0; c < NC; ++c) {
      const Eigen::Isometry3d& X = refs.contact_pose[c];
      for (int k = 0; k < 4; ++k) {  // the corners of the CoP region (a point for point feet)
        const Eigen::Vector3d corner(k & 1 ? cop_hi_.x() : cop_lo_.x(), k & 2 ? cop_hi_.y() : cop_lo_.y(), 0.0);
        const Eigen::Vector2d p =
            (X * (Layout::contact_dim == 6 ? corner : Eigen::Vector3d::Zero())).template head<2>();
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
    // The CoP constraint's moment margins δ_c move the whole robot's CoP range in by Σ δ_c over
    // the weight (the total normal force standing still).
    double margin = 0.0;
    for (int c = 0; c < NC; ++c)
      margin += copMomentMargin(cop_moment_margin_, refs.contact_load[c], cop_lo_.y(), cop_hi_.y());
    const double shrink = margin / (dyn.mass() * hqp::model::kGravity);
    lo.array() += shrink;
    hi.array() -= shrink;
    const Eigen::Vector3d& c = dyn.com();
    const double h = std::max(0.1, c.z() - feetHeight(refs)), w2 = hqp::model::kGravity / h, mh = dyn.mass() * h;
    const Eigen::Vector3d L = dyn.hg().template tail<3>();
    // θ: the torso's rotation from its reference (world rotation vector).
    const Eigen::Vector3d tilt = -orientationError(refs.torso_orientation, dyn.placement(Layout::torso_frame).linear());
    const double K = hip_stiffness_, D = hip_damping_, t = hip_tilt_;
    const auto dL_lo = [&](int i) { return -K * (tilt[i] + t) - D * L[i]; };
    const auto dL_hi = [&](int i) { return K * (t - tilt[i]) - D * L[i]; };
    a.x() = std::clamp(a.x(), w2 * (c.x() - hi.x()) - dL_hi(1) / mh, w2 * (c.x() - lo.x()) - dL_lo(1) / mh);
    a.y() = std::clamp(a.y(), w2 * (c.y() - hi.y()) + dL_lo(0) / mh, w2 * (c.y() - lo.y()) + dL_hi(0) / mh);
  }

  Eigen::Vector3d error_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d integral_ = Eigen::Vector2d::Zero();  // m·s, horizontal
  double ki_ = 0.0, integral_limit_ = 0.0, dt_ = 0.001;
  bool reset_on_crossing_ = false;
  PdGains high_{};
  double dcm_low_ = 0.0, dcm_high_ = 0.0;  // m; dcm_high <= dcm_low: no schedule
  double hip_tilt_ = std::numeric_limits<double>::infinity();  // rad; ∞: no budget
  double hip_stiffness_ = 0.0, hip_damping_ = 0.0;                 // N·m/rad, 1/s
  Eigen::Vector2d cop_lo_{-0.1, -0.04}, cop_hi_{0.1, 0.04};        // CoP region, sole frame (m)
  double cop_moment_margin_ = 0.0;                                 // N·m, the CoP rows' δ
};

}  // namespace hqp::tasks
