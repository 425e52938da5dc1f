#pragma once
// Level 3 task, eq. 2 with the centroidal momentum matrix (Wensing & Orin 2016):
//   Ṗ = A_G,lin q̈ + (Ȧ_G v)_lin = m a,   a = a_ff + kp e + kd ė,
//   e = r_CoM,ref − r_CoM,  ė = v_CoM,ref − v_CoM,
// so [A_G,lin 0] x = m a − (Ȧ_G v)_lin (3 rows, N).
// The vertical row has its own gains (`vertical`): the CoM height does not matter for balance,
// and a stiff height loop straightens the knees when the torso leans (docs/tasks.md).

#include <Eigen/Core>

#include "hqp/task.hpp"
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
    a.z() = refs.com_acceleration.z() + vertical.kp * error_.z() + vertical.kd * derr.z();
    this->A.template leftCols<nv>() = dyn.Ag().template topRows<3>();
    this->b = dyn.mass() * a - dyn.dAg_v().template head<3>();
  }

  template <class P>
  void configure(const P& p) noexcept {
    gains = p.com;
    vertical = p.com_vertical;
  }

  // r_CoM,ref − r_CoM at the last update (m).
  const Eigen::Vector3d& error() const { return error_; }

 private:
  Eigen::Vector3d error_ = Eigen::Vector3d::Zero();
};

}  // namespace hqp::tasks
