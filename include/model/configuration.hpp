#pragma once
// Configuration space: the neutral configuration and q ⊕ v dt.
// Floating base: q = [p; quat (w x y z)], v = body twist [v_b; ω_b]
// (docs/conventions.md), so integrating a constant v is the exponential map
// of SE(3) in body coordinates: (R, p) ← (R exp(ω dt), p + R V(ω dt) v dt).

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/data.hpp"

namespace hqp::model {

// Base at the origin, identity orientation, all joints at 0.
template <class Robot>
typename Data<Robot>::VectorQ neutralConfiguration() noexcept {
  typename Data<Robot>::VectorQ q = Data<Robot>::VectorQ::Zero();
  if constexpr (Robot::floating_base) q[3] = 1.0;
  return q;
}

// q ⊕ v dt: exact for a constant body twist of the base; joints add v dt.
template <class Robot>
typename Data<Robot>::VectorQ integrate(const typename Data<Robot>::VectorQ& q,
                                        const typename Data<Robot>::VectorV& v,
                                        double dt) noexcept {
  typename Data<Robot>::VectorQ out = q;
  int first_joint = 0;
  if constexpr (Robot::floating_base) {
    first_joint = 1;
    const Eigen::Vector3d u = v.template head<3>() * dt;     // translation part of the twist
    const Eigen::Vector3d phi = v.template segment<3>(3) * dt;  // rotation vector
    const double th2 = phi.squaredNorm();
    const double th = std::sqrt(th2);
    // V(φ) = I + b S(φ) + c S(φ)², b = (1 − cos θ)/θ², c = (θ − sin θ)/θ³ (series near 0).
    double b, c, half_sinc;
    if (th < 1e-4) {
      b = 0.5 - th2 / 24.0;
      c = 1.0 / 6.0 - th2 / 120.0;
      half_sinc = 0.5 - th2 / 48.0;  // sin(θ/2)/θ
    } else {
      b = (1.0 - std::cos(th)) / th2;
      c = (th - std::sin(th)) / (th2 * th);
      half_sinc = std::sin(0.5 * th) / th;
    }
    const Eigen::Vector3d pxu = phi.cross(u);
    const Eigen::Vector3d dp = u + b * pxu + c * phi.cross(pxu);
    const Eigen::Quaterniond quat(q[3], q[4], q[5], q[6]);
    const Eigen::Quaterniond dq(std::cos(0.5 * th), half_sinc * phi.x(), half_sinc * phi.y(),
                                half_sinc * phi.z());
    const Eigen::Vector3d p = q.template head<3>() + quat.normalized() * dp;
    const Eigen::Quaterniond qn = (quat * dq).normalized();
    out.template head<3>() = p;
    out[3] = qn.w();
    out[4] = qn.x();
    out[5] = qn.y();
    out[6] = qn.z();
  }
  for (int i = first_joint; i < Robot::nb; ++i) {
    const BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
    out[b.idx_q] = q[b.idx_q] + v[b.idx_v] * dt;
  }
  return out;
}

}  // namespace hqp::model
