#pragma once
// Inverse dynamics of eq. 1 by the recursive Newton-Euler algorithm
// (Featherstone 2008, §5.3), in world-origin coordinates with gravity folded
// into the accelerations (a_g = [0 0 −g; 0]):
//   f_i = I_i (A_i − a_g) + V_i ×* I_i V_i,  f_λ += f_i,  τ_i = S_iᵀ f_i.

#include "model/backward_pass.hpp"
#include "model/data.hpp"
#include "model/kinematics.hpp"

namespace hqp::model {

// d.tau = M(q) a + C(q, v) v + G(q). Leaves d.A (the q̈ = 0 bias) alone.
template <class Robot>
const typename Data<Robot>::VectorV& rnea(Data<Robot>& d, const typename Data<Robot>::VectorQ& q,
                                          const typename Data<Robot>::VectorV& v,
                                          const typename Data<Robot>::VectorV& a) noexcept {
  detail::forwardPass<Robot, detail::kMotion | detail::kAccel | detail::kForces>(d, q, v, a);
  detail::backwardPass<Robot, detail::kTau>(d, d.tau);
  return d.tau;
}

// d.h = C(q, v) v + G(q): RNEA at q̈ = 0. Also updates the forward kinematics
// (placements, twists, bias accelerations) as forwardKinematics(d, q, v) does.
template <class Robot>
const typename Data<Robot>::VectorV& nonLinearEffects(
    Data<Robot>& d, const typename Data<Robot>::VectorQ& q,
    const typename Data<Robot>::VectorV& v) noexcept {
  detail::forwardPass<Robot, detail::kMotion | detail::kForces>(d, q, v, v);
  detail::backwardPass<Robot, detail::kTau>(d, d.h);
  return d.h;
}

// d.g = G(q): RNEA at v = 0, q̈ = 0 (only gravity loads the bodies).
template <class Robot>
const typename Data<Robot>::VectorV& computeGravity(
    Data<Robot>& d, const typename Data<Robot>::VectorQ& q) noexcept {
  detail::forwardPass<Robot, detail::kForces>(d, q, d.g, d.g);
  detail::backwardPass<Robot, detail::kTau>(d, d.g);
  return d.g;
}

}  // namespace hqp::model
