// Property tests of the model layer (include/model) on random states.
// Expected values come from independent sources: a homogeneous-transform
// chain for placements, central finite differences for velocities and
// derivatives, body-by-body sums for energy and momentum, the potential
// energy for gravity, Christoffel symbols for C (fixed base) and the power
// balance vᵀ Ṁ v = 2 vᵀ C v (any base).
//
// Built once per robot set (tests/model/CMakeLists.txt): test_model_hand
// (hand-written robots, tests/model/support), test_model_<robot> with
// MODEL_TEST_HEADER / MODEL_TEST_ROBOT for one generated robot, and
// test_model_random_trees (MODEL_TEST_RANDOM_TREES, the five generated trees).
//
// Tolerances: central differences with step eps = 1e-6 have truncation error
// ~eps² |f'''| ≈ 1e-12 and round-off ~1e-16 |f| / eps ≈ 1e-10 for quantities
// of order one, so every finite-difference comparison uses 1e-6 relative
// (to 1 + |reference|); identities that need no differences use 1e-9.

#include <gtest/gtest.h>

#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "model/robot_dynamics.hpp"
#include "model/support/model_reference.hpp"

#if defined(MODEL_TEST_RANDOM_TREES)
#include "random_tree0_model.hpp"
#include "random_tree1_model.hpp"
#include "random_tree2_model.hpp"
#include "random_tree3_model.hpp"
#include "random_tree4_model.hpp"
#elif defined(MODEL_TEST_HEADER)
#include MODEL_TEST_HEADER
#else
#include "model/support/hand_robots.hpp"
#endif

namespace {

namespace hm = hqp::model;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using model_test::VecQ;
using model_test::VecV;

constexpr int kStates = 100;
constexpr double kEps = 1e-6;
constexpr double kFdTol = 1e-6;
constexpr double kTol = 1e-9;

// |a − b| ≤ tol (1 + |b|) elementwise-in-norm.
template <class A, class B>
::testing::AssertionResult near(const A& a, const B& b, double tol) {
  const double err = (a - b).norm();
  const double scale = 1.0 + b.norm();
  if (err <= tol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "error " << err << " > " << tol << " * " << scale
                                       << "\n got:      " << a.transpose()
                                       << "\n expected: " << b.transpose();
}
::testing::AssertionResult nearScalar(double a, double b, double tol) {
  if (std::abs(a - b) <= tol * (1.0 + std::abs(b))) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b;
}

template <class Robot>
class ModelProperties : public ::testing::Test {
 protected:
  std::mt19937 rng{1234u + static_cast<unsigned>(Robot::nv)};
  hm::Data<Robot> d;
  VecQ<Robot> q() { return model_test::randomConfiguration<Robot>(rng); }
  VecV<Robot> v() { return model_test::randomVelocity<Robot>(rng); }
};

#if defined(MODEL_TEST_RANDOM_TREES)
using Robots = ::testing::Types<random_tree0::Robot, random_tree1::Robot, random_tree2::Robot,
                                random_tree3::Robot, random_tree4::Robot>;
#elif defined(MODEL_TEST_HEADER)
using Robots = ::testing::Types<MODEL_TEST_ROBOT>;
#else
using Robots = ::testing::Types<hand_test::FloatingTree, hand_test::FixedForest>;
#endif
TYPED_TEST_SUITE(ModelProperties, Robots);

// Body and frame placements equal the homogeneous-transform chain.
TYPED_TEST(ModelProperties, PlacementsMatchTransformChain) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    hm::forwardKinematics(this->d, q, this->v());
    const auto X = model_test::chainPoses<R>(q);
    for (int i = 0; i < R::nb; ++i) {
      EXPECT_TRUE(near(this->d.op[i], X[i].translation(), kTol));
      EXPECT_TRUE(near(this->d.oR[i], X[i].linear(), kTol));
    }
    for (int k = 0; k < R::nframes; ++k) {
      const Eigen::Isometry3d Xf = hm::framePlacement(this->d, k);
      const Eigen::Isometry3d Xr = model_test::chainFrame<R>(X, k);
      EXPECT_TRUE(near(Xf.matrix(), Xr.matrix(), kTol)) << "frame " << k;
    }
  }
}

// Total mass: description constant, Data, and the sum of the bodies.
TYPED_TEST(ModelProperties, TotalMass) {
  using R = TypeParam;
  double m = 0.0;
  for (int i = 0; i < R::nb; ++i) m += R::bodies[static_cast<std::size_t>(i)].mass;
  EXPECT_NEAR(this->d.mass, m, 1e-12 * m);
  EXPECT_NEAR(R::total_mass, m, 1e-9 * m);
}

// M is symmetric positive definite.
TYPED_TEST(ModelProperties, MassMatrixSymmetricPositiveDefinite) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    hm::crba(this->d, this->q());
    const auto& M = this->d.M;
    EXPECT_LE((M - M.transpose()).norm(), 1e-14 * M.norm());
    Eigen::SelfAdjointEigenSolver<typename hm::Data<R>::MatrixV> es(M);
    EXPECT_GT(es.eigenvalues().minCoeff(), 0.0);
  }
}

// ½ vᵀ M v equals the kinetic energy summed over bodies with velocities from
// finite differences of the transform chain along integrate(q, v, ±eps).
TYPED_TEST(ModelProperties, KineticEnergy) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    hm::crba(this->d, q);
    const double T = 0.5 * v.dot(this->d.M * v);
    const auto bm = model_test::fdBodyMotion<R>(q, v, kEps);
    EXPECT_TRUE(nearScalar(T, model_test::kineticEnergy<R>(bm), kFdTol));
  }
}

// rnea(q, v, a) = M a + h;  h(q, 0) = g;  rnea(q, 0, 0) = g.
TYPED_TEST(ModelProperties, RneaEqualsMaPlusH) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    const VecV<R> a = this->v();
    hm::crba(this->d, q);
    const VecV<R> M_a = this->d.M * a;
    const VecV<R> h = hm::nonLinearEffects(this->d, q, v);
    const VecV<R> tau = hm::rnea(this->d, q, v, a);
    EXPECT_TRUE(near(tau, VecV<R>(M_a + h), kTol));
    const VecV<R> g = hm::computeGravity(this->d, q);
    EXPECT_TRUE(near(VecV<R>(hm::nonLinearEffects(this->d, q, VecV<R>::Zero())), g, kTol));
    EXPECT_TRUE(near(VecV<R>(hm::rnea(this->d, q, VecV<R>::Zero(), VecV<R>::Zero())), g, kTol));
  }
}

// G_j = ∂U/∂q_j along integrate(q, e_j, ±eps) (the generalized gravity force
// is the derivative of the potential energy along each velocity direction).
TYPED_TEST(ModelProperties, GravityIsPotentialGradient) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const VecV<R> g = hm::computeGravity(this->d, q);
    VecV<R> g_fd;
    for (int j = 0; j < R::nv; ++j) {
      const VecV<R> e = VecV<R>::Unit(j);
      g_fd[j] = (model_test::potentialEnergy<R>(hm::integrate<R>(q, e, kEps)) -
                 model_test::potentialEnergy<R>(hm::integrate<R>(q, e, -kEps))) /
                (2 * kEps);
    }
    EXPECT_TRUE(near(g, g_fd, kFdTol));
  }
}

// h(q, v) by virtual work, independent of the recursions: with q̈ = 0 every
// body follows q(t) = q ⊕ v t; its CoM acceleration p̈_c and angular
// acceleration ω̇ come from nested central differences of the transform chain
// (inner step 1e-5 for velocities, outer 1e-4 for accelerations: error ~1e-7),
// the wrench it needs is F = m (p̈_c − g), N = I ω̇ + ω × I ω about the CoM, and
// h_k = Σ_i (F_i · ∂ṗ_c,i/∂v_k + N_i · ∂ω_i/∂v_k) with those derivatives again
// by differences along integrate(q, e_k, ±1e-5). Holds for any base (power equivalence).
TYPED_TEST(ModelProperties, NonLinearEffectsByVirtualWork) {
  using R = TypeParam;
  constexpr double kOuter = 1e-4;
  constexpr double kInner = 1e-5;
  for (int s = 0; s < kStates / 4; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    const auto bp = model_test::fdBodyMotion<R>(hm::integrate<R>(q, v, kOuter), v, kInner);
    const auto bm = model_test::fdBodyMotion<R>(hm::integrate<R>(q, v, -kOuter), v, kInner);
    const auto b0 = model_test::fdBodyMotion<R>(q, v, kInner);
    std::array<Vector6d, R::nb> wrench;  // [F; N] about each body's CoM
    for (int i = 0; i < R::nb; ++i) {
      const double m = R::bodies[static_cast<std::size_t>(i)].mass;
      const Eigen::Matrix3d Rw = b0.X[i].linear();
      const Eigen::Matrix3d Iw = Rw * model_test::bodyInertiaAtCom<R>(i) * Rw.transpose();
      const Eigen::Vector3d ac = (bp.vc[i] - bm.vc[i]) / (2 * kOuter);
      const Eigen::Vector3d wd = (bp.w[i] - bm.w[i]) / (2 * kOuter);
      const Eigen::Vector3d w = b0.w[i];
      wrench[i] << m * (ac + Eigen::Vector3d(0.0, 0.0, 9.81)), Iw * wd + w.cross(Iw * w);
    }
    VecV<R> h_ref = VecV<R>::Zero();
    for (int k = 0; k < R::nv; ++k) {
      const auto dk = model_test::fdBodyMotion<R>(q, VecV<R>::Unit(k), kInner);
      for (int i = 0; i < R::nb; ++i) {
        h_ref[k] += wrench[i].template head<3>().dot(dk.vc[i]) +
                    wrench[i].template tail<3>().dot(dk.w[i]);
      }
    }
    EXPECT_TRUE(near(VecV<R>(hm::nonLinearEffects(this->d, q, v)), h_ref, 1e-5));
  }
}

// Power balance vᵀ Ṁ v = 2 vᵀ (h − g), Ṁ by central differences along integrate.
TYPED_TEST(ModelProperties, PowerBalance) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    const VecV<R> h = hm::nonLinearEffects(this->d, q, v);
    const VecV<R> g = hm::computeGravity(this->d, q);
    const typename hm::Data<R>::MatrixV Mp = hm::crba(this->d, hm::integrate<R>(q, v, kEps));
    const typename hm::Data<R>::MatrixV Mm = hm::crba(this->d, hm::integrate<R>(q, v, -kEps));
    const double vMdv = v.dot((Mp - Mm) * v) / (2 * kEps);
    EXPECT_TRUE(nearScalar(vMdv, 2.0 * v.dot(h - g), kFdTol * (1.0 + v.squaredNorm())));
  }
}

// Fixed base (q̇ = v): C from Christoffel symbols of ∂M/∂q by finite
// differences; h − g = C v and Ṁ − 2C is skew-symmetric.
TYPED_TEST(ModelProperties, ChristoffelFixedBase) {
  using R = TypeParam;
  if constexpr (R::floating_base) {
    GTEST_SKIP() << "Christoffel symbols need q̇ = v (fixed base)";
  } else {
    using MatV = typename hm::Data<R>::MatrixV;
    for (int s = 0; s < kStates / 5; ++s) {
      const auto q = this->q();
      const auto v = this->v();
      std::array<MatV, R::nv> dM;  // dM[i] = ∂M/∂q_i
      for (int i = 0; i < R::nv; ++i) {
        const MatV Mp = hm::crba(this->d, hm::integrate<R>(q, VecV<R>::Unit(i), kEps));
        const MatV Mm = hm::crba(this->d, hm::integrate<R>(q, VecV<R>::Unit(i), -kEps));
        dM[i] = (Mp - Mm) / (2 * kEps);
      }
      MatV C = MatV::Zero();
      MatV Mdot = MatV::Zero();
      for (int i = 0; i < R::nv; ++i) Mdot += dM[i] * v[i];
      for (int k = 0; k < R::nv; ++k)
        for (int j = 0; j < R::nv; ++j)
          for (int i = 0; i < R::nv; ++i)
            C(k, j) += 0.5 * (dM[i](k, j) + dM[j](k, i) - dM[k](i, j)) * v[i];
      const VecV<R> h = hm::nonLinearEffects(this->d, q, v);
      const VecV<R> g = hm::computeGravity(this->d, q);
      EXPECT_TRUE(near(VecV<R>(h - g), VecV<R>(C * v), kFdTol));
      const MatV N = Mdot - 2 * C;
      EXPECT_LE((N + N.transpose()).norm(), kFdTol * (1.0 + Mdot.norm()));
    }
  }
}

// J v and frameVelocity equal the finite-difference frame motion (position,
// and orientation via the log map), for every frame.
TYPED_TEST(ModelProperties, FrameJacobianMatchesFiniteDifferences) {
  using R = TypeParam;
  typename hm::Data<R>::Jacobian J;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    const auto Xp = model_test::chainPoses<R>(hm::integrate<R>(q, v, kEps));
    const auto Xm = model_test::chainPoses<R>(hm::integrate<R>(q, v, -kEps));
    hm::forwardKinematics(this->d, q, v);
    for (int k = 0; k < R::nframes; ++k) {
      const auto mo = model_test::centralMotion(model_test::chainFrame<R>(Xp, k),
                                                model_test::chainFrame<R>(Xm, k), kEps);
      Vector6d ref;
      ref << mo.v, mo.w;
      hm::frameJacobian(this->d, k, J);
      EXPECT_TRUE(near(Vector6d(J * v), ref, kFdTol)) << "frame " << k;
      EXPECT_TRUE(near(Vector6d(hm::frameVelocity(this->d, k)), ref, kFdTol)) << "frame " << k;
    }
  }
}

// J̇v = d/dt (J v) − J q̈ along q(t) with constant q̈ = a:
// q(±eps) = q ⊕ (±eps v + ½ eps² a) is exact to O(eps³), v(±eps) = v ± eps a.
TYPED_TEST(ModelProperties, FrameBiasAccelerationMatchesFiniteDifferences) {
  using R = TypeParam;
  typename hm::Data<R>::Jacobian Jp, Jm, J;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    const VecV<R> a = this->v();
    const VecV<R> vp = v + kEps * a;
    const VecV<R> vm = v - kEps * a;
    const VecV<R> dq = kEps * v + 0.5 * kEps * kEps * a;
    const auto qp = hm::integrate<R>(q, dq, 1.0);
    const auto qm = hm::integrate<R>(q, VecV<R>(-kEps * v + 0.5 * kEps * kEps * a), 1.0);
    for (int k = 0; k < R::nframes; ++k) {
      hm::forwardKinematics(this->d, qp, vp);
      hm::frameJacobian(this->d, k, Jp);
      hm::forwardKinematics(this->d, qm, vm);
      hm::frameJacobian(this->d, k, Jm);
      hm::forwardKinematics(this->d, q, v);
      hm::frameJacobian(this->d, k, J);
      const Vector6d ref = (Jp * vp - Jm * vm) / (2 * kEps) - J * a;
      EXPECT_TRUE(near(Vector6d(hm::frameBiasAcceleration(this->d, k)), ref, kFdTol))
          << "frame " << k;
    }
  }
}

// CoM equals the mass-weighted body CoMs; Jcom v and vcom equal its finite
// difference; Jcom is the linear block of A_G over the mass.
TYPED_TEST(ModelProperties, CenterOfMass) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    hm::centerOfMass(this->d, q, v);
    EXPECT_TRUE(near(this->d.com, model_test::systemCom<R>(model_test::chainPoses<R>(q)), kTol));
    const Eigen::Vector3d vref =
        (model_test::systemCom<R>(model_test::chainPoses<R>(hm::integrate<R>(q, v, kEps))) -
         model_test::systemCom<R>(model_test::chainPoses<R>(hm::integrate<R>(q, v, -kEps)))) /
        (2 * kEps);
    EXPECT_TRUE(near(Eigen::Vector3d(this->d.Jcom * v), vref, kFdTol));
    EXPECT_TRUE(near(this->d.vcom, vref, kFdTol));
  }
}

// A_G v equals [P; L_G] summed over bodies from finite-difference velocities;
// Ȧ_G v = d/dt (A_G v) − A_G q̈ by finite differences along constant q̈.
TYPED_TEST(ModelProperties, CentroidalMomentum) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    const VecV<R> a = this->v();
    hm::centroidalMomentum(this->d, q, v);
    const typename hm::Data<R>::Jacobian Ag = this->d.Ag;
    const Vector6d dAg_v = this->d.dAg_v;
    const auto bm = model_test::fdBodyMotion<R>(q, v, kEps);
    EXPECT_TRUE(near(Vector6d(Ag * v), model_test::centroidalMomentum<R>(bm), kFdTol));
    const typename hm::Data<R>::Matrix3V Jcom_ref = Ag.template topRows<3>() / this->d.mass;
    EXPECT_TRUE(near(this->d.Jcom, Jcom_ref, kTol));

    const VecV<R> vp = v + kEps * a;
    const VecV<R> vm = v - kEps * a;
    const auto qp = hm::integrate<R>(q, VecV<R>(kEps * v + 0.5 * kEps * kEps * a), 1.0);
    const auto qm = hm::integrate<R>(q, VecV<R>(-kEps * v + 0.5 * kEps * kEps * a), 1.0);
    hm::centroidalMomentum(this->d, qp, vp);
    const Vector6d hp = this->d.Ag * vp;
    hm::centroidalMomentum(this->d, qm, vm);
    const Vector6d hmn = this->d.Ag * vm;
    EXPECT_TRUE(near(dAg_v, Vector6d((hp - hmn) / (2 * kEps) - Ag * a), kFdTol));
  }
}

// RobotDynamics::calcWbcDependence gives the same numbers as the separate
// algorithms (it fuses them into one sweep pair).
TYPED_TEST(ModelProperties, RobotDynamicsMatchesFreeFunctions) {
  using R = TypeParam;
  constexpr int nf = R::nframes < 3 ? R::nframes : 3;
  std::array<int, nf> fr{};
  for (int k = 0; k < nf; ++k) fr[k] = R::nframes - 1 - k;
  hm::RobotDynamics<R, nf> dyn(fr);
  ASSERT_TRUE(dyn.valid());
  typename hm::Data<R>::Jacobian J;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    dyn.calcWbcDependence(q, v);
    hm::crba(this->d, q);
    EXPECT_TRUE(near(dyn.M(), this->d.M, kTol));
    hm::centroidalMomentum(this->d, q, v);
    EXPECT_TRUE(near(dyn.h(), this->d.h, kTol));
    EXPECT_TRUE(near(dyn.Ag(), this->d.Ag, kTol));
    EXPECT_TRUE(near(dyn.dAg_v(), this->d.dAg_v, kTol));
    EXPECT_TRUE(near(dyn.com(), this->d.com, kTol));
    EXPECT_TRUE(near(dyn.vcom(), this->d.vcom, kTol));
    EXPECT_TRUE(near(dyn.Jcom(), this->d.Jcom, kTol));
    EXPECT_DOUBLE_EQ(dyn.mass(), this->d.mass);
    hm::forwardKinematics(this->d, q, v);
    for (int k = 0; k < nf; ++k) {
      hm::frameJacobian(this->d, fr[k], J);
      EXPECT_TRUE(near(dyn.J(k), J, kTol));
      EXPECT_TRUE(near(dyn.dJv(k), hm::frameBiasAcceleration(this->d, fr[k]), kTol));
      EXPECT_TRUE(near(dyn.velocity(k), hm::frameVelocity(this->d, fr[k]), kTol));
      EXPECT_TRUE(
          near(dyn.placement(k).matrix(), hm::framePlacement(this->d, fr[k]).matrix(), kTol));
    }
  }
}

// integrate: q ⊕ 0 = q; a unit quaternion stays unit; q ⊕ v dt ⊕ v (−dt) = q.
TYPED_TEST(ModelProperties, IntegrateRoundTrip) {
  using R = TypeParam;
  for (int s = 0; s < kStates; ++s) {
    const auto q = this->q();
    const auto v = this->v();
    EXPECT_TRUE(near(hm::integrate<R>(q, VecV<R>::Zero(), 1.0), q, 1e-15));
    const auto q1 = hm::integrate<R>(q, v, 0.3);
    if constexpr (R::floating_base) {
      EXPECT_NEAR(q1.template segment<4>(3).norm(), 1.0, 1e-14);
    }
    const auto q2 = hm::integrate<R>(q1, v, -0.3);
    // The quaternion may come back with either sign; compare placements.
    const auto X0 = model_test::chainPoses<R>(q);
    const auto X2 = model_test::chainPoses<R>(q2);
    for (int i = 0; i < R::nb; ++i) EXPECT_TRUE(near(X2[i].matrix(), X0[i].matrix(), kTol));
  }
}

}  // namespace
