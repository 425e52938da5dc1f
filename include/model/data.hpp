#pragma once
// Data<Robot>: every result and all scratch of the model algorithms, with
// sizes fixed at compile time from the generated Robot description, so no
// algorithm ever touches the heap. Constants of the description that the
// algorithms need as Eigen types are cached once by the constructor.
// Spatial quantities are in world axes at the world origin (model/spatial.hpp).

#include <array>
#include <cmath>
#include <type_traits>

#include <Eigen/Core>

#include "model/robot_description.hpp"
#include "model/spatial.hpp"

namespace hqp::model {

namespace detail {
template <int R, int C>
struct MatrixBuffer {
  std::array<double, static_cast<std::size_t>(R) * C> values;
};
}  // namespace detail

// An R x C matrix stored in place like Eigen::Matrix<double, R, C>, used through an
// Eigen::Map. For sizes above EIGEN_STACK_ALLOCATION_LIMIT (128 KiB: nv > 128 for M), where
// Eigen refuses to build a fixed-size matrix with OBJECT_ALLOCATED_ON_STACK_IS_TOO_BIG: the
// storage stays inside its owner (no heap), and the limit itself, which also sizes Eigen's
// stack temporaries, is left alone (docs/install.md, "Large robots").
template <int R, int C>
class MappedMatrix : private detail::MatrixBuffer<R, C>, public Eigen::Map<Eigen::Matrix<double, R, C>> {
  using Buffer = detail::MatrixBuffer<R, C>;

 public:
  using Base = Eigen::Map<Eigen::Matrix<double, R, C>>;
  MappedMatrix() noexcept : Buffer{}, Base(Buffer::values.data()) {}
  // Copies the values and keeps pointing at its own storage.
  MappedMatrix(const MappedMatrix& o) noexcept : Buffer(o), Base(Buffer::values.data()) {}
  MappedMatrix& operator=(const MappedMatrix& o) noexcept {
    Buffer::values = o.Buffer::values;
    return *this;
  }
  template <class Derived>
  MappedMatrix& operator=(const Eigen::DenseBase<Derived>& x) {
    Base::operator=(x);
    return *this;
  }
};

// Eigen::Matrix<double, R, C> when Eigen accepts it as a fixed-size object, MappedMatrix
// otherwise; both are fixed-size expressions with the same storage order.
template <int R, int C>
using FixedMatrix = std::conditional_t<(EIGEN_STACK_ALLOCATION_LIMIT == 0 ||
                                        sizeof(double) * R * C <= EIGEN_STACK_ALLOCATION_LIMIT),
                                       Eigen::Matrix<double, R, C>, MappedMatrix<R, C>>;

template <class Robot>
struct Data {
  static constexpr int nb = Robot::nb;
  static constexpr int nq = Robot::nq;
  static constexpr int nv = Robot::nv;
  static_assert(nb >= 1, "a robot needs at least one movable body");
  static_assert(Robot::floating_base ? (nq == nv + 1) : (nq == nv), "nq/nv mismatch");

  using VectorQ = Eigen::Matrix<double, nq, 1>;
  using VectorV = Eigen::Matrix<double, nv, 1>;
  using MatrixV = FixedMatrix<nv, nv>;   // MappedMatrix for nv > 128
  using Jacobian = Eigen::Matrix<double, 6, nv>;
  using Matrix3V = Eigen::Matrix<double, 3, nv>;

  // ---- constants from Robot::bodies (filled by the constructor) ----
  std::array<int, nb> parent;                    // parent body, -1 = world
  std::array<int, nb> idx_q;                     // first index in q
  std::array<int, nb> idx_v;                     // first index in v
  std::array<bool, nb> prismatic;                // 1-DoF translation
  std::array<bool, nb> fix_identity;             // R_fix == 1 (skip a product)
  std::array<int, nb> axis_kind;                 // 0/1/2: ±x/±y/±z axis, 3: general
  std::array<double, nb> axis_sign;              // sign of a coordinate axis
  std::array<Eigen::Matrix3d, nb> R_fix;         // R_parent_body at q = 0
  std::array<Eigen::Vector3d, nb> p_fix;         // body origin in parent at q = 0
  std::array<Eigen::Vector3d, nb> axis;          // joint axis, body frame
  std::array<double, nb> body_mass;              // kg
  std::array<Eigen::Vector3d, nb> body_com;      // CoM, body frame
  std::array<Eigen::Matrix3d, nb> body_inertia;  // about the CoM, body frame
  std::array<bool, nb> inertia_diagonal;         // no products of inertia

  // ---- kinematics: forwardKinematics, and every pass that needs them ----
  std::array<Eigen::Matrix3d, nb> oR;  // body orientation R_world_body
  std::array<Eigen::Vector3d, nb> op;  // body origin in world (m)
  std::array<Vector6, nb> S;           // motion subspace of 1-DoF bodies (world origin)
  std::array<Vector6, nb> V;           // body twist (world origin)
  std::array<Vector6, nb> A;           // bias acceleration at q̈ = 0, no gravity (world origin)

  // ---- dynamics scratch ----
  std::array<Vector6, nb> Aq;             // acceleration with q̈ (rnea)
  std::array<SpatialInertia, nb> Ic;      // body inertia after the forward sweep, composite
                                          // inertia of the subtree after the backward sweep
  std::array<Vector6, nb> f;              // subtree force (world origin) after rnea
  std::array<Vector6, nb> F;              // Ic S of 1-DoF bodies: column of A_G at the origin
  Matrix6 F0;                             // Ic_0 S_0 of a floating base (6 columns)
  SpatialInertia Itot;                    // inertia of the whole robot
  Vector6 ftot;                           // total force sum (rate of momentum, with gravity)

  // ---- results ----
  MatrixV M;                // joint-space inertia matrix (nv x nv), eq. 1
  VectorV tau;              // rnea: M a + C v + G (nv)
  VectorV h;                // C v + G (nv), eq. 1
  VectorV g;                // G (nv)
  double mass = 0.0;        // total mass (kg)
  Eigen::Vector3d com;      // centre of mass, world (3)
  Eigen::Vector3d vcom;     // CoM velocity, world (3)
  Matrix3V Jcom;            // CoM Jacobian (3 x nv)
  Jacobian Ag;              // centroidal momentum matrix (6 x nv): [P; L_G] = Ag v
  Vector6 dAg_v;            // Ȧg v (6), eq. 2 for the momentum task
  Vector6 hg;               // centroidal momentum [P; L_G] = Ag v (6)

  Data() noexcept {
    for (int i = 0; i < nb; ++i) {
      const BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
      parent[i] = b.parent;
      idx_q[i] = b.idx_q;
      idx_v[i] = b.idx_v;
      prismatic[i] = (b.type == JointType::Prismatic);
      R_fix[i] << b.rot[0], b.rot[1], b.rot[2], b.rot[3], b.rot[4], b.rot[5], b.rot[6], b.rot[7],
          b.rot[8];
      p_fix[i] << b.xyz[0], b.xyz[1], b.xyz[2];
      axis[i] << b.axis[0], b.axis[1], b.axis[2];
      fix_identity[i] = R_fix[i] == Eigen::Matrix3d::Identity();
      axis_kind[i] = 3;
      axis_sign[i] = 1.0;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(axis[i][k]) == 1.0) {
          axis_kind[i] = k;
          axis_sign[i] = axis[i][k];
        }
      }
      body_mass[i] = b.mass;
      body_com[i] << b.com[0], b.com[1], b.com[2];
      // Ixx, Iyy, Izz, Ixy, Ixz, Iyz
      body_inertia[i] << b.inertia[0], b.inertia[3], b.inertia[4], b.inertia[3], b.inertia[1],
          b.inertia[5], b.inertia[4], b.inertia[5], b.inertia[2];
      inertia_diagonal[i] = b.inertia[3] == 0.0 && b.inertia[4] == 0.0 && b.inertia[5] == 0.0;
      oR[i].setIdentity();
      op[i].setZero();
      S[i].setZero();
      V[i].setZero();
      A[i].setZero();
      Aq[i].setZero();
      Ic[i].setZero();
      f[i].setZero();
      F[i].setZero();
    }
    F0.setZero();
    Itot.setZero();
    ftot.setZero();
    M.setZero();
    tau.setZero();
    h.setZero();
    g.setZero();
    com.setZero();
    vcom.setZero();
    Jcom.setZero();
    Ag.setZero();
    dAg_v.setZero();
    for (int i = 0; i < nb; ++i) mass += body_mass[i];
  }
};

// Gravity (m/s²) along world −z (docs/conventions.md).
inline constexpr double kGravity = 9.81;

}  // namespace hqp::model
