#pragma once
// Level 4 task, eq. 2 on the angular rows of the torso frame (task frame NC):
//   J_ω q̈ = α_ff + kp sat(e) + kd (ω_ref − ω) − (J̇v)_ω,   e = log(R_ref Rᵀ) (world rotation vector),
// sat(e) = e scaled to |e| ≤ error_limit (beyond the paper; ∞ = the paper's PD). After the hip
// strategy has pitched the torso 30–45°, the full kp e asks 100–150 rad/s² to bring it back, and the
// reaction of that return throws the CoM the other way (docs/tasks.md).

#include <limits>

#include <Eigen/Core>

#include "hqp/task.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/orientation_error.hpp"
#include "tasks/pd_gains.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

template <class Layout>
class TorsoPostureTask : public hqp::Task<3, Layout::nx> {
 public:
  using layout = Layout;
  static constexpr int nv = Layout::nv, NC = Layout::num_contacts,
                       frame = Layout::torso_frame;

  PdGains gains{200.0, 28.28};

  TorsoPostureTask() { this->name = "torso_posture"; }

  template <class Dyn>
  void update(const Dyn& dyn, const References<NC>& refs) noexcept {
    error_ = orientationError(refs.torso_orientation, dyn.placement(frame).linear());
    const double norm = error_.norm();
    const double scale = norm > error_limit_ ? error_limit_ / norm : 1.0;
    this->A.template leftCols<nv>() = dyn.J(frame).template bottomRows<3>();
    this->b = refs.torso_angular_acceleration + (gains.kp * scale) * error_ +
              gains.kd * (refs.torso_angular_velocity - dyn.velocity(frame).template tail<3>()) -
              dyn.dJv(frame).template tail<3>();
  }

  template <class P>
  void configure(const P& p) noexcept {
    gains = p.torso;
    error_limit_ = p.torso_error_limit;
    this->setWeight(p.torso_weight);
  }

  // log(R_ref Rᵀ) at the last update (rad, world).
  const Eigen::Vector3d& error() const { return error_; }

 private:
  Eigen::Vector3d error_ = Eigen::Vector3d::Zero();
  double error_limit_ = std::numeric_limits<double>::infinity();  // rad
};

}  // namespace hqp::tasks
