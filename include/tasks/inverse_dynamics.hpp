#pragma once
// Eq. 6: the joint torques of a hierarchy solution x* = [q̈*; F*],
//   τ_opt = S_a (M q̈* + h − Σ_c J_cᵀ F*_c).

#include <Eigen/Core>

namespace hqp::tasks {

template <class L>
Eigen::Matrix<double, L::nj, 1> jointTorque(const typename L::Dynamics& dyn,
                                            const Eigen::Matrix<double, L::nx, 1>& x) noexcept {
  constexpr int nv = L::nv, nj = L::nj, CD = L::contact_dim;
  Eigen::Matrix<double, nj, 1> tau = dyn.h().template tail<nj>();
  tau.noalias() += dyn.M().template bottomRows<nj>() * x.template head<nv>();
  for (int c = 0; c < L::num_contacts; ++c)
    tau.noalias() -= dyn.J(c).template topRightCorner<CD, nj>().transpose() *
                     x.template segment<CD>(L::forceIndex(c));
  return tau;
}

}  // namespace hqp::tasks
