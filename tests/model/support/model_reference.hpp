#pragma once
// Independent references for the model-layer tests: body placements by a
// plain chain of homogeneous transforms built from the description (Eigen's
// AngleAxis, no spatial algebra), body velocities by central finite
// differences of placements along integrate(), kinetic energy, momentum and
// potential energy summed body by body. Nothing here calls the recursions
// under test except forwardKinematics' placements (checked separately against
// the transform chain) and integrate().

#include <array>
#include <cmath>
#include <random>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/robot_dynamics.hpp"

namespace model_test {

template <class Robot>
using VecQ = typename hqp::model::Data<Robot>::VectorQ;
template <class Robot>
using VecV = typename hqp::model::Data<Robot>::VectorV;

template <class Robot>
using Poses = std::array<Eigen::Isometry3d, Robot::nb>;

// World placement of every body by composing homogeneous transforms.
template <class Robot>
Poses<Robot> chainPoses(const VecQ<Robot>& q) {
  Poses<Robot> X;
  for (int i = 0; i < Robot::nb; ++i) {
    const hqp::model::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
    Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
    if (b.type == hqp::model::JointType::Free) {
      local.translation() = Eigen::Vector3d(q[0], q[1], q[2]);
      local.linear() = Eigen::Quaterniond(q[3], q[4], q[5], q[6]).normalized().toRotationMatrix();
    } else {
      Eigen::Isometry3d fixed = Eigen::Isometry3d::Identity();
      fixed.translation() = Eigen::Vector3d(b.xyz[0], b.xyz[1], b.xyz[2]);
      fixed.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(b.rot);
      const Eigen::Vector3d axis(b.axis[0], b.axis[1], b.axis[2]);
      Eigen::Isometry3d joint = Eigen::Isometry3d::Identity();
      if (b.type == hqp::model::JointType::Prismatic) {
        joint.translation() = axis * q[b.idx_q];
      } else {
        joint.linear() = Eigen::AngleAxisd(q[b.idx_q], axis).toRotationMatrix();
      }
      local = fixed * joint;
    }
    X[i] = b.parent >= 0 ? X[b.parent] * local : local;
  }
  return X;
}

template <class Robot>
Eigen::Isometry3d chainFrame(const Poses<Robot>& X, int k) {
  const hqp::model::FrameDesc& f = Robot::frames[static_cast<std::size_t>(k)];
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
  local.translation() = Eigen::Vector3d(f.xyz[0], f.xyz[1], f.xyz[2]);
  local.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(f.rot);
  return f.body >= 0 ? X[f.body] * local : local;
}

// World CoM of body i.
template <class Robot>
Eigen::Vector3d bodyCom(const Poses<Robot>& X, int i) {
  const hqp::model::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
  return X[i] * Eigen::Vector3d(b.com[0], b.com[1], b.com[2]);
}

template <class Robot>
Eigen::Matrix3d bodyInertiaAtCom(int i) {
  const hqp::model::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
  Eigen::Matrix3d I;
  I << b.inertia[0], b.inertia[3], b.inertia[4], b.inertia[3], b.inertia[1], b.inertia[5],
      b.inertia[4], b.inertia[5], b.inertia[2];
  return I;
}

template <class Robot>
Eigen::Vector3d systemCom(const Poses<Robot>& X) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double m = 0.0;
  for (int i = 0; i < Robot::nb; ++i) {
    const double mi = Robot::bodies[static_cast<std::size_t>(i)].mass;
    c += mi * bodyCom<Robot>(X, i);
    m += mi;
  }
  return c / m;
}

// Rotation vector of R (log map), via AngleAxis.
inline Eigen::Vector3d logRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// Linear velocity of a moving point and angular velocity of a moving frame by
// central differences of two placements taken at ±eps.
struct PointMotion {
  Eigen::Vector3d v;
  Eigen::Vector3d w;
};
inline PointMotion centralMotion(const Eigen::Isometry3d& Xp, const Eigen::Isometry3d& Xm,
                                 double eps) {
  return {(Xp.translation() - Xm.translation()) / (2 * eps),
          logRotation(Xp.linear() * Xm.linear().transpose()) / (2 * eps)};
}

// Velocities of every body's CoM and angular velocities, by finite differences.
template <class Robot>
struct BodyMotion {
  std::array<Eigen::Vector3d, Robot::nb> vc;  // world velocity of the CoM
  std::array<Eigen::Vector3d, Robot::nb> w;   // world angular velocity
  Poses<Robot> X;                             // placements at q
};

template <class Robot>
BodyMotion<Robot> fdBodyMotion(const VecQ<Robot>& q, const VecV<Robot>& v, double eps) {
  const VecQ<Robot> qp = hqp::model::integrate<Robot>(q, v, eps);
  const VecQ<Robot> qm = hqp::model::integrate<Robot>(q, v, -eps);
  const Poses<Robot> Xp = chainPoses<Robot>(qp);
  const Poses<Robot> Xm = chainPoses<Robot>(qm);
  BodyMotion<Robot> out;
  out.X = chainPoses<Robot>(q);
  for (int i = 0; i < Robot::nb; ++i) {
    out.vc[i] = (bodyCom<Robot>(Xp, i) - bodyCom<Robot>(Xm, i)) / (2 * eps);
    out.w[i] = logRotation(Xp[i].linear() * Xm[i].linear().transpose()) / (2 * eps);
  }
  return out;
}

// Σ ½ m |v_c|² + ½ ωᵀ I_c ω with I_c rotated to world axes.
template <class Robot>
double kineticEnergy(const BodyMotion<Robot>& bm) {
  double T = 0.0;
  for (int i = 0; i < Robot::nb; ++i) {
    const double m = Robot::bodies[static_cast<std::size_t>(i)].mass;
    const Eigen::Matrix3d R = bm.X[i].linear();
    const Eigen::Matrix3d Iw = R * bodyInertiaAtCom<Robot>(i) * R.transpose();
    T += 0.5 * m * bm.vc[i].squaredNorm() + 0.5 * bm.w[i].dot(Iw * bm.w[i]);
  }
  return T;
}

// [P; L_G]: linear momentum and angular momentum about the system CoM.
template <class Robot>
Eigen::Matrix<double, 6, 1> centroidalMomentum(const BodyMotion<Robot>& bm) {
  const Eigen::Vector3d G = systemCom<Robot>(bm.X);
  Eigen::Matrix<double, 6, 1> hG = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < Robot::nb; ++i) {
    const double m = Robot::bodies[static_cast<std::size_t>(i)].mass;
    const Eigen::Matrix3d R = bm.X[i].linear();
    const Eigen::Matrix3d Iw = R * bodyInertiaAtCom<Robot>(i) * R.transpose();
    hG.head<3>() += m * bm.vc[i];
    hG.tail<3>() += Iw * bm.w[i] + (bodyCom<Robot>(bm.X, i) - G).cross(m * bm.vc[i]);
  }
  return hG;
}

// Potential energy U = −Σ m gᵀ c, g = (0, 0, −9.81).
template <class Robot>
double potentialEnergy(const VecQ<Robot>& q) {
  const Poses<Robot> X = chainPoses<Robot>(q);
  double U = 0.0;
  for (int i = 0; i < Robot::nb; ++i) {
    U += Robot::bodies[static_cast<std::size_t>(i)].mass * 9.81 * bodyCom<Robot>(X, i).z();
  }
  return U;
}

// Random state: base anywhere within 1 m, any orientation; revolute joints
// within ±π, prismatic within ±0.3 m; rates and accelerations within ±2.
template <class Robot>
VecQ<Robot> randomConfiguration(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecQ<Robot> q = hqp::model::neutralConfiguration<Robot>();
  int first = 0;
  if constexpr (Robot::floating_base) {
    first = 1;
    q.template head<3>() << u(rng), u(rng), u(rng);
    Eigen::Vector4d quat(u(rng), u(rng), u(rng), u(rng));
    quat.normalize();
    q.template segment<4>(3) = quat;
  }
  for (int i = first; i < Robot::nb; ++i) {
    const hqp::model::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
    q[b.idx_q] = (b.type == hqp::model::JointType::Prismatic ? 0.3 : 3.141592653589793) * u(rng);
  }
  return q;
}

template <class Robot>
VecV<Robot> randomVelocity(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  VecV<Robot> v;
  for (int i = 0; i < Robot::nv; ++i) v[i] = u(rng);
  return v;
}

}  // namespace model_test
