#pragma once
// The inverse-dynamics regressor τ = Y(q, q̇, q̈) π of §V-B ("linearization of
// the dynamic equation"): the RNEA of model/rnea.hpp reorganized so that the
// generalized forces are linear in the inertial parameters of every body and
// the friction parameters of every joint.
//
// π = [π_body 0, …, π_body nb−1, π_fric joint 0, …, π_fric joint nj−1], with
//   π_body = [m, m c_x, m c_y, m c_z, I_xx, I_yy, I_zz, I_xy, I_xz, I_yz]
//            (c the CoM and I the rotational inertia about the BODY ORIGIN, body axes),
//   π_fric = [F_c, F_v] (Coulomb, viscous) of the friction law of eq. 7.
//
// Body i with body-frame twist [v; ω] and spatial acceleration [a; α] (gravity
// folded in as an upward acceleration of the base, as in the RNEA) feels, in
// body axes about its origin (Featherstone 2008, eq. 2.64 expanded),
//   f = m a' + (S(α) + S(ω)²) h,               a' = a + ω × v (classical)
//   n = I α + ω × I ω + h × a'                 (h = m c)
// which is linear in π_body. That 6×10 block is moved to world-origin
// coordinates and projected on the motion subspace of every ancestor joint,
// exactly as the RNEA's backward sweep does with the body forces.

#include <array>

#include <Eigen/Core>

#include "model/data.hpp"
#include "model/kinematics.hpp"
#include "model/spatial.hpp"

namespace hqp::model {

// Sizes of the regressor of a generated Robot.
template <class Robot>
struct RegressorSizes {
  static constexpr int nb = Robot::nb;
  static constexpr int nj = Robot::nj;
  static constexpr int nv = Robot::nv;
  static constexpr int n_inertial = 10 * nb;       // inertial parameters
  static constexpr int n_friction = 2 * nj;        // Coulomb + viscous per joint
  static constexpr int np = n_inertial + n_friction;
  // Column of joint j's Coulomb parameter (viscous is the next one).
  static constexpr int frictionColumn(int j) noexcept { return n_inertial + 2 * j; }
};

template <class Robot>
using RegressorMatrix = Eigen::Matrix<double, Robot::nv, RegressorSizes<Robot>::np>;
template <class Robot>
using ParameterVector = Eigen::Matrix<double, RegressorSizes<Robot>::np, 1>;
template <class Robot>
using JointVector = Eigen::Matrix<double, Robot::nj, 1>;

// Basis functions of the friction law of eq. 7, linear in (F_c, F_v):
//   τ_f = F_c φ_c(q̇) + F_v φ_v(q̇),
//   φ_c = q̇ / q̇* inside the band |q̇| ≤ q̇*, sign(q̇) outside  (the Coulomb ramp),
//   φ_v = q̇ − sign(q̇) q̇* outside the band, 0 inside         (viscous beyond q̇*).
// q̇* > 0 avoids the jump of the Coulomb term at reversal. q̇* ≤ 0 gives the
// discontinuous law F_c sign(q̇) + F_v q̇.
struct FrictionBasis {
  double coulomb;
  double viscous;
};

inline FrictionBasis frictionBasis(double dq, double dq_star) noexcept {
  if (dq_star > 0.0 && dq <= dq_star && dq >= -dq_star) return {dq / dq_star, 0.0};
  const double s = dq > 0.0 ? 1.0 : (dq < 0.0 ? -1.0 : 0.0);
  const double band = dq_star > 0.0 ? dq_star : 0.0;
  return {s, dq - s * band};
}

namespace detail {

// 6×10 block: the body force [f; n] (body axes, body origin) per unit of each
// inertial parameter, for body twist V = [v; ω] and spatial acceleration A = [a; α].
inline Eigen::Matrix<double, 6, 10> bodyRegressor(const Eigen::Vector3d& v,
                                                  const Eigen::Vector3d& w,
                                                  const Eigen::Vector3d& a,
                                                  const Eigen::Vector3d& al) noexcept {
  Eigen::Matrix<double, 6, 10> B;
  B.setZero();
  const Eigen::Vector3d ac = a + w.cross(v);  // classical acceleration of the origin
  // f = m a' + (S(α) + S(ω)²) h
  B.block<3, 1>(0, 0) = ac;
  B.block<3, 3>(0, 1) = skew(al) + skew(w) * skew(w);
  // n = h × a' + I α + ω × (I ω); I w = L(w) [xx yy zz xy xz yz]
  B.block<3, 3>(3, 1) = -skew(ac);
  const auto L = [](const Eigen::Vector3d& u) {
    Eigen::Matrix<double, 3, 6> M;
    M << u.x(), 0.0, 0.0, u.y(), u.z(), 0.0,  //
        0.0, u.y(), 0.0, u.x(), 0.0, u.z(),   //
        0.0, 0.0, u.z(), 0.0, u.x(), u.y();
    return M;
  };
  B.block<3, 6>(3, 4) = L(al) + skew(w) * L(w);
  return B;
}

}  // namespace detail

// Y(q, q̇, q̈) with Y π = M(q) q̈ + C(q, q̇) q̇ + G(q) + τ_friction(q̇) (eqs. 1 and 7).
// dq_star holds q̇* per joint (eq. 7). Floating base: the first 6 rows are the
// base wrench in base axes, as rnea() returns them; friction acts on joints only.
// Overwrites the kinematics of d (placements, twists, accelerations).
template <class Robot>
void computeRegressor(Data<Robot>& d, const typename Data<Robot>::VectorQ& q,
                      const typename Data<Robot>::VectorV& v,
                      const typename Data<Robot>::VectorV& a, const JointVector<Robot>& dq_star,
                      RegressorMatrix<Robot>& Y) noexcept {
  using Sizes = RegressorSizes<Robot>;
  constexpr int first = Robot::floating_base ? 1 : 0;
  detail::forwardPass<Robot, detail::kMotion | detail::kAccel>(d, q, v, a);
  Y.setZero();
  for (int i = 0; i < Sizes::nb; ++i) {
    const Eigen::Matrix3d& R = d.oR[i];
    const Eigen::Vector3d& o = d.op[i];
    // World-origin twist / acceleration (gravity folded in) to body axes at the body origin.
    const Vector6& Vi = d.V[i];
    const Vector6& Ai = d.Aq[i];
    const Eigen::Vector3d ww = Vi.tail<3>();
    const Eigen::Vector3d w = R.transpose() * ww;
    const Eigen::Vector3d vb = R.transpose() * (Vi.head<3>() + ww.cross(o));
    Eigen::Vector3d aw = Ai.head<3>();
    aw.z() += kGravity;
    const Eigen::Vector3d alw = Ai.tail<3>();
    const Eigen::Vector3d ab = R.transpose() * (aw + alw.cross(o));
    const Eigen::Vector3d alb = R.transpose() * alw;
    const Eigen::Matrix<double, 6, 10> B = detail::bodyRegressor(vb, w, ab, alb);
    // Body force to world-origin coordinates: [R f; R n + o × R f].
    Eigen::Matrix<double, 6, 10> Fw;
    Fw.topRows<3>().noalias() = R * B.topRows<3>();
    Fw.bottomRows<3>().noalias() = R * B.bottomRows<3>();
    Fw.bottomRows<3>().noalias() += skew(o) * Fw.topRows<3>();
    const int col = 10 * i;
    // τ_j = S_jᵀ f_i for every 1-DoF ancestor j of i (i included).
    for (int j = i; j >= first; j = d.parent[j]) {
      Y.template block<1, 10>(d.idx_v[j], col).noalias() = d.S[j].transpose() * Fw;
    }
    if constexpr (Robot::floating_base) {
      // Base rows: X_0ᵀ F = [Rᵀ f; Rᵀ (n − o × f)].
      const Eigen::Matrix3d& R0 = d.oR[0];
      const Eigen::Vector3d& o0 = d.op[0];
      Y.template block<3, 10>(0, col).noalias() = R0.transpose() * Fw.topRows<3>();
      Eigen::Matrix<double, 3, 10> n = Fw.bottomRows<3>();
      n.noalias() -= skew(o0) * Fw.topRows<3>();
      Y.template block<3, 10>(3, col).noalias() = R0.transpose() * n;
    }
  }
  for (int j = 0; j < Sizes::nj; ++j) {
    const int row = d.idx_v[j + first];
    const FrictionBasis phi = frictionBasis(v[row], dq_star[j]);
    Y(row, Sizes::frictionColumn(j)) = phi.coulomb;
    Y(row, Sizes::frictionColumn(j) + 1) = phi.viscous;
  }
}

// π from the generated description (the CAD / URDF values): inertia moved from
// the CoM to the body origin, I_O = I_c + m (|c|² 1 − c cᵀ); Coulomb friction
// from <dynamics friction>, viscous from <dynamics damping>.
template <class Robot>
ParameterVector<Robot> nominalParameters() noexcept {
  using Sizes = RegressorSizes<Robot>;
  constexpr int first = Robot::floating_base ? 1 : 0;
  ParameterVector<Robot> p;
  for (int i = 0; i < Sizes::nb; ++i) {
    const BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
    const Eigen::Vector3d c(b.com[0], b.com[1], b.com[2]);
    const double m = b.mass;
    Eigen::Matrix3d I;
    I << b.inertia[0], b.inertia[3], b.inertia[4], b.inertia[3], b.inertia[1], b.inertia[5],
        b.inertia[4], b.inertia[5], b.inertia[2];
    I += m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    p.template segment<10>(10 * i) << m, m * c.x(), m * c.y(), m * c.z(), I(0, 0), I(1, 1),
        I(2, 2), I(0, 1), I(0, 2), I(1, 2);
  }
  for (int j = 0; j < Sizes::nj; ++j) {
    const BodyDesc& b = Robot::bodies[static_cast<std::size_t>(j + first)];
    p[Sizes::frictionColumn(j)] = b.friction;
    p[Sizes::frictionColumn(j) + 1] = b.damping;
  }
  return p;
}

}  // namespace hqp::model
