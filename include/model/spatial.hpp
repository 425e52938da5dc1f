#pragma once
// Spatial (6D) algebra in [linear; angular] order, every vector expressed in
// world axes at the world origin (Plücker coordinates of Featherstone 2008,
// ch. 2, with the two halves swapped). Working in one frame lets composite
// inertias be summed without transforms and gives Jacobian columns directly.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace hqp::model {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// Rigid-body (or composite) inertia about the world origin in world axes:
// mass m, first moment h = m c, rotational inertia I_O about the origin.
// Sums of these are again rigid-body inertias, which is what CRBA needs.
struct SpatialInertia {
  double m = 0.0;
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();

  void setZero() noexcept {
    m = 0.0;
    h.setZero();
    I.setZero();
  }
  SpatialInertia& operator+=(const SpatialInertia& o) noexcept {
    m += o.m;
    h += o.h;
    I += o.I;
    return *this;
  }
};

// Momentum of a body moving with twist V = [v_O; ω]:
// [m v_O + ω × h; I_O ω + h × v_O]  (linear momentum; angular momentum about O).
inline Vector6 applyInertia(const SpatialInertia& in, const Vector6& V) noexcept {
  const Eigen::Vector3d v = V.head<3>();
  const Eigen::Vector3d w = V.tail<3>();
  Vector6 f;
  f.head<3>() = in.m * v + w.cross(in.h);
  f.tail<3>() = in.I * w + in.h.cross(v);
  return f;
}

// Motion cross product V × U = [ω × u + v × η; ω × η] for V = [v; ω], U = [u; η].
inline Vector6 crossMotion(const Vector6& V, const Vector6& U) noexcept {
  const Eigen::Vector3d v = V.head<3>();
  const Eigen::Vector3d w = V.tail<3>();
  const Eigen::Vector3d u = U.head<3>();
  const Eigen::Vector3d e = U.tail<3>();
  Vector6 r;
  r.head<3>() = w.cross(u) + v.cross(e);
  r.tail<3>() = w.cross(e);
  return r;
}

// Force cross product V ×* F = [ω × f; ω × n + v × f] for F = [f; n].
inline Vector6 crossForce(const Vector6& V, const Vector6& F) noexcept {
  const Eigen::Vector3d v = V.head<3>();
  const Eigen::Vector3d w = V.tail<3>();
  const Eigen::Vector3d f = F.head<3>();
  const Eigen::Vector3d n = F.tail<3>();
  Vector6 r;
  r.head<3>() = w.cross(f);
  r.tail<3>() = w.cross(n) + v.cross(f);
  return r;
}

// Body twist [v_b; ω_b] (body axes, body origin) of a body at (R, p) to
// world-origin coordinates: [R v_b + p × R ω_b; R ω_b].
inline Vector6 bodyToWorldMotion(const Eigen::Matrix3d& R, const Eigen::Vector3d& p,
                                 const Vector6& vb) noexcept {
  const Eigen::Vector3d w = R * vb.tail<3>();
  Vector6 r;
  r.head<3>() = R * vb.head<3>() + p.cross(w);
  r.tail<3>() = w;
  return r;
}

// Transpose of the map above, applied to a world-origin force [f; n]:
// the same force in body axes about the body origin, [Rᵀ f; Rᵀ (n − p × f)].
inline Vector6 worldToBodyForce(const Eigen::Matrix3d& R, const Eigen::Vector3d& p,
                                const Vector6& F) noexcept {
  const Eigen::Vector3d f = F.head<3>();
  Vector6 r;
  r.head<3>() = R.transpose() * f;
  r.tail<3>() = R.transpose() * (F.tail<3>() - p.cross(f));
  return r;
}

// Velocity of the point p of a body moving with world-origin twist V:
// world-aligned twist at p, [v_O + ω × p; ω].
inline Vector6 shiftMotionTo(const Vector6& V, const Eigen::Vector3d& p) noexcept {
  Vector6 r;
  r.head<3>() = V.head<3>() + V.tail<3>().cross(p);
  r.tail<3>() = V.tail<3>();
  return r;
}

// Skew-symmetric matrix S(a) with S(a) b = a × b.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& a) noexcept {
  Eigen::Matrix3d S;
  S << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return S;
}

// sin and cos of one angle, to about one ulp for |x| < 1e5 (joint angles), at
// a fraction of the cost of the libm call: Cody-Waite reduction by π/2 (two-part
// constant, exact product for |k| < 2^20) and the classical minimax polynomials
// for sin and cos on [−π/4, π/4]. Larger or non-finite arguments use libm.
inline void sinCos(double x, double& s, double& c) noexcept {
  if (!(std::abs(x) < 1e5)) {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  const double t = x * 0.63661977236758134308;  // 2/π
  const long n = static_cast<long>(t + (t >= 0.0 ? 0.5 : -0.5));
  const double k = static_cast<double>(n);
  const double r = (x - k * 1.57079632673412561417e+00) - k * 6.07710050650619224932e-11;
  const double z = r * r;
  const double sr =
      r + r * z *
              (-1.66666666666666324348e-01 +
               z * (8.33333333332248946124e-03 +
                    z * (-1.98412698298579493134e-04 +
                         z * (2.75573137070700676789e-06 +
                              z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))));
  const double pc =
      z * z *
      (4.16666666666666019037e-02 +
       z * (-1.38888888888741095749e-03 +
            z * (2.48015872894767294178e-05 +
                 z * (-2.75573143513906633035e-07 +
                      z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
  // 1 − z/2 + pc, summed so that the rounding error of 1 − z/2 is recovered.
  const double hz = 0.5 * z;
  const double w = 1.0 - hz;
  const double cr = w + (((1.0 - w) - hz) + pc);
  switch (n & 3) {
    case 0: s = sr; c = cr; break;
    case 1: s = cr; c = -sr; break;
    case 2: s = -sr; c = -cr; break;
    default: s = -cr; c = sr; break;
  }
}

// Rotation by angle about the unit axis a (Rodrigues).
inline Eigen::Matrix3d axisRotation(const Eigen::Vector3d& a, double angle) noexcept {
  double s, c;
  sinCos(angle, s, c);
  const double t = 1.0 - c;
  Eigen::Matrix3d R;
  R << t * a.x() * a.x() + c, t * a.x() * a.y() - s * a.z(), t * a.x() * a.z() + s * a.y(),
      t * a.x() * a.y() + s * a.z(), t * a.y() * a.y() + c, t * a.y() * a.z() - s * a.x(),
      t * a.x() * a.z() - s * a.y(), t * a.y() * a.z() + s * a.x(), t * a.z() * a.z() + c;
  return R;
}

}  // namespace hqp::model
