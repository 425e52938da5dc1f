#pragma once
// Orientation error e = log(R_ref Rᵀ) as a world-frame rotation vector (angle · axis,
// angle in [0, π]). It is the rotation that takes the current frame to the reference,
// so ė = ω_ref − ω to first order and a = kp e + kd ė drives R towards R_ref.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace hqp::tasks {

inline Eigen::Vector3d orientationError(const Eigen::Matrix3d& R_ref,
                                        const Eigen::Matrix3d& R) noexcept {
  Eigen::Quaterniond dq(Eigen::Matrix3d(R_ref * R.transpose()));
  if (dq.w() < 0.0) dq.coeffs() = -dq.coeffs();  // shortest rotation: angle ≤ π
  const double s = dq.vec().norm();              // sin(θ/2)
  // θ = 2 atan2(s, w); e = θ / s · vec, with θ / s → 2 as s → 0.
  const double k = s > 1e-12 ? 2.0 * std::atan2(s, dq.w()) / s : 2.0;
  return k * dq.vec();
}

}  // namespace hqp::tasks
