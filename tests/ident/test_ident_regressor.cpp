// The regressor τ = Y(q, q̇, q̈) π (include/model/regressor.hpp) and the base
// parameters (include/ident/base_parameters.hpp), on Walker3 (floating), the
// legs of Walker3 on a fixed torso, the quadruped and two random trees
// (floating and fixed base). References:
//  - the RNEA of include/model/rnea.hpp (tested against MuJoCo and finite
//    differences in tests/model and tests/mujoco), run with the CAD parameters
//    AND with random physical parameters written into Data, so that every
//    column of Y is checked, not just their sum at one π;
//  - eq. 7 written out here, and tasks::frictionTorque of the controller;
//  - the numerical rank of stacked regressors by an SVD (not the QR under test).
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include <Eigen/SVD>

#include "ident/base_parameters.hpp"
#include "model/regressor.hpp"
#include "model/rnea.hpp"
#include "model/support/model_reference.hpp"
#include "ident_walker3_fixed_model.hpp"
#include "quadruped_model.hpp"
#include "random_tree0_model.hpp"
#include "random_tree4_model.hpp"
#include "walker3_model.hpp"

#if __has_include("tasks/friction_model.hpp")
#include "tasks/friction_model.hpp"
#define IDENT_HAVE_TASKS_FRICTION 1
#endif

namespace {

namespace hm = hqp::model;
namespace hi = hqp::ident;

template <class Robot>
using Params = hm::ParameterVector<Robot>;

// Random physically consistent inertial parameters: mass in [0.5, 5], CoM in a
// 0.2 m cube, principal moments satisfying the triangle inequality, random axes.
template <class Robot>
void randomizeBodies(hm::Data<Robot>& d, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < Robot::nb; ++i) {
    d.body_mass[i] = 2.75 + 2.25 * u(rng);
    d.body_com[i] = 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const double a = 0.02 + 0.01 * u(rng), b = 0.02 + 0.01 * u(rng);
    const double c = std::abs(a - b) + (a + b - std::abs(a - b)) * 0.5 * (1.0 + u(rng));
    const Eigen::Matrix3d R =
        Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    d.body_inertia[i] = R * Eigen::Vector3d(a, b, c).asDiagonal() * R.transpose();
    d.inertia_diagonal[i] = false;
  }
}

// π of the bodies in d (independent of nominalParameters: built from Data).
template <class Robot>
Params<Robot> parametersOf(const hm::Data<Robot>& d) {
  Params<Robot> p = Params<Robot>::Zero();
  for (int i = 0; i < Robot::nb; ++i) {
    const double m = d.body_mass[i];
    const Eigen::Vector3d c = d.body_com[i];
    // Steiner about the origin: I_O = I_c − m S(c)².
    const Eigen::Matrix3d I = d.body_inertia[i] - m * hm::skew(c) * hm::skew(c);
    p.template segment<10>(10 * i) << m, m * c.x(), m * c.y(), m * c.z(), I(0, 0), I(1, 1),
        I(2, 2), I(0, 1), I(0, 2), I(1, 2);
  }
  return p;
}

template <class Robot>
class Regressor : public ::testing::Test {
 protected:
  std::mt19937 rng{4321u + static_cast<unsigned>(Robot::nv)};
  hm::Data<Robot> d;          // the RNEA reference
  hm::Data<Robot> dy;         // scratch of the regressor
  hm::RegressorMatrix<Robot> Y;
  hm::JointVector<Robot> dq_star = hm::JointVector<Robot>::Constant(0.05);
  using VQ = typename hm::Data<Robot>::VectorQ;
  using VV = typename hm::Data<Robot>::VectorV;
  void state(VQ& q, VV& v, VV& a) {
    q = model_test::randomConfiguration<Robot>(rng);
    v = model_test::randomVelocity<Robot>(rng);
    a = model_test::randomVelocity<Robot>(rng);
  }
};

using Robots = ::testing::Types<walker3::Robot, walker3_fixed::Robot, quadruped::Robot,
                                random_tree0::Robot, random_tree4::Robot>;
TYPED_TEST_SUITE(Regressor, Robots);

// Y π = τ_RNEA to 1e-10 with the CAD parameters (friction set to zero).
TYPED_TEST(Regressor, MatchesRneaWithCadParameters) {
  using R = TypeParam;
  using Sizes = hm::RegressorSizes<R>;
  Params<R> pi = hm::nominalParameters<R>();
  pi.template tail<Sizes::n_friction>().setZero();
  // nominalParameters against the description, through Data (independent path).
  EXPECT_LE((pi.template head<Sizes::n_inertial>() -
             parametersOf<R>(this->d).template head<Sizes::n_inertial>())
                .norm(),
            1e-12);
  typename TestFixture::VQ q;
  typename TestFixture::VV v, a;
  for (int s = 0; s < 100; ++s) {
    this->state(q, v, a);
    hm::rnea<R>(this->d, q, v, a);
    hm::computeRegressor<R>(this->dy, q, v, a, this->dq_star, this->Y);
    const typename TestFixture::VV tau = this->Y * pi;
    ASSERT_LE((tau - this->d.tau).norm(), 1e-10 * (1.0 + this->d.tau.norm())) << "state " << s;
  }
}

// Every column: random physical parameters in the RNEA's Data, at random states.
TYPED_TEST(Regressor, MatchesRneaWithRandomParameters) {
  using R = TypeParam;
  typename TestFixture::VQ q;
  typename TestFixture::VV v, a;
  for (int s = 0; s < 50; ++s) {
    randomizeBodies<R>(this->d, this->rng);
    const Params<R> pi = parametersOf<R>(this->d);
    this->state(q, v, a);
    hm::rnea<R>(this->d, q, v, a);
    hm::computeRegressor<R>(this->dy, q, v, a, this->dq_star, this->Y);
    const typename TestFixture::VV tau = this->Y * pi;
    ASSERT_LE((tau - this->d.tau).norm(), 1e-10 * (1.0 + this->d.tau.norm())) << "state " << s;
  }
}

// Friction columns: eq. 7 written out, and the controller's frictionTorque.
TYPED_TEST(Regressor, FrictionColumnsFollowEquation7) {
  using R = TypeParam;
  using Sizes = hm::RegressorSizes<R>;
  constexpr int first = R::floating_base ? 1 : 0;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  typename TestFixture::VQ q;
  typename TestFixture::VV v, a;
  for (int s = 0; s < 200; ++s) {
    this->state(q, v, a);
    // Also hit the band |q̇| ≤ q̇* and its edges.
    for (int j = 0; j < R::nj; ++j) {
      const int row = first * 6 + j;
      if (s % 4 == 1) v[row] = 0.05 * u(this->rng);
      if (s % 4 == 2) v[row] = (j % 2 ? 0.05 : -0.05);
      if (s % 4 == 3) v[row] = 0.0;
    }
    hm::computeRegressor<R>(this->dy, q, v, a, this->dq_star, this->Y);
    for (int j = 0; j < R::nj; ++j) {
      const int row = first * 6 + j;
      const double Fc = 1.0 + 4.0 * 0.5 * (1.0 + u(this->rng)), Fv = 0.5 + u(this->rng) * 0.4;
      const double dq = v[row], qs = this->dq_star[j];
      double expected;
      if (dq >= qs) {
        expected = Fc + Fv * (dq - qs);
      } else if (dq <= -qs) {
        expected = -Fc + Fv * (dq + qs);
      } else {
        expected = Fc * dq / qs;
      }
      const double got = this->Y(row, Sizes::frictionColumn(j)) * Fc +
                         this->Y(row, Sizes::frictionColumn(j) + 1) * Fv;
      ASSERT_NEAR(got, expected, 1e-12) << "joint " << j << " dq " << dq;
#ifdef IDENT_HAVE_TASKS_FRICTION
      ASSERT_NEAR(got, hqp::tasks::frictionTorque(hqp::tasks::JointFriction{Fc, Fv, qs}, dq), 1e-12);
#endif
      // Friction acts on its own joint only.
      for (int r = 0; r < R::nv; ++r) {
        if (r != row) {
          ASSERT_EQ(this->Y(r, Sizes::frictionColumn(j)), 0.0);
        }
      }
    }
  }
}

// The QR's base parameters: rank = SVD rank of an independent stack, and
// Y π = Y_B K π for random π at new states.
TYPED_TEST(Regressor, BaseParametersReproduceTheRegressor) {
  using R = TypeParam;
  using Sizes = hm::RegressorSizes<R>;
  const hi::BaseParameters bp = hi::computeBaseParameters<R>(this->dq_star, 11u);
  const Eigen::MatrixXd W = hi::stackRandomRegressors<R>(4 * Sizes::np / R::nv + 10, 99u,
                                                         this->dq_star);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(W);
  const Eigen::VectorXd sv = svd.singularValues();
  int rank = 0;
  for (Eigen::Index k = 0; k < sv.size(); ++k) rank += sv[k] > 1e-9 * sv[0];
  EXPECT_EQ(bp.rank, rank);
  std::printf("[ %s ] %d bodies, %d joints, %d parameters, %d base parameters\n", R::name, R::nb,
              R::nj, Sizes::np, bp.rank);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  typename TestFixture::VQ q;
  typename TestFixture::VV v, a;
  for (int s = 0; s < 20; ++s) {
    Eigen::VectorXd pi(Sizes::np);
    for (int k = 0; k < Sizes::np; ++k) pi[k] = u(this->rng);
    this->state(q, v, a);
    hm::computeRegressor<R>(this->dy, q, v, a, this->dq_star, this->Y);
    const Eigen::VectorXd full = this->Y * pi;
    const Eigen::VectorXd base = bp.reduce(this->Y) * (bp.K * pi);
    ASSERT_LE((full - base).norm(), 1e-8 * (1.0 + full.norm()));
  }
}

TYPED_TEST(Regressor, DoesNotAllocate) {
  using R = TypeParam;
  typename TestFixture::VQ q;
  typename TestFixture::VV v, a;
  this->state(q, v, a);
  Eigen::internal::set_is_malloc_allowed(false);
  hm::computeRegressor<R>(this->dy, q, v, a, this->dq_star, this->Y);
  Eigen::internal::set_is_malloc_allowed(true);
  SUCCEED();
}

// The count for Walker3's legs on a fixed torso (12 bodies, 144 parameters).
// Independent count (regrouping rules of Khalil & Dombre, "Modeling,
// identification and control of robots", ch. 12): a revolute joint lets 3 of
// its link's 10 parameters be regrouped into the parent (7 remain), and the
// first link of each leg turns about the vertical through the fixed torso, so
// only its inertia about that axis acts: 1 + 7·5 = 36 per leg; friction adds
// 2 per joint: 2·36 + 24 = 96. The SVD rank in the typed test above agrees.
TEST(Walker3Legs, BaseParameterCount) {
  using R = walker3_fixed::Robot;
  const hi::BaseParameters bp =
      hi::computeBaseParameters<R>(hm::JointVector<R>::Constant(0.01), 3u);
  std::printf("[ walker3 legs ] base parameters: %d of %d\n", bp.rank, hm::RegressorSizes<R>::np);
  EXPECT_EQ(bp.rank, 2 * (1 + 7 * 5) + 24);
}

}  // namespace
