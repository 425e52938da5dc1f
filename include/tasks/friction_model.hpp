#pragma once
// Joint friction compensation torque τ_f, eq. 7 of the paper (Sec. V-A):
//
//   τ_f =  F_c + F_v (q̇_d − q̇*)     if q̇_d ≥  q̇*
//          F_c q̇_d / q̇*              if −q̇* ≤ q̇_d ≤ q̇*
//         −F_c + F_v (q̇_d + q̇*)     if q̇_d ≤ −q̇*
//
// with q̇_d = ∫q̈* dt the desired joint velocity (joint_controller.hpp). The paper
// prints the middle branch as F_c q̇_d / q*; that is a typo for q̇* (only with q̇*
// do the branches meet: F_c at q̇_d = q̇*, −F_c at −q̇*). The linear band replaces
// the jump of sign(q̇) so that the compensation does not chatter when the joint
// reverses. Note that the viscous term counts from the band edge (q̇_d ∓ q̇*), as
// printed, so the law is continuous and odd.

#include <cmath>

namespace hqp::tasks {

// One joint's Coulomb-viscous friction (joint side).
struct JointFriction {
  double coulomb = 0.0;  // F_c (N·m)
  double viscous = 0.0;  // F_v (N·m·s/rad)
  double dq_star = 0.01; // q̇* (rad/s), half width of the linear band; > 0
};

// eq. 7. A non-positive q̇* degenerates to F_c sign(q̇_d) + F_v q̇_d (0 at rest).
// Non-finite q̇_d gives a non-finite result: callers check their inputs.
inline double frictionTorque(const JointFriction& f, double dq_des) noexcept {
  if (!(f.dq_star > 0.0)) {
    if (dq_des > 0.0) return f.coulomb + f.viscous * dq_des;
    if (dq_des < 0.0) return -f.coulomb + f.viscous * dq_des;
    return 0.0;
  }
  if (dq_des >= f.dq_star) return f.coulomb + f.viscous * (dq_des - f.dq_star);
  if (dq_des <= -f.dq_star) return -f.coulomb + f.viscous * (dq_des + f.dq_star);
  return f.coulomb * dq_des / f.dq_star;
}

}  // namespace hqp::tasks
