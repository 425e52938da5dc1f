#pragma once
// Frames (Robot::frames): placement, velocity, Jacobian and J̇v of a frame
// rigidly attached to a body, from the state left by forwardKinematics.
// Jacobians are world-aligned at the frame origin (docs/conventions.md):
// J v = [ṗ; ω]. A body twist V (world origin) seen at the point p is
// [v_O + ω × p; ω]; the classical acceleration of p follows from the spatial
// acceleration A = [a_O; α] as p̈ = a_O + α × p + ω × ṗ.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/data.hpp"
#include "model/spatial.hpp"

namespace hqp::model {
namespace detail {

// World placement (R, p) of frame k from the body placements in d.
template <class Robot>
inline void framePose(const Data<Robot>& d, int k, Eigen::Matrix3d& R,
                      Eigen::Vector3d& p) noexcept {
  const FrameDesc& fr = Robot::frames[static_cast<std::size_t>(k)];
  Eigen::Matrix3d Rl;
  Rl << fr.rot[0], fr.rot[1], fr.rot[2], fr.rot[3], fr.rot[4], fr.rot[5], fr.rot[6], fr.rot[7],
      fr.rot[8];
  const Eigen::Vector3d pl(fr.xyz[0], fr.xyz[1], fr.xyz[2]);
  if (fr.body < 0) {
    R = Rl;
    p = pl;
  } else {
    R.noalias() = d.oR[fr.body] * Rl;
    p = d.op[fr.body];
    p.noalias() += d.oR[fr.body] * pl;
  }
}

// Columns of the world-aligned Jacobian at point p of body b; other columns untouched.
template <class Robot, class Derived>
inline void pointJacobian(const Data<Robot>& d, int b, const Eigen::Vector3d& p,
                          Eigen::MatrixBase<Derived>& J) noexcept {
  constexpr int first = Robot::floating_base ? 1 : 0;
  for (int j = b; j >= first; j = d.parent[j]) {
    J.col(d.idx_v[j]) = shiftMotionTo(d.S[j], p);
  }
  if constexpr (Robot::floating_base) {
    if (b >= 0) {
      // S_0 = X_0: v_p = R v_b + R ω_b × (p − o), ω = R ω_b.
      const Eigen::Matrix3d& R = d.oR[0];
      const Eigen::Vector3d r = p - d.op[0];
      J.template block<3, 3>(0, 0) = R;
      for (int k = 0; k < 3; ++k) J.template block<3, 1>(0, 3 + k) = R.col(k).cross(r);
      J.template block<3, 3>(3, 0).setZero();
      J.template block<3, 3>(3, 3) = R;
    }
  }
}

// Classical [p̈; ω̇] of point p of body b from spatial twist V and acceleration A.
inline Vector6 classicalAcceleration(const Vector6& V, const Vector6& A,
                                     const Eigen::Vector3d& p) noexcept {
  const Eigen::Vector3d w = V.tail<3>();
  const Eigen::Vector3d pd = V.head<3>() + w.cross(p);
  Vector6 r;
  r.head<3>() = A.head<3>() + A.tail<3>().cross(p) + w.cross(pd);
  r.tail<3>() = A.tail<3>();
  return r;
}

}  // namespace detail

// World placement of frame k.
template <class Robot>
Eigen::Isometry3d framePlacement(const Data<Robot>& d, int frame) noexcept {
  Eigen::Matrix3d R;
  Eigen::Vector3d p;
  detail::framePose(d, frame, R, p);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R;
  X.translation() = p;
  return X;
}

// [ṗ; ω] of frame k, world axes.
template <class Robot>
Vector6 frameVelocity(const Data<Robot>& d, int frame) noexcept {
  const int b = Robot::frames[static_cast<std::size_t>(frame)].body;
  if (b < 0) return Vector6::Zero();
  Eigen::Matrix3d R;
  Eigen::Vector3d p;
  detail::framePose(d, frame, R, p);
  return shiftMotionTo(d.V[b], p);
}

// 6 x nv Jacobian of frame k, world-aligned at the frame origin.
template <class Robot>
void frameJacobian(const Data<Robot>& d, int frame, typename Data<Robot>::Jacobian& J) noexcept {
  J.setZero();
  const int b = Robot::frames[static_cast<std::size_t>(frame)].body;
  if (b < 0) return;
  Eigen::Matrix3d R;
  Eigen::Vector3d p;
  detail::framePose(d, frame, R, p);
  detail::pointJacobian(d, b, p, J);
}

// J̇v of frame k: classical [p̈; ω̇] at q̈ = 0 (eq. 2), world axes.
template <class Robot>
Vector6 frameBiasAcceleration(const Data<Robot>& d, int frame) noexcept {
  const int b = Robot::frames[static_cast<std::size_t>(frame)].body;
  if (b < 0) return Vector6::Zero();
  Eigen::Matrix3d R;
  Eigen::Vector3d p;
  detail::framePose(d, frame, R, p);
  return detail::classicalAcceleration(d.V[b], d.A[b], p);
}

}  // namespace hqp::model
