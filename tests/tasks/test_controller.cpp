// Controller::tick() end to end on Walker3: quiet standing against an independent gravity
// compensation (RNEA + static equilibrium), the safe mode on NaN input, on a fall and its latch,
// and no heap use in the tick (Eigen's no-malloc guard plus a counting operator new).
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <sstream>
#include <string>

#include <unistd.h>

#include "model/rnea.hpp"
#include "tasks/cop_constraint.hpp"
#include "support/walker3_controller.hpp"
#include "support/walker3_standing.hpp"
#include "support/allocation_counter.hpp"

using hqp::testing::g_counting;
using hqp::testing::g_news;

namespace {

using Robot = walker3::Robot;
using Layout = hqp::tasks::ContactLayout<Robot, 2, 6>;
using Controller = hqp::testing::Walker3Controller;
using hqp::testing::makeWalker3Controller;
using hqp::testing::walker3Config;
using hqp::tasks::ControllerMode;
using hqp::tasks::SafeModeReason;

constexpr double kG = 9.81;

// τ that holds the robot at rest with m g / 2 straight up at each sole centre:
// S_a (G − Σ_c J_cᵀ F_c), from RNEA (q̈ = 0, v = 0) and the model's sole Jacobians.
Eigen::Matrix<double, 12, 1> gravityCompensation(const hqp::testing::Walker3Standing& s) {
  hqp::model::Data<Robot> d;
  const Eigen::Matrix<double, Robot::nv, 1> G = hqp::model::computeGravity<Robot>(d, s.q);
  auto dyn = hqp::testing::Walker3Standing::Dyn(hqp::testing::walker3StandingFrames());
  dyn.calcWbcDependence(s.q, s.v);
  Eigen::Matrix<double, Robot::nv, 1> tau = G;
  for (int c = 0; c < 2; ++c) {
    Eigen::Matrix<double, 6, 1> F = Eigen::Matrix<double, 6, 1>::Zero();
    F(2) = 0.5 * Robot::total_mass * kG;
    tau -= dyn.J(c).transpose() * F;
  }
  EXPECT_LT(tau.head<6>().norm(), 1e-9) << "the pose is not in static equilibrium";
  return tau.tail<12>();
}

class ControllerStanding : public ::testing::TestWithParam<Controller::Config::Solver> {};

TEST_P(ControllerStanding, TorquesAreGravityCompensationAndZmpAtSoleCentre) {
  const auto s = hqp::testing::walker3Standing();
  const double half = 0.5 * Robot::total_mass * kG;
  const auto sensors = hqp::testing::walker3RestingSensors(
      s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  auto ctrl = makeWalker3Controller(walker3Config(GetParam(), s.com_height));
  Controller::Command cmd;
  const auto tau_expected = gravityCompensation(s);
  for (int k = 0; k < 3; ++k) ctrl->tick(sensors, cmd);
  const auto& d = ctrl->diagnostics();
  ASSERT_EQ(d.mode, ControllerMode::Balance) << toString(d.reason);
  EXPECT_FALSE(cmd.safe_mode);
  const bool hqp = GetParam() == Controller::Config::Solver::Hqp;
  for (int p = 0; p < Controller::num_levels; ++p)
    EXPECT_EQ(d.levels[p].status, hqp::QpStatus::Optimal) << "level " << p;
  // τ_opt: S_a(M q̈* + h − Jᵀ F*) with q̈* ≈ 0 and F* = m g / 2 at the sole centres. The
  // weighted QP trades levels at a finite ratio, so it gets a looser bound.
  const double tol = hqp ? 1e-6 : 1e-2;
  const Eigen::Matrix<double, 12, 1> tau_opt = hqp::tasks::jointTorque<Layout>(ctrl->dynamics(), ctrl->solution());
  EXPECT_LT((tau_opt - tau_expected).cwiseAbs().maxCoeff(), tol)
      << "tau_opt " << tau_opt.transpose() << "\nexpected " << tau_expected.transpose();
  // At rest the commanded torque is τ_opt up to friction and kinematic terms of ∫q̈* dt ≈ 0.
  EXPECT_LT((cmd.torque - tau_expected).cwiseAbs().maxCoeff(), 10 * tol);
  for (int j = 0; j < 12; ++j) {
    EXPECT_TRUE(std::isfinite(cmd.current(j)));
    EXPECT_NEAR(cmd.current(j) * ctrl->config().joint.torque_constant[j], cmd.torque(j),
                1e-9 * (1 + std::abs(cmd.torque(j))));
  }
  for (int c = 0; c < 2; ++c) {
    EXPECT_TRUE(d.in_contact[c]);
    EXPECT_LT(d.zmp_optimized[c].norm(), hqp ? 1e-6 : 1e-3) << d.zmp_optimized[c].transpose();
    EXPECT_LT(d.zmp_measured[c].norm(), 1e-9);
  }
  EXPECT_GT(d.time_us[static_cast<int>(hqp::tasks::Stage::Total)], 0.0);
  if (hqp) {  // per-level solve times are parts of the solve stage
    double levels_us = 0.0;
    for (int p = 0; p < Controller::num_levels; ++p) {
      EXPECT_GT(d.levels[p].time_us, 0.0) << "level " << p;
      levels_us += d.levels[p].time_us;
    }
    EXPECT_LE(levels_us, d.time_us[static_cast<int>(hqp::tasks::Stage::Solve)]);
  }
}

// The CoP rows' moment margin is capped by each foot's measured load (docs/tasks.md, "CoP moment
// margin"): the tick hands the F/T normal forces to the references, and the rows of a foot that
// carries f_z get the bound −min(δ, (y_max − y_min) f_z / 4).
TEST(ControllerCopMargin, MeasuredLoadsCapTheMomentMargin) {
  const auto s = hqp::testing::walker3Standing();
  const double weight = Robot::total_mass * kG, light = 20.0;
  const std::array<double, 2> load{weight - light, light};
  const auto sensors =
      hqp::testing::walker3RestingSensors(s, load, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  const auto cfg = walker3Config(Controller::Config::Solver::Hqp, s.com_height);
  const double delta = cfg.balance.cop_moment_margin;
  ASSERT_GT(delta, 0.0) << "the shipped Walker3 configuration has the margin on";
  const double capped = 0.25 * (cfg.balance.sole_y_max - cfg.balance.sole_y_min) * light;
  ASSERT_LT(capped, delta);
  const double expected[2] = {delta, capped};
  auto ctrl = makeWalker3Controller(cfg);
  Controller::Command cmd;
  for (int k = 0; k < 3; ++k) ctrl->tick(sensors, cmd);
  ASSERT_EQ(ctrl->diagnostics().mode, ControllerMode::Balance) << toString(ctrl->diagnostics().reason);
  for (int c = 0; c < 2; ++c) EXPECT_NEAR(ctrl->references().contact_load[c], load[c], 1e-9) << "foot " << c;
  // Both solvers hold a CoP constraint; only the ticked one (HqpWbc) was updated.
  int seen = 0, capped_rows = 0;
  ctrl->configureItems<hqp::tasks::CopConstraint<Layout>>([&](const auto& cop) {
    ++seen;
    int rows = 0;
    for (int c = 0; c < 2; ++c)
      for (int r = 0; r < 4; ++r) rows += std::abs(cop.upper(4 * c + r) + expected[c]) < 1e-12;
    if (rows > 0) capped_rows = rows;
  });
  EXPECT_EQ(seen, 2);
  EXPECT_EQ(capped_rows, 8);
}

INSTANTIATE_TEST_SUITE_P(Solvers, ControllerStanding,
                         ::testing::Values(Controller::Config::Solver::Hqp,
                                           Controller::Config::Solver::Wqp));

TEST(ControllerSafeMode, NanSensorLatchesSafeModeWithFiniteCurrents) {
  const auto s = hqp::testing::walker3Standing();
  const double half = 0.5 * Robot::total_mass * kG;
  const auto good = hqp::testing::walker3RestingSensors(
      s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  auto ctrl = makeWalker3Controller(walker3Config(Controller::Config::Solver::Hqp, s.com_height));
  Controller::Command cmd;
  ctrl->tick(good, cmd);
  ASSERT_EQ(ctrl->diagnostics().mode, ControllerMode::Balance);
  const Eigen::Matrix<double, 12, 1> tau_good = cmd.torque;

  for (int field = 0; field < 4; ++field) {
    auto bad = good;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (field == 0) bad.q(3) = nan;
    if (field == 1) bad.dq(7) = std::numeric_limits<double>::infinity();
    if (field == 2) bad.imu_gyro.y() = nan;
    if (field == 3) bad.ft[1](2) = nan;
    ctrl->reset();
    ctrl->tick(good, cmd);
    ASSERT_EQ(ctrl->diagnostics().mode, ControllerMode::Balance);
    ctrl->tick(bad, cmd);
    EXPECT_EQ(ctrl->diagnostics().mode, ControllerMode::Safe) << field;
    EXPECT_EQ(ctrl->diagnostics().reason, SafeModeReason::NonFiniteSensor) << field;
    EXPECT_TRUE(cmd.safe_mode);
    EXPECT_TRUE(cmd.current.allFinite()) << field;
    EXPECT_TRUE(cmd.torque.allFinite()) << field;
    // At rest the safe mode holds the last good torques (damping acts on q̇ = 0 ... or on the last
    // finite q̇ where the reading is bad).
    EXPECT_LT((cmd.torque - tau_good).cwiseAbs().maxCoeff(), 1e-6) << field;
    // Latched: good data does not bring the controller back; reset() does.
    ctrl->tick(good, cmd);
    EXPECT_EQ(ctrl->diagnostics().mode, ControllerMode::Safe);
    EXPECT_TRUE(cmd.safe_mode);
  }
  ctrl->reset();
  ctrl->tick(good, cmd);
  EXPECT_EQ(ctrl->diagnostics().mode, ControllerMode::Balance);
  EXPECT_FALSE(cmd.safe_mode);
}

TEST(ControllerSafeMode, SafeModeDampsJointMotion) {
  const auto s = hqp::testing::walker3Standing();
  const double half = 0.5 * Robot::total_mass * kG;
  auto sensors = hqp::testing::walker3RestingSensors(
      s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  auto ctrl = makeWalker3Controller(walker3Config(Controller::Config::Solver::Hqp, s.com_height));
  Controller::Command cmd;
  ctrl->tick(sensors, cmd);
  const Eigen::Matrix<double, 12, 1> tau_good = cmd.torque;
  auto bad = sensors;
  bad.q(0) = std::numeric_limits<double>::quiet_NaN();
  ctrl->tick(bad, cmd);
  ASSERT_TRUE(cmd.safe_mode);
  sensors.dq.setConstant(0.5);
  ctrl->tick(sensors, cmd);
  const double d = ctrl->config().safe.damping;
  ASSERT_GT(d, 0.0);
  for (int j = 0; j < 12; ++j) {
    const double lim = ctrl->config().joint.current_limit[j] * ctrl->config().joint.torque_constant[j];
    const double expected = std::clamp(tau_good(j) - d * 0.5, -lim, lim);
    EXPECT_NEAR(cmd.torque(j), expected, 1e-9) << j;
  }
}

TEST(ControllerSafeMode, FallDetectedFromTorsoTilt) {
  const auto s = hqp::testing::walker3Standing();
  const double half = 0.5 * Robot::total_mass * kG;
  auto sensors = hqp::testing::walker3RestingSensors(
      s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  auto ctrl = makeWalker3Controller(walker3Config(Controller::Config::Solver::Hqp, s.com_height));
  Controller::Command cmd;
  ctrl->tick(sensors, cmd);
  ASSERT_EQ(ctrl->diagnostics().mode, ControllerMode::Balance);
  const double tilt = ctrl->config().safe.max_tilt + 0.1;
  sensors.imu_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY())) *
                            sensors.imu_orientation;
  ctrl->tick(sensors, cmd);
  EXPECT_EQ(ctrl->diagnostics().mode, ControllerMode::Safe);
  EXPECT_EQ(ctrl->diagnostics().reason, SafeModeReason::Fallen);
  EXPECT_TRUE(cmd.current.allFinite());
}

// The shipped controller.yaml with `from` replaced by `to`, loaded; solver and C as walker3Config.
Controller::Config editedConfig(const std::string& from, const std::string& to, Controller::Config::Solver solver,
                                double com_height) {
  std::ifstream in(HQP_SOURCE_DIR "/robots/walker3/controller.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  const std::string path = ::testing::TempDir() + "qp_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << text;
  auto cfg = hqp::tasks::loadControllerConfig<Robot>(path);
  std::remove(path.c_str());
  cfg.solver = solver;
  cfg.planner.com_height = com_height;
  return cfg;
}

// The `qp` keys reach the solvers: a magnitude bound below the robot's mass (M's base block holds
// the total mass, 43 kg) makes each solver refuse the problem as invalid input (safe mode), and
// dual_last_level and defer_constraints decide how HqpWbc solves its levels.
TEST(ControllerQpSettings, YamlValuesReachTheSolvers) {
  const auto s = hqp::testing::walker3Standing();
  const double half = 0.5 * Robot::total_mass * kG;
  const auto sensors = hqp::testing::walker3RestingSensors(
      s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  using Solver = Controller::Config::Solver;
  ASSERT_GT(Robot::total_mass, 1.0);
  Controller::Command cmd;
  {
    auto ctrl = makeWalker3Controller(
        editedConfig("max_magnitude: 1.0e50", "max_magnitude: 1.0", Solver::Hqp, s.com_height));
    EXPECT_EQ(ctrl->hqp().settings().qp.max_magnitude, 1.0);
    ctrl->tick(sensors, cmd);
    EXPECT_EQ(ctrl->diagnostics().levels[0].status, hqp::QpStatus::InvalidInput);
    EXPECT_EQ(ctrl->diagnostics().reason, SafeModeReason::SolverFailure);
  }
  {
    auto ctrl = makeWalker3Controller(
        editedConfig("    max_magnitude: 1.0e50\n    warm_start: true", "    max_magnitude: 1.0\n    warm_start: true",
                     Solver::Wqp, s.com_height));
    ctrl->tick(sensors, cmd);
    EXPECT_EQ(ctrl->diagnostics().status, hqp::QpStatus::InvalidInput);
    EXPECT_EQ(ctrl->diagnostics().reason, SafeModeReason::SolverFailure);
  }
  for (bool dual : {true, false}) {
    auto ctrl = makeWalker3Controller(editedConfig("dual_last_level: true", dual ? "dual_last_level: true"
                                                                                 : "dual_last_level: false",
                                                   Solver::Hqp, s.com_height));
    EXPECT_EQ(ctrl->hqp().settings().qp.max_iterations, 100);
    ctrl->tick(sensors, cmd);
    ASSERT_EQ(ctrl->diagnostics().mode, ControllerMode::Balance);
    EXPECT_EQ(ctrl->hqp().result().levels[Controller::num_levels - 1].dual, dual);
  }
  // Standing at rest, every level above the last reaches its unconstrained minimum within the
  // limits: the deferred path holds when it is on, and the cascade gives the same command.
  std::array<Eigen::VectorXd, 2> tau;
  for (bool defer : {true, false}) {
    auto ctrl = makeWalker3Controller(editedConfig("defer_constraints: true", defer ? "defer_constraints: true"
                                                                                     : "defer_constraints: false",
                                                   Solver::Hqp, s.com_height));
    EXPECT_EQ(ctrl->hqp().settings().defer_constraints, defer);
    ctrl->tick(sensors, cmd);
    ASSERT_EQ(ctrl->diagnostics().mode, ControllerMode::Balance);
    EXPECT_EQ(ctrl->hqp().result().deferred, defer);
    tau[defer ? 0 : 1] = cmd.torque;
  }
  EXPECT_LT((tau[0] - tau[1]).lpNorm<Eigen::Infinity>(), 1e-9 * std::max(1.0, tau[1].lpNorm<Eigen::Infinity>()));
}

TEST(ControllerNoAlloc, TickDoesNotAllocate) {
  const auto s = hqp::testing::walker3Standing();
  const double half = 0.5 * Robot::total_mass * kG;
  for (auto solver : {Controller::Config::Solver::Hqp, Controller::Config::Solver::Wqp}) {
    auto ctrl = makeWalker3Controller(walker3Config(solver, s.com_height));
    Controller::Command cmd;
    // Uneven loads and off-centre CoPs, so that constraints become active and warm starts change.
    std::array<hqp::tasks::SensorData<12, 2>, 4> inputs = {
        hqp::testing::walker3RestingSensors(s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()}),
        hqp::testing::walker3RestingSensors(s, {1.4 * half, 0.6 * half},
                                            {Eigen::Vector2d(0.09, 0.0), Eigen::Vector2d(-0.05, 0.03)}),
        hqp::testing::walker3RestingSensors(s, {0.5 * half, 1.5 * half},
                                            {Eigen::Vector2d(0.105, 0.045), Eigen::Vector2d(0.0, -0.04)}),
        hqp::testing::walker3RestingSensors(s, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()})};
    inputs[3].dq.setConstant(0.3);
    ctrl->tick(inputs[0], cmd);  // first tick initialises the planner and ∫q̈ dt
    g_news = 0;
    g_counting = true;
    Eigen::internal::set_is_malloc_allowed(false);
    for (int k = 0; k < 40; ++k) ctrl->tick(inputs[k % 4], cmd);
    auto bad = inputs[0];
    bad.ft[0](0) = std::numeric_limits<double>::quiet_NaN();
    ctrl->tick(bad, cmd);  // into the safe mode
    ctrl->tick(inputs[0], cmd);
    Eigen::internal::set_is_malloc_allowed(true);
    g_counting = false;
    EXPECT_EQ(g_news.load(), 0);
    EXPECT_EQ(ctrl->diagnostics().mode, ControllerMode::Safe);
  }
  // The counter works: an allocation while counting is seen.
  g_counting = true;
  auto* v = new std::vector<int>(10);
  g_counting = false;
  EXPECT_GE(g_news.load(), 1);
  delete v;
}

}  // namespace
