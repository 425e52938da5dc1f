#pragma once
// Level 3 task, eq. 2 with the centroidal momentum matrix (Wensing & Orin 2016):
//   Ṗ = A_G,lin q̈ + (Ȧ_G v)_lin = m a,   a = a_ff + kp e + kd ė,
//   e = r_CoM,ref − r_CoM,  ė = v_CoM,ref − v_CoM,
// Two extensions beyond the paper on the horizontal rows, both off by default (docs/tasks.md):
//   ki ∫e dt, the integral clamped per axis and, optionally, reset to 0 on an axis whose error
//   has the opposite sign of its integral (a Clegg integrator): what it stored while the push
//   carried the CoM away then cannot carry the CoM past its reference on the way back;
//   a capture-point gain schedule: per axis the gains blend from (kp, kd) to (kp_high, kd_high)
//   as the capture-point error |e + ė/ω| (ω = √(g / CoM height above the feet)) grows from
//   dcm_low to dcm_high, so soft gains ride out what the ankles can absorb and stiff ones act
//   when the capture point nears the sole edge.
// so [A_G,lin 0] x = m a − (Ȧ_G v)_lin (3 rows, N).
// The vertical row has its own gains (`vertical`): the CoM height does not matter for balance,
// and a stiff height loop straightens the knees when the torso leans (docs/tasks.md).

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "hqp/task.hpp"
#include "model/data.hpp"
#include "tasks/contact_layout.hpp"
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
      double z_feet = 0.0;
      for (int c = 0; c < NC; ++c) z_feet += refs.contact_pose[c].translation().z() / NC;
      const double omega = std::sqrt(hqp::model::kGravity / std::max(0.1, refs.com.z() - z_feet));
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
    resetState();
  }

  // The integral back to zero (Controller::reset()).
  void resetState() noexcept { integral_.setZero(); }

  // ∫e dt of the horizontal rows (m·s), as the last update left it.
  const Eigen::Vector2d& integral() const { return integral_; }

  // r_CoM,ref − r_CoM at the last update (m).
  const Eigen::Vector3d& error() const { return error_; }

 private:
  Eigen::Vector3d error_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d integral_ = Eigen::Vector2d::Zero();  // m·s, horizontal
  double ki_ = 0.0, integral_limit_ = 0.0, dt_ = 0.001;
  bool reset_on_crossing_ = false;
  PdGains high_{};
  double dcm_low_ = 0.0, dcm_high_ = 0.0;  // m; dcm_high <= dcm_low: no schedule
};

}  // namespace hqp::tasks
