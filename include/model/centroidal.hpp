#pragma once
// Centre of mass and centroidal momentum (Wensing & Orin 2016; Orin, Goswami
// & Lee 2013), from by-products of CRBA and RNEA in world-origin coordinates:
//   h_O = Σ_i I_i V_i = Σ_i (Ic_i S_i) q̇_i, so column i of A_G at O is F_i = Ic_i S_i
//   ḣ_O(q̈ = 0) = Σ_i (I_i A_i + V_i ×* I_i V_i) = f_tot + I_tot a_g
//                (the RNEA forces summed over the roots, gravity removed)
// and the shift to the CoM c: [P; L_G] = [P; L_O − c × P]. Since ċ ∥ P,
// d/dt L_G = d/dt L_O − c × Ṗ, so Ȧ_G v is shifted the same way.
// Jcom = A_G(linear) / m; c = h / m of the total inertia.

#include <Eigen/Core>

#include "model/backward_pass.hpp"
#include "model/data.hpp"
#include "model/kinematics.hpp"

namespace hqp::model {
namespace detail {

// [f; n − c × f]: a world-origin momentum (or its rate) about the point c.
inline Vector6 shiftForceTo(const Vector6& F, const Eigen::Vector3d& c) noexcept {
  Vector6 r;
  r.head<3>() = F.head<3>();
  r.tail<3>() = F.tail<3>() - c.cross(F.template head<3>());
  return r;
}

// d.com, d.Ag, d.Jcom, d.vcom, d.hg from the composite pass (kComposite).
template <class Robot>
inline void centroidalFromComposite(Data<Robot>& d,
                                    const typename Data<Robot>::VectorV& v) noexcept {
  constexpr int first = Robot::floating_base ? 1 : 0;
  d.com = d.Itot.h / d.Itot.m;
  for (int i = first; i < Data<Robot>::nb; ++i) d.Ag.col(d.idx_v[i]) = shiftForceTo(d.F[i], d.com);
  if constexpr (Robot::floating_base) {
    for (int k = 0; k < 6; ++k) d.Ag.col(k) = shiftForceTo(d.F0.col(k), d.com);
  }
  d.Jcom = d.Ag.template topRows<3>() / d.Itot.m;
  d.vcom.noalias() = d.Jcom * v;
  d.hg.template head<3>() = d.Itot.m * d.vcom;  // P = m v_CoM: the linear rows are not formed twice
  d.hg.template tail<3>().noalias() = d.Ag.template bottomRows<3>() * v;
}

// d.dAg_v from the RNEA total force (kTau after a q̈ = 0 forward pass with forces).
template <class Robot>
inline void centroidalBias(Data<Robot>& d) noexcept {
  Vector6 ag = Vector6::Zero();
  ag[2] = -kGravity;
  d.dAg_v = shiftForceTo(d.ftot + applyInertia(d.Itot, ag), d.com);
}

}  // namespace detail

// d.com, d.vcom, d.Jcom (and d.mass, a constant); also d.Ag as a by-product.
template <class Robot>
void centerOfMass(Data<Robot>& d, const typename Data<Robot>::VectorQ& q,
                  const typename Data<Robot>::VectorV& v) noexcept {
  detail::forwardPass<Robot, detail::kInertia>(d, q, v, v);
  detail::backwardPass<Robot, detail::kComposite>(d, d.tau);
  detail::centroidalFromComposite(d, v);
}

// d.Ag (6 x nv), d.hg = A_G v = [P; L_G] and d.dAg_v (6): ḣ_G = A_G q̈ + Ȧ_G v.
// Also fills d.com, d.vcom, d.Jcom, d.h and the forward kinematics.
template <class Robot>
void centroidalMomentum(Data<Robot>& d, const typename Data<Robot>::VectorQ& q,
                        const typename Data<Robot>::VectorV& v) noexcept {
  detail::forwardPass<Robot, detail::kMotion | detail::kForces>(d, q, v, v);
  detail::backwardPass<Robot, detail::kComposite | detail::kTau>(d, d.h);
  detail::centroidalFromComposite(d, v);
  detail::centroidalBias(d);
}

}  // namespace hqp::model
