#pragma once
// The leaf-to-root sweep shared by CRBA, RNEA and the centroidal quantities.
// With every spatial quantity in world-origin coordinates the sweep needs no
// coordinate transforms: children's composite inertias and forces are simply
// added to their parent's (Featherstone 2008, §6.2 and §5.3).
//
//   Ic_λ += Ic_i,  f_λ += f_i                      (subtree sums)
//   F_i = Ic_i S_i,  M_ij = S_jᵀ F_i for j ⪯ i      (CRBA, eq. 1's M)
//   τ_i = S_iᵀ f_i                                  (RNEA, eq. 1's C + G)
// Floating base: S_0 = X_0, so its rows are X_0ᵀ F = the force in body axes.

#include <Eigen/Core>

#include "model/data.hpp"
#include "model/spatial.hpp"

namespace hqp::model {
namespace detail {

enum BackwardFlags : unsigned {
  kComposite = 1u,   // composite inertias Ic, F = Ic S, Data::Itot
  kMassMatrix = 2u,  // Data::M (needs kComposite)
  kTau = 4u,         // subtree forces, Data::ftot and the generalized forces τ
};

template <class Robot, unsigned Flags>
inline void backwardPass(Data<Robot>& d, typename Data<Robot>::VectorV& tau) noexcept {
  constexpr bool composite = (Flags & kComposite) != 0;
  constexpr bool mass_matrix = (Flags & kMassMatrix) != 0;
  constexpr bool forces = (Flags & kTau) != 0;
  static_assert(!mass_matrix || composite, "M needs the composite inertias");
  constexpr int first = Robot::floating_base ? 1 : 0;

  // d.Ic holds the body inertias from the forward sweep; they are summed in place.
  if constexpr (composite) d.Itot.setZero();
  if constexpr (mass_matrix) d.M.setZero();
  if constexpr (forces) d.ftot.setZero();

  for (int i = Data<Robot>::nb - 1; i >= first; --i) {
    const int vi = d.idx_v[i];
    const int p = d.parent[i];
    // Locals: stores into d.M cannot alias them, so they stay in registers.
    const Vector6 Si = d.S[i];
    Vector6 Fi = Vector6::Zero();
    if constexpr (composite) {
      Fi = applyInertia(d.Ic[i], Si);
      d.F[i] = Fi;
    }
    if constexpr (mass_matrix) {
      d.M(vi, vi) = Si.dot(Fi);
      for (int j = p; j >= first; j = d.parent[j]) {
        const double mij = d.S[j].dot(Fi);
        d.M(d.idx_v[j], vi) = mij;
        d.M(vi, d.idx_v[j]) = mij;
      }
      if constexpr (Robot::floating_base) {
        const Vector6 Fb = worldToBodyForce(d.oR[0], d.op[0], Fi);
        d.M.template block<6, 1>(0, vi) = Fb;
        d.M.template block<1, 6>(vi, 0) = Fb.transpose();
      }
    }
    if constexpr (forces) tau[vi] = d.S[i].dot(d.f[i]);
    if (p >= 0) {
      if constexpr (composite) d.Ic[p] += d.Ic[i];
      if constexpr (forces) d.f[p] += d.f[i];
    } else {
      if constexpr (composite) d.Itot += d.Ic[i];
      if constexpr (forces) d.ftot += d.f[i];
    }
  }

  if constexpr (Robot::floating_base) {
    const Eigen::Matrix3d& R = d.oR[0];
    const Eigen::Vector3d& o = d.op[0];
    const SpatialInertia& I = d.Ic[0];
    if constexpr (composite) {
      d.Itot = I;
      // F0 = Ic_0 X_0 column by column: a translation R_k gives [m R_k; h × R_k], a
      // rotation about R_k through o gives the twist [o × R_k; R_k].
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d Rk = R.col(k);
        const Eigen::Vector3d oxR = o.cross(Rk);
        d.F0.template block<3, 1>(0, k) = I.m * Rk;
        d.F0.template block<3, 1>(3, k) = I.h.cross(Rk);
        d.F0.template block<3, 1>(0, 3 + k) = I.m * oxR + Rk.cross(I.h);
        d.F0.template block<3, 1>(3, 3 + k) = I.I * Rk + I.h.cross(oxR);
      }
    }
    if constexpr (mass_matrix) {
      // X_0ᵀ Ic_0 X_0 = [[m 1, −S(m r_b)]; [S(m r_b), I_b]] with m r_b = Rᵀ (h − m o) and
      // I_b the rotational inertia about the base origin in base axes:
      // I_o = I_O + (m |o|² − 2 oᵀh) 1 + h oᵀ + o hᵀ − m o oᵀ, I_b = Rᵀ I_o R.
      const Eigen::Vector3d mrb = R.transpose() * (I.h - I.m * o);
      Eigen::Matrix3d Io = I.I;
      Io.diagonal().array() += I.m * o.squaredNorm() - 2.0 * o.dot(I.h);
      Io.noalias() += I.h * o.transpose() + o * I.h.transpose() - I.m * o * o.transpose();
      d.M.template block<3, 3>(0, 0) = I.m * Eigen::Matrix3d::Identity();
      d.M.template block<3, 3>(0, 3) = -skew(mrb);
      d.M.template block<3, 3>(3, 0) = skew(mrb);
      d.M.template block<3, 3>(3, 3).noalias() = R.transpose() * Io * R;
    }
    if constexpr (forces) {
      tau.template head<6>() = worldToBodyForce(R, o, d.f[0]);
      d.ftot = d.f[0];
    }
  }
}

}  // namespace detail
}  // namespace hqp::model
