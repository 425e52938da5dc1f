// Adding a task to Walker3's hierarchy as docs/adding-a-task.md says: a joint-posture task (its
// class and a hierarchy definition, both in this file) in a new level between the linear momentum
// (level 3) and the torso/force level, run by the unchanged Controller. Checked: levels 1–3 keep
// the residuals Table I gives on the same data (strict priorities), and the new level reaches
// the least-squares optimum of its task over the set levels 1–3 leave free, computed here with
// dense SVD / LU (not the hierarchy's null-space code). Table I is solved by a bare HqpWbc on the
// controller's own level data rather than by a second Controller (half the compile time).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <memory>

#include "support/walker3_controller.hpp"
#include "support/walker3_standing.hpp"
#include "tasks/balance_hierarchy.hpp"
#include "tasks/controller.hpp"

namespace {

using Robot = walker3::Robot;
using Layout = hqp::tasks::ContactLayout<Robot, 2, 6>;

// q̈_j = kp (q_ref − q_j) − kd q̇_j on every joint: A = [0 I 0], b as above.
template <class L>
class JointPostureTask : public hqp::Task<L::nj, L::nx> {
 public:
  static constexpr int nj = L::nj;
  using VectorJ = Eigen::Matrix<double, nj, 1>;
  VectorJ q_ref = VectorJ::Zero();
  hqp::tasks::PdGains gains{100.0, 20.0};

  JointPostureTask() {
    this->name = "joint_posture";
    this->A.template middleCols<nj>(6).setIdentity();
  }
  // Takes the estimated state (the third argument): q is not in the dynamics object.
  template <class Dyn, class State>
  void update(const Dyn&, const hqp::tasks::References<L::num_contacts>&, const State& s) noexcept {
    error_ = q_ref - s.q.template tail<nj>();
    this->b = gains.kp * error_ - gains.kd * s.v.template tail<nj>();
  }
  const VectorJ& error() const { return error_; }

 private:
  VectorJ error_ = VectorJ::Zero();
};

template <class L>
using PostureLevel = hqp::Level<L::nx, hqp::TaskList<JointPostureTask<L>>>;

// Table I with the posture level inserted before the torso/force level. (As a new lowest level it
// could not act on Walker3: level 4 already uses the last 9 free dimensions.)
struct PostureHierarchy {
  template <class L>
  using Levels = hqp::tasks::LevelList<hqp::tasks::BalanceLevel1<L>, hqp::tasks::BalanceLevel2<L>,
                                       hqp::tasks::BalanceLevel3<L>, PostureLevel<L>,
                                       hqp::tasks::BalanceLevel4<L>>;
};

using TableI = hqp::tasks::BalanceHqp<Layout>;
using WithPosture = hqp::tasks::Controller<Layout, PostureHierarchy>;
static_assert(WithPosture::num_levels == 5, "the new level counts");
static_assert(WithPosture::Hqp::LevelType<3>::task_rows == Robot::nj, "its rows come from the task");
static_assert(WithPosture::Hierarchy::error_rows ==
                  hqp::tasks::Hierarchy<hqp::tasks::BalanceHierarchy, Layout>::error_rows + Robot::nj,
              "its error is reported");

template <class C>
std::unique_ptr<C> make(const typename C::Config& cfg) {
  using R = Robot;
  return std::make_unique<C>(cfg, std::array<int, 2>{R::Frames::l_sole, R::Frames::r_sole},
                             std::array<int, 2>{R::Frames::l_ft_sensor, R::Frames::r_ft_sensor}, R::Frames::imu);
}

TEST(HierarchyExtension, PostureLevelKeepsHigherLevelsAndIsOptimalInTheirNullSpace) {
  const auto s = hqp::testing::walker3Standing();
  const double half = 0.5 * Robot::total_mass * 9.81;
  const auto sensors = hqp::testing::walker3RestingSensors(
      s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  const auto cfg = hqp::testing::walker3Config(WithPosture::Config::Solver::Hqp, s.com_height);
  auto b = make<WithPosture>(cfg);
  // A reference 0.1 rad away on knees and hips: the posture level has something to do.
  Eigen::Matrix<double, Robot::nj, 1> offset = Eigen::Matrix<double, Robot::nj, 1>::Zero();
  for (int j : {Robot::Joints::l_knee, Robot::Joints::r_knee}) offset(j) = 0.1;
  for (int j : {Robot::Joints::l_hip_pitch, Robot::Joints::r_hip_pitch}) offset(j) = -0.05;
  const Eigen::Matrix<double, Robot::nj, 1> q_ref = sensors.q + offset;
  b->configureItems<JointPostureTask<Layout>>([&](JointPostureTask<Layout>& t) { t.q_ref = q_ref; });

  WithPosture::Command cb;
  b->tick(sensors, cb);
  const auto& db = b->diagnostics();
  ASSERT_EQ(db.mode, hqp::tasks::ControllerMode::Balance) << toString(db.reason);
  for (int p = 0; p < WithPosture::num_levels; ++p) ASSERT_EQ(db.levels[p].status, hqp::QpStatus::Optimal) << p;
  const auto& h = b->hqp();

  // Table I on the same data (its levels are the same types): levels 1–3 keep their residuals.
  auto a = std::make_unique<TableI>(cfg.qp.hqp);
  a->level<0>() = h.level<0>();
  a->level<1>() = h.level<1>();
  a->level<2>() = h.level<2>();
  a->level<3>() = h.level<4>();
  ASSERT_EQ(a->solve(), hqp::QpStatus::Optimal);
  for (int p = 0; p < 3; ++p) {
    const double ra = a->result().levels[p].residual;
    EXPECT_NEAR(db.levels[p].residual, ra, 1e-9 * (1.0 + ra)) << p;
  }

  // The reference: the posture task's least-squares optimum over E x = e, the rows of levels 1–3
  // as equalities, ignoring the inequalities. When levels 1–3 are consistent and that optimum
  // meets every inequality (both checked below), it is the optimum with them too.
  constexpr int nx = Layout::nx;
  Eigen::MatrixXd E(6 + 12 + 3, nx);
  Eigen::VectorXd e(E.rows());
  E << h.level<0>().task<0>().A, h.level<1>().task<0>().A, h.level<2>().task<0>().A;
  e << h.level<0>().task<0>().b, h.level<1>().task<0>().b, h.level<2>().task<0>().b;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd_e(E, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd x0 = svd_e.solve(e);
  ASSERT_LT((E * x0 - e).norm(), 1e-9 * (1.0 + e.norm())) << "levels 1-3 are not consistent";
  const Eigen::MatrixXd N = Eigen::FullPivLU<Eigen::MatrixXd>(E).kernel();
  const Eigen::MatrixXd P = h.level<3>().task<0>().A;
  const Eigen::VectorXd pb = h.level<3>().task<0>().b;
  const Eigen::MatrixXd PN = P * N;
  const Eigen::VectorXd u = PN.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(pb - P * x0);
  const Eigen::VectorXd x_ref = x0 + N * u;
  const double best = (P * x_ref - pb).squaredNorm();
  const auto feasible = [&](const auto& c) {
    const Eigen::VectorXd d = c.D * x_ref;
    const double tol = 1e-9 * (1.0 + d.cwiseAbs().maxCoeff());
    return ((d.array() >= c.lower.array() - tol) && (d.array() <= c.upper.array() + tol)).all();
  };
  ASSERT_TRUE(feasible(h.level<0>().constraint<0>())) << "torque limits";
  ASSERT_TRUE(feasible(h.level<1>().constraint<0>())) << "CoP";
  ASSERT_TRUE(feasible(h.level<1>().constraint<1>())) << "friction";

  const Eigen::VectorXd xa = a->x(), xb = b->solution();
  const double with = (P * xb - pb).squaredNorm();
  const double without = (P * xa - pb).squaredNorm();
  EXPECT_NEAR(with, best, 1e-7 * (1.0 + best)) << "the posture level is not optimal in the null space";
  EXPECT_NEAR(db.levels[3].residual, best, 1e-7 * (1.0 + best));
  EXPECT_LT(with, 0.9 * without) << "the posture level changed nothing";
  // At rest the commanded joint accelerations turn toward the reference.
  EXPECT_GT(offset.dot(xb.segment<Robot::nj>(6)), 0.0);
  EXPECT_GT(offset.dot(xb.segment<Robot::nj>(6)), offset.dot(xa.segment<Robot::nj>(6)));

  // The diagnostics report the new level's error, q_ref − q.
  EXPECT_LT((db.levelTaskError(3) - offset).cwiseAbs().maxCoeff(), 1e-12);
  // The named balance errors are found wherever their level now is.
  EXPECT_EQ(db.torso_error, h.level<4>().task<0>().error());
  EXPECT_EQ(db.com_error, h.level<2>().task<0>().error());
}

}  // namespace
