// The same task library composed for the quadruped: four point contacts (CD = 3), level 2 =
// foot positions (12 rows) + friction pyramids with unilateral rows (20 rows), no CoP. In the
// nominal stance of robots/quadruped/README.md with references equal to the state, every level
// is optimal, the vertical forces carry the weight (Σ f_z = m g from total_mass, as the CoM
// must not accelerate), every f_z ≥ fz_min and every force lies in its pyramid (checked by hand).
// The planner for four feet: F_ref = m g / 4, the CoM reference over the mean foot position,
// and the torso reference equal to the upright imu frame (yawed by π/2 on this robot).
#include <gtest/gtest.h>

#include <cmath>

#include "model/configuration.hpp"
#include "tasks/balance_hierarchy.hpp"
#include "tasks/inverse_dynamics.hpp"
#include "tasks/task_planner.hpp"
#include "quadruped_model.hpp"

namespace {

using Robot = quadruped::Robot;
using Layout = hqp::tasks::ContactLayout<Robot, 4, 3>;
using Dyn = Layout::Dynamics;
using Hqp = hqp::tasks::BalanceHqp<Layout>;
using VectorQ = Eigen::Matrix<double, Robot::nq, 1>;
using VectorV = Eigen::Matrix<double, Robot::nv, 1>;
using VectorX = Eigen::Matrix<double, Layout::nx, 1>;

constexpr double kMass = 13.0;  // robots/quadruped/README.md
constexpr double kG = 9.81;

static_assert(Layout::nx == 30, "x = [q̈ (18); F (4 × 3)]");
static_assert(hqp::tasks::BalanceLevel2<Layout>::task_rows == 12, "foot positions");
static_assert(hqp::tasks::BalanceLevel2<Layout>::constraint_rows == 20, "4 × (4 pyramid + 1 unilateral)");
static_assert(hqp::tasks::BalanceLevel4<Layout>::task_rows == 15, "torso 3 + forces 12");

Dyn makeDynamics() {
  return Dyn({Robot::Frames::lf_foot, Robot::Frames::rf_foot, Robot::Frames::lh_foot,
              Robot::Frames::rh_foot, Robot::Frames::imu});
}

// Nominal stance (README): hfe 0.8 (rf −0.8, its axis is −y), kfe −1.6; feet on z = 0; at rest.
VectorQ nominalStance() {
  VectorQ q = hqp::model::neutralConfiguration<Robot>();
  for (int j : {Robot::Joints::lf_hfe, Robot::Joints::lh_hfe, Robot::Joints::rh_hfe}) q(7 + j) = 0.8;
  q(7 + Robot::Joints::rf_hfe) = -0.8;
  for (int j : {Robot::Joints::lf_kfe, Robot::Joints::rf_kfe, Robot::Joints::lh_kfe, Robot::Joints::rh_kfe})
    q(7 + j) = -1.6;
  q(2) = 0.306550952;  // README: base height with the foot frames at z = 0
  return q;
}

TEST(QuadrupedHierarchy, NominalStanceBalances) {
  Dyn dyn = makeDynamics();
  ASSERT_TRUE(dyn.valid());
  const VectorQ q = nominalStance();
  const VectorV v = VectorV::Zero();
  dyn.calcWbcDependence(q, v);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(dyn.placement(c).translation().z(), 0.0, 1e-8) << c;
  EXPECT_NEAR(dyn.placement(0).translation().x(), 0.204347, 1e-6);   // README: front feet
  EXPECT_NEAR(dyn.placement(2).translation().x(), -0.175653, 1e-6);  // hind feet

  hqp::tasks::References<4> refs;
  for (int c = 0; c < 4; ++c) {
    refs.contact_pose[c] = dyn.placement(c);
    refs.contact_velocity[c].setZero();
    refs.contact_force[c].setZero();
    refs.contact_force[c](2) = kMass * kG / 4.0;
  }
  refs.com = dyn.com();
  refs.torso_orientation = dyn.placement(4).linear();

  auto params = hqp::tasks::defaultBalanceParameters<Robot>();
  params.fz_min = 5.0;
  Hqp wbc;
  hqp::tasks::configureHierarchy(wbc, params);
  hqp::tasks::updateHierarchy(wbc, dyn, refs);
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  for (int p = 0; p < Hqp::num_levels; ++p)
    EXPECT_EQ(wbc.result().levels[p].status, hqp::QpStatus::Optimal) << "level " << p;
  // Levels 1–3 are met exactly (a static stance exists); level 4 is a compromise.
  for (int p = 0; p < 3; ++p)
    EXPECT_LT(wbc.result().levels[p].residual, 1e-16 * kMass * kMass * kG * kG) << "level " << p;

  const VectorX& x = wbc.x();
  double sum_fz = 0.0;
  Eigen::Vector3d sum_f = Eigen::Vector3d::Zero();
  const double k = params.mu / std::sqrt(2.0);
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector3d f = x.segment<3>(Layout::forceIndex(c));  // world = ground frame
    sum_f += f;
    sum_fz += f.z();
    EXPECT_GE(f.z(), params.fz_min - 1e-9) << "foot " << c;
    EXPECT_LE(std::abs(f.x()), k * f.z() + 1e-9) << "foot " << c;
    EXPECT_LE(std::abs(f.y()), k * f.z() + 1e-9) << "foot " << c;
  }
  EXPECT_NEAR(sum_fz, kMass * kG, 1e-6);
  EXPECT_LT(sum_f.head<2>().norm(), 1e-6);
  // The stance is held: no foot accelerates; joint torques within the URDF efforts.
  for (int c = 0; c < 4; ++c)
    EXPECT_LT((dyn.J(c).topRows<3>() * x.head<Robot::nv>() + dyn.dJv(c).head<3>()).norm(), 1e-9);
  const auto tau = hqp::tasks::jointTorque<Layout>(dyn, x);
  EXPECT_TRUE((tau.cwiseAbs().array() <= params.tau_max.array() + 1e-9).all()) << tau.transpose();
  // Loaded knees (README: 4.3 N·m front, 6.2 N·m hind under a PD-held stance in MuJoCo).
  EXPECT_GT(std::abs(tau(Robot::Joints::lh_kfe)), 1.0);
}

TEST(QuadrupedHierarchy, PlannerReferencesForFourFeet) {
  Dyn dyn = makeDynamics();
  dyn.calcWbcDependence(nominalStance(), VectorV::Zero());
  hqp::tasks::PlannerParameters pp;
  pp.torso_yaw_offset = 0.5 * 3.14159265358979323846;  // imu frame yawed by π/2 on the base (README)
  hqp::tasks::TaskPlanner<4> planner;
  planner.configure(pp, Robot::total_mass);
  hqp::tasks::References<4> refs;
  std::array<Eigen::Vector2d, 4> cop;
  cop.fill(Eigen::Vector2d::Zero());
  std::array<bool, 4> contact;
  contact.fill(true);
  planner.update(dyn, cop, contact, refs);
  for (int c = 0; c < 4; ++c) {
    EXPECT_TRUE(planner.inSafeRegion(c));
    EXPECT_NEAR(refs.contact_force[c](2), kMass * kG / 4.0, 1e-9);
    EXPECT_LT(refs.contact_force[c].head<2>().norm(), 1e-12);
  }
  // Mean of the README feet: x = (0.204347 − 0.175653) / 2, y = 0.
  EXPECT_NEAR(refs.com.x(), 0.5 * (0.204347 - 0.175653), 1e-6);
  EXPECT_NEAR(refs.com.y(), 0.0, 1e-9);
  // Upright base, so the upright reference at the feet's heading + π/2 is the imu's orientation.
  EXPECT_TRUE(refs.torso_orientation.isApprox(dyn.placement(4).linear(), 1e-12));

  // The hierarchy on the planner's references (the CoM is asked to move 2 cm forward).
  auto params = hqp::tasks::defaultBalanceParameters<Robot>();
  Hqp wbc;
  hqp::tasks::configureHierarchy(wbc, params);
  hqp::tasks::updateHierarchy(wbc, dyn, refs);
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  for (int p = 0; p < Hqp::num_levels; ++p)
    EXPECT_EQ(wbc.result().levels[p].status, hqp::QpStatus::Optimal) << "level " << p;
  EXPECT_LT(wbc.result().levels[1].residual, 1e-16);  // feet held
  // Vertical force balance: Σ f_z − m g = m a_z, and the CoM task asks for no vertical motion.
  double sum_fz = 0.0;
  for (int c = 0; c < 4; ++c) sum_fz += wbc.x()(Layout::forceIndex(c) + 2);
  EXPECT_NEAR(sum_fz, kMass * kG, 1e-6);
}

}  // namespace
