#pragma once
// Level 2 task, eq. 2 for every contact frame: J_c q̈ = a_c − J̇_c v, with
//   a_c = a_ff + kp e + kd ė   (per part: linear and angular gains),
//   position:    e = p_ref − p,               ė = v_ref − v
//   orientation: e = log(R_ref Rᵀ) (world),   ė = ω_ref − ω
// CD = 6 (flat foot): 6 rows per contact [position; orientation].
// CD = 3 (point foot): 3 rows per contact, position only.

#include <Eigen/Core>

#include "hqp/task.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/orientation_error.hpp"
#include "tasks/pd_gains.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

template <class Layout>
class ContactPoseTask : public hqp::Task<Layout::nf, Layout::nx> {
 public:
  using layout = Layout;
  static constexpr int nv = Layout::nv, NC = Layout::num_contacts, CD = Layout::contact_dim;
  using VectorE = Eigen::Matrix<double, Layout::nf, 1>;

  PdGains linear{400.0, 40.0};
  PdGains angular{400.0, 40.0};

  ContactPoseTask() { this->name = "contact_pose"; }

  template <class Dyn>
  void update(const Dyn& dyn, const References<NC>& refs) noexcept {
    for (int c = 0; c < NC; ++c) {
      const int r = CD * c;
      const Eigen::Isometry3d& X = dyn.placement(c);
      const Vector6& vel = dyn.velocity(c);
      const Vector6& ff = refs.contact_acceleration[c];
      const Vector6& vref = refs.contact_velocity[c];
      const Eigen::Vector3d ep = refs.contact_pose[c].translation() - X.translation();
      error_.template segment<3>(r) = ep;
      this->A.template block<3, nv>(r, 0) = dyn.J(c).template topRows<3>();
      this->b.template segment<3>(r) = ff.template head<3>() + linear.kp * ep +
                                       linear.kd * (vref.template head<3>() - vel.template head<3>()) -
                                       dyn.dJv(c).template head<3>();
      if constexpr (CD == 6) {
        const Eigen::Vector3d eo = orientationError(refs.contact_pose[c].linear(), X.linear());
        error_.template segment<3>(r + 3) = eo;
        this->A.template block<3, nv>(r + 3, 0) = dyn.J(c).template bottomRows<3>();
        this->b.template segment<3>(r + 3) =
            ff.template tail<3>() + angular.kp * eo +
            angular.kd * (vref.template tail<3>() - vel.template tail<3>()) -
            dyn.dJv(c).template tail<3>();
      }
    }
  }

  template <class P>
  void configure(const P& p) noexcept {
    linear = p.foot_linear;
    angular = p.foot_angular;
  }

  // Per contact [p_ref − p; log(R_ref Rᵀ)] (CD = 6) or p_ref − p (CD = 3), last update.
  const VectorE& error() const { return error_; }

 private:
  VectorE error_ = VectorE::Zero();
};

}  // namespace hqp::tasks
