#pragma once
// Forward kinematics: body placements, twists and bias accelerations, all in
// world axes at the world origin, by one root-to-leaf sweep (Featherstone
// 2008, RNEA forward pass). The same sweep optionally adds q̈ and computes the
// body inertias and RNEA body forces, so that every algorithm of this folder
// is one forward sweep plus one backward sweep (model/backward_pass.hpp).
//
// 1-DoF joint of body i with unit axis a (world) through the body origin o:
//   S_i = [o × a; a] (revolute), S_i = [a; 0] (prismatic)
//   V_i = V_λ + S_i q̇_i,  A_i = A_λ + (V_i × S_i) q̇_i + S_i q̈_i
// (Ṡ_i = V_i × S_i because the axis is fixed in the body). Floating base:
// S_0 = X_0 (body twist to world origin), Ṡ_0 v = V_0 × V_0 = 0, so A_0 = X_0 a_0.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/data.hpp"
#include "model/spatial.hpp"

namespace hqp::model {
namespace detail {

// What one forward sweep computes, besides placements (always).
enum ForwardFlags : unsigned {
  kMotion = 1u,   // twists V and bias accelerations
  kAccel = 2u,    // add S q̈ (writes Data::Aq instead of Data::A)
  kInertia = 4u,  // body inertias in world coordinates, into Data::Ic
  kForces = 8u,   // RNEA body forces f = I (A − a_g) + V ×* I V, gravity folded in
};

// Body inertia about the world origin: c = o + R c_b, I_O = R I_c Rᵀ + m (|c|² 1 − c cᵀ).
// Only the 6 distinct entries are formed; a diagonal I_c (common in URDFs)
// gives R I_c Rᵀ = Σ_k I_kk r_k r_kᵀ with r_k the columns of R.
// Also returns the CoM c and R I_c Rᵀ (about the CoM, world axes) for the forces.
template <class Robot>
inline void bodyInertiaWorld(const Data<Robot>& d, int i, const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& o, SpatialInertia& I, Eigen::Vector3d& c,
                             Eigen::Matrix3d& Icw) noexcept {
  const double m = d.body_mass[i];
  c = o + R * d.body_com[i];
  I.m = m;
  I.h = m * c;
  Eigen::Matrix3d RI;  // R I_c, column k = R I_c e_k
  if (d.inertia_diagonal[i]) {
    const Eigen::Matrix3d& B = d.body_inertia[i];
    RI.col(0) = B(0, 0) * R.col(0);
    RI.col(1) = B(1, 1) * R.col(1);
    RI.col(2) = B(2, 2) * R.col(2);
  } else {
    RI.noalias() = R * d.body_inertia[i];
  }
  const double mcc = I.h.dot(c);
  // (R I_c Rᵀ)(a, b) = Σ_k RI(a, k) R(b, k)
  const double xx = RI(0, 0) * R(0, 0) + RI(0, 1) * R(0, 1) + RI(0, 2) * R(0, 2);
  const double yy = RI(1, 0) * R(1, 0) + RI(1, 1) * R(1, 1) + RI(1, 2) * R(1, 2);
  const double zz = RI(2, 0) * R(2, 0) + RI(2, 1) * R(2, 1) + RI(2, 2) * R(2, 2);
  const double xy = RI(0, 0) * R(1, 0) + RI(0, 1) * R(1, 1) + RI(0, 2) * R(1, 2);
  const double xz = RI(0, 0) * R(2, 0) + RI(0, 1) * R(2, 1) + RI(0, 2) * R(2, 2);
  const double yz = RI(1, 0) * R(2, 0) + RI(1, 1) * R(2, 1) + RI(1, 2) * R(2, 2);
  Icw << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  I.I(0, 0) = xx + mcc - I.h.x() * c.x();
  I.I(1, 1) = yy + mcc - I.h.y() * c.y();
  I.I(2, 2) = zz + mcc - I.h.z() * c.z();
  I.I(0, 1) = I.I(1, 0) = xy - I.h.x() * c.y();
  I.I(0, 2) = I.I(2, 0) = xz - I.h.x() * c.z();
  I.I(1, 2) = I.I(2, 1) = yz - I.h.y() * c.z();
}

// Ro = A Rot(a, angle): for a coordinate axis only two columns mix.
inline void rotateColumns(const Eigen::Matrix3d& A, int kind, double angle,
                          const Eigen::Vector3d& a, Eigen::Matrix3d& Ro) noexcept {
  if (kind == 3) {
    Ro.noalias() = A * axisRotation(a, angle);
    return;
  }
  double s, c;
  sinCos(angle, s, c);
  const int i = (kind + 1) % 3;  // (i, j, kind) is a cyclic permutation
  const int j = (kind + 2) % 3;
  Ro.col(kind) = A.col(kind);
  Ro.col(i) = c * A.col(i) + s * A.col(j);
  Ro.col(j) = c * A.col(j) - s * A.col(i);
}

template <class Robot, unsigned Flags>
inline void forwardPass(Data<Robot>& d, const typename Data<Robot>::VectorQ& q,
                        const typename Data<Robot>::VectorV& v,
                        const typename Data<Robot>::VectorV& qdd) noexcept {
  constexpr bool motion = (Flags & kMotion) != 0;
  constexpr bool accel = (Flags & kAccel) != 0;
  constexpr bool forces = (Flags & kForces) != 0;
  constexpr bool inertia = forces || (Flags & kInertia) != 0;
  static_assert(!accel || motion, "q̈ needs the velocities");
  std::array<Vector6, Data<Robot>::nb>& Aout = accel ? d.Aq : d.A;

  // f = I (A − a_g) + V ×* I V with a_g = [0 0 −g; 0] (gravity folded in),
  // evaluated as Newton-Euler about the CoM c (fewer products than the 6D form):
  // F = m (p̈_c − a_g), n = I_c α + ω × I_c ω + c × F, with the classical CoM
  // acceleration p̈_c = a_O + α × c + ω × ṗ_c and ṗ_c = v_O + ω × c.
  const auto bodyForce = [](double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& Icw,
                            const Vector6& V, const Vector6& A) {
    Eigen::Vector3d F(0.0, 0.0, m * kGravity);
    Vector6 f;
    if constexpr (motion) {
      const Eigen::Vector3d w = V.tail<3>();
      const Eigen::Vector3d alpha = A.tail<3>();
      const Eigen::Vector3d vc = V.head<3>() + w.cross(c);
      F += m * (A.head<3>() + alpha.cross(c) + w.cross(vc));
      f.tail<3>() = Icw * alpha + w.cross(Icw * w) + c.cross(F);
    } else {
      f.tail<3>() = c.cross(F);
    }
    f.head<3>() = F;
    return f;
  };

  int first = 0;
  if constexpr (Robot::floating_base) {
    first = 1;
    const Eigen::Quaterniond quat(q[3], q[4], q[5], q[6]);
    const Eigen::Matrix3d R = quat.normalized().toRotationMatrix();
    const Eigen::Vector3d o = q.template head<3>();
    d.oR[0] = R;
    d.op[0] = o;
    Vector6 V = Vector6::Zero();
    Vector6 A = Vector6::Zero();
    if constexpr (motion) {
      V = bodyToWorldMotion(R, o, v.template head<6>());
      if constexpr (accel) A = bodyToWorldMotion(R, o, qdd.template head<6>());
      d.V[0] = V;
      Aout[0] = A;
    }
    if constexpr (inertia) {
      Eigen::Vector3d c;
      Eigen::Matrix3d Icw;
      bodyInertiaWorld(d, 0, R, o, d.Ic[0], c, Icw);
      if constexpr (forces) d.f[0] = bodyForce(d.body_mass[0], c, Icw, V, A);
    }
  }

  for (int i = first; i < Data<Robot>::nb; ++i) {
    const int p = d.parent[i];
    const double qi = q[d.idx_q[i]];
    // Parent orientation times the fixed joint placement (often the identity).
    const Eigen::Matrix3d& Rp = p >= 0 ? d.oR[p] : d.R_fix[i];
    Eigen::Matrix3d RpF;
    if (p < 0) {
      RpF = d.R_fix[i];
    } else if (d.fix_identity[i]) {
      RpF = Rp;
    } else {
      RpF.noalias() = Rp * d.R_fix[i];
    }
    // Body origin: o_λ + R_λ (p_fix + R_fix a q), the last term for prismatic joints.
    d.op[i] = d.p_fix[i];
    if (p >= 0) d.op[i] = d.op[p] + Rp * d.p_fix[i];
    if (d.prismatic[i]) {
      d.oR[i] = RpF;
      d.op[i].noalias() += RpF * (d.axis[i] * qi);
    } else {
      rotateColumns(RpF, d.axis_kind[i], d.axis_sign[i] * qi, d.axis[i], d.oR[i]);
    }
    const Eigen::Vector3d aw = d.oR[i] * d.axis[i];
    if (d.prismatic[i]) {
      d.S[i] << aw, 0.0, 0.0, 0.0;
    } else {
      d.S[i] << d.op[i].cross(aw), aw;
    }
    Vector6 V = Vector6::Zero();
    Vector6 A = Vector6::Zero();
    if constexpr (motion) {
      const double qdi = v[d.idx_v[i]];
      d.V[i] = d.S[i] * qdi;
      if (p >= 0) d.V[i] += d.V[p];
      Aout[i] = crossMotion(d.V[i], d.S[i]) * qdi;
      if constexpr (accel) Aout[i] += d.S[i] * qdd[d.idx_v[i]];
      if (p >= 0) Aout[i] += Aout[p];
      V = d.V[i];
      A = Aout[i];
    }
    if constexpr (inertia) {
      Eigen::Vector3d c;
      Eigen::Matrix3d Icw;
      bodyInertiaWorld(d, i, d.oR[i], d.op[i], d.Ic[i], c, Icw);
      if constexpr (forces) d.f[i] = bodyForce(d.body_mass[i], c, Icw, V, A);
    }
  }
}

}  // namespace detail

// Body placements (Data::oR, Data::op), twists (Data::V) and bias
// accelerations at q̈ = 0 without gravity (Data::A); frames.hpp reads them.
template <class Robot>
void forwardKinematics(Data<Robot>& d, const typename Data<Robot>::VectorQ& q,
                       const typename Data<Robot>::VectorV& v) noexcept {
  detail::forwardPass<Robot, detail::kMotion>(d, q, v, v);
}

// Body placements only.
template <class Robot>
void forwardKinematics(Data<Robot>& d, const typename Data<Robot>::VectorQ& q) noexcept {
  detail::forwardPass<Robot, 0u>(d, q, Data<Robot>::VectorV::Zero(), Data<Robot>::VectorV::Zero());
}

}  // namespace hqp::model
