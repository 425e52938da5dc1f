#pragma once
// Level 4 task, eq. 2 on the angular rows of the torso frame (task frame NC):
//   J_ω q̈ = α_ff + kp e + kd (ω_ref − ω) − (J̇v)_ω,   e = log(R_ref Rᵀ) (world rotation vector).

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
    this->A.template leftCols<nv>() = dyn.J(frame).template bottomRows<3>();
    this->b = refs.torso_angular_acceleration + gains.kp * error_ +
              gains.kd * (refs.torso_angular_velocity - dyn.velocity(frame).template tail<3>()) -
              dyn.dJv(frame).template tail<3>();
  }

  template <class P>
  void configure(const P& p) noexcept {
    gains = p.torso;
    this->setWeight(p.torso_weight);
  }

  // log(R_ref Rᵀ) at the last update (rad, world).
  const Eigen::Vector3d& error() const { return error_; }

 private:
  Eigen::Vector3d error_ = Eigen::Vector3d::Zero();
};

}  // namespace hqp::tasks
