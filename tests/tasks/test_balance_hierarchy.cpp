// The Walker3 balance hierarchy (Table I) on the robot model:
// - quiet standing: every level optimal, τ_opt equal to an independent gravity compensation
//   (RNEA gravity vector minus the joint torques of m g/2 per sole by virtual work about each
//   joint axis), CoP of each optimized wrench at the sole centre; HqpWbc and WqpWbc;
// - the contact Jacobian sign: the static wrenches zero the floating-base rows, flipped ones don't;
// - a CoM demand too large for the support: CoP, friction and torque limits hold (checked on
//   the wrenches by hand), the foot task keeps a zero residual, levels 3 and 4 pay;
// - torque saturation: |τ_opt| ≤ tau_max with low knee limits, and a level reports the knee rows.
// - the contact constraints on a turned and tilted sole, the PD signs of the operational tasks;
// - a straight leg removes the torso roll from level 4's reach (the reason for the planner's C);
// - no heap in update + solve + τ_opt + planner (Eigen's guard and a counting operator new).
// Expected values come from the model layer (checked against MuJoCo in tests/mujoco), closed
// forms and the robot's total mass, never from the tasks under test.
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "model/configuration.hpp"
#include "model/frames.hpp"
#include "model/kinematics.hpp"
#include "model/rnea.hpp"
#include "tasks/balance_hierarchy.hpp"
#include "tasks/inverse_dynamics.hpp"
#include "tasks/orientation_error.hpp"
#include "tasks/task_planner.hpp"
#include "walker3_model.hpp"
#include "support/allocation_counter.hpp"

using hqp::testing::g_counting;
using hqp::testing::g_news;

namespace {

using Robot = walker3::Robot;
using Layout = hqp::tasks::ContactLayout<Robot, 2, 6>;
using Dyn = Layout::Dynamics;
using Hqp = hqp::tasks::BalanceHqp<Layout>;
using Wqp = hqp::tasks::BalanceWqp<Layout>;
using VectorQ = Eigen::Matrix<double, Robot::nq, 1>;
using VectorV = Eigen::Matrix<double, Robot::nv, 1>;
using VectorJ = Eigen::Matrix<double, Robot::nj, 1>;
using VectorX = Eigen::Matrix<double, Layout::nx, 1>;
using Refs = hqp::tasks::References<2>;

constexpr double kG = 9.81;
constexpr double kMass = 43.0;  // robots/walker3/README.md (paper)

static_assert(Layout::nx == 30, "x = [q̈ (18); F (12)]");
static_assert(hqp::tasks::BalanceLevel1<Layout>::task_rows == 6, "Table I");
static_assert(hqp::tasks::BalanceLevel1<Layout>::constraint_rows == 12, "Table I");
static_assert(hqp::tasks::BalanceLevel2<Layout>::task_rows == 12, "Table I");
static_assert(hqp::tasks::BalanceLevel2<Layout>::constraint_rows == 18, "Table I");
static_assert(hqp::tasks::BalanceLevel3<Layout>::task_rows == 3, "Table I");
static_assert(hqp::tasks::BalanceLevel4<Layout>::task_rows == 15, "Table I");

std::array<int, 3> frames() { return {Robot::Frames::l_sole, Robot::Frames::r_sole, Robot::Frames::imu}; }

// The crouch of robots/walker3/README.md (hip pitch −0.3, knee 0.6, ankle pitch −0.3) with
// hip pitch + δ and ankle pitch − δ (torso and feet stay parallel), δ found by bisection so
// that the model CoM is above the midpoint of the sole centres; soles on z = 0; at rest.
VectorQ standingPose() {
  Dyn dyn(frames());
  const VectorV v = VectorV::Zero();
  auto pose = [&](double d) {
    VectorQ q = hqp::model::neutralConfiguration<Robot>();
    for (int leg = 0; leg < 2; ++leg) {
      const int o = leg == 0 ? Robot::Joints::l_hip_pitch : Robot::Joints::r_hip_pitch;
      q(7 + o) = -0.3 + d;  // hip pitch, knee, ankle pitch are consecutive in each leg
      q(7 + o + 1) = 0.6;
      q(7 + o + 2) = -0.3 - d;
    }
    dyn.calcWbcDependence(q, v);
    q(2) -= 0.5 * (dyn.placement(0).translation().z() + dyn.placement(1).translation().z());
    dyn.calcWbcDependence(q, v);
    return q;
  };
  static_assert(Robot::Joints::l_knee == Robot::Joints::l_hip_pitch + 1 &&
                    Robot::Joints::l_ankle_pitch == Robot::Joints::l_hip_pitch + 2 &&
                    Robot::Joints::r_knee == Robot::Joints::r_hip_pitch + 1 &&
                    Robot::Joints::r_ankle_pitch == Robot::Joints::r_hip_pitch + 2,
                "joint order assumed by standingPose()");
  auto offset = [&](double d) {
    pose(d);
    return dyn.com().x() - 0.5 * (dyn.placement(0).translation().x() + dyn.placement(1).translation().x());
  };
  double lo = -0.2, hi = 0.2;
  const bool increasing = offset(hi) > offset(lo);
  EXPECT_LT(offset(lo) * offset(hi), 0.0);
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    if ((offset(mid) > 0.0) == increasing) hi = mid;
    else lo = mid;
  }
  return pose(0.5 * (lo + hi));
}

// References equal to the current state: nothing should move.
Refs restingReferences(const Dyn& dyn) {
  Refs r;
  for (int c = 0; c < 2; ++c) {
    r.contact_pose[c] = dyn.placement(c);
    r.contact_velocity[c] = dyn.velocity(c);
    r.contact_acceleration[c].setZero();
    r.contact_force[c].setZero();
    r.contact_force[c](2) = kMass * kG / 2.0;
  }
  r.com = dyn.com();
  r.com_velocity = dyn.vcom();
  r.torso_orientation = dyn.placement(2).linear();
  return r;
}

// Joint torques that hold the robot at rest in q when each sole carries `F[c]` (world-aligned
// wrench about the sole origin): τ = G_a − Σ_c Σ_{joints j above c} a_j · ((p_c − o_j) × f_c + m_c),
// by virtual work about each joint axis (world axis a_j through the joint origin o_j).
VectorJ gravityCompensation(const VectorQ& q, const std::array<hqp::model::Vector6, 2>& F) {
  hqp::model::Data<Robot> d;
  const VectorV g = hqp::model::computeGravity(d, q);
  hqp::model::forwardKinematics(d, q);
  VectorJ tau = g.tail<Robot::nj>();
  const int soles[2] = {Robot::Frames::l_sole, Robot::Frames::r_sole};
  for (int c = 0; c < 2; ++c) {
    const Eigen::Vector3d p = hqp::model::framePlacement(d, soles[c]).translation();
    for (int b = Robot::frames[soles[c]].body; b > 0; b = Robot::bodies[b].parent) {
      const Eigen::Vector3d a = d.oR[b] * d.axis[b];
      tau(b - 1) -= a.dot((p - d.op[b]).cross(F[c].head<3>()) + F[c].tail<3>());
    }
  }
  return tau;
}

// Contact wrench c of x rotated into the sole frame: [f; m] about the sole origin.
hqp::model::Vector6 soleWrench(const Dyn& dyn, const VectorX& x, int c) {
  const Eigen::Matrix3d Rt = dyn.placement(c).linear().transpose();
  hqp::model::Vector6 w;
  w.head<3>() = Rt * x.segment<3>(Layout::forceIndex(c));
  w.tail<3>() = Rt * x.segment<3>(Layout::forceIndex(c) + 3);
  return w;
}

class BalanceHierarchy : public ::testing::Test {
 protected:
  BalanceHierarchy() : dyn(frames()) {
    q = standingPose();
    dyn.calcWbcDependence(q, VectorV::Zero());
    refs = restingReferences(dyn);
    params = hqp::tasks::defaultBalanceParameters<Robot>();
    for (int c = 0; c < 2; ++c) {
      F_static[c].setZero();
      F_static[c](2) = kMass * kG / 2.0;
    }
  }

  template <class Wbc>
  hqp::QpStatus solve(Wbc& wbc, const Refs& r) {
    hqp::tasks::configureHierarchy(wbc, params);
    hqp::tasks::updateHierarchy(wbc, dyn, r);
    return wbc.solve();
  }

  // The bounds of every contact constraint at x, checked on the sole-frame wrenches.
  // `margin`: each foot's moment margin δ_c (default: the parameter's δ on both).
  void expectContactConstraints(const VectorX& x, double tol, std::array<double, 2> margin = {-1.0, -1.0}) const {
    const double k = params.mu / std::sqrt(2.0);
    for (int c = 0; c < 2; ++c) {
      const auto w = soleWrench(dyn, x, c);
      const double fz = w(2);
      EXPECT_GE(fz, params.fz_min - tol) << "foot " << c;
      EXPECT_LE(std::abs(w(0)), k * fz + tol) << "foot " << c;
      EXPECT_LE(std::abs(w(1)), k * fz + tol) << "foot " << c;
      // The CoP keeps δ_c / f_z from the region's edges (δ = the moment margin, 0 by default).
      const double delta = margin[c] >= 0.0 ? margin[c] : params.cop_moment_margin;
      const double cop_x = -w(4) / fz, cop_y = w(3) / fz, inset = delta / fz;
      EXPECT_GE(cop_x, params.sole_x_min + inset - tol) << "foot " << c;
      EXPECT_LE(cop_x, params.sole_x_max - inset + tol) << "foot " << c;
      EXPECT_GE(cop_y, params.sole_y_min + inset - tol) << "foot " << c;
      EXPECT_LE(cop_y, params.sole_y_max - inset + tol) << "foot " << c;
    }
  }

  // The hip-strategy budget on: θ_max (rad), K (N·m/rad), D 10 /s.
  void useHipBudget(double tilt, double K) {
    params.hip_max_tilt = tilt;
    params.hip_stiffness = K;
    params.hip_damping = 10.0;
  }

  VectorQ q;
  Dyn dyn;
  Refs refs;
  hqp::tasks::BalanceParameters<Robot::nj> params;
  std::array<hqp::model::Vector6, 2> F_static;
};

TEST_F(BalanceHierarchy, StandingPoseIsBalanced) {
  // The fixture's premise, checked on the model: CoM above the sole midpoint, soles on z = 0,
  // feet flat and torso upright.
  const Eigen::Vector3d mid = 0.5 * (dyn.placement(0).translation() + dyn.placement(1).translation());
  EXPECT_NEAR(dyn.com().x(), mid.x(), 1e-12);
  EXPECT_NEAR(dyn.com().y(), mid.y(), 1e-12);
  EXPECT_NEAR(dyn.placement(0).translation().z(), 0.0, 1e-12);
  EXPECT_NEAR(dyn.placement(1).translation().z(), 0.0, 1e-12);
  EXPECT_TRUE(dyn.placement(0).linear().isIdentity(1e-12));
  EXPECT_TRUE(dyn.placement(2).linear().isIdentity(1e-12));
  EXPECT_NEAR(dyn.mass(), kMass, 1e-9);
}

// The contact Jacobian convention: x = [0; F_static] must zero the floating-base rows of eq. 1
// (a static robot: S_f G = S_f Σ J_cᵀ F_c); the wrong sign must not.
TEST_F(BalanceHierarchy, ContactJacobianSignConvention) {
  hqp::tasks::FloatingBaseDynamicsTask<Layout> task;
  task.update(dyn, refs);
  VectorX x = VectorX::Zero();
  for (int c = 0; c < 2; ++c) x.segment<6>(Layout::forceIndex(c)) = F_static[c];
  EXPECT_LT((task.A * x - task.b).norm(), 1e-9 * kMass * kG);
  x.tail<12>() *= -1.0;
  EXPECT_GT((task.A * x - task.b).norm(), kMass * kG);
  // And τ of eq. 6 for that x is the independent gravity compensation.
  for (int c = 0; c < 2; ++c) x.segment<6>(Layout::forceIndex(c)) = F_static[c];
  const VectorJ tau = hqp::tasks::jointTorque<Layout>(dyn, x);
  EXPECT_LT((tau - gravityCompensation(q, F_static)).norm(), 1e-9);
}

TEST_F(BalanceHierarchy, QuietStandingHqp) {
  Hqp wbc;
  ASSERT_EQ(solve(wbc, refs), hqp::QpStatus::Optimal);
  for (int p = 0; p < Hqp::num_levels; ++p) {
    EXPECT_EQ(wbc.result().levels[p].status, hqp::QpStatus::Optimal) << "level " << p;
    EXPECT_LT(wbc.result().levels[p].residual, 1e-16 * kMass * kMass * kG * kG) << "level " << p;
  }
  // Null-space dimensions 30 → 24 → 12 → 9 → 0 (full-rank levels, Sec. III-B).
  EXPECT_EQ(wbc.result().levels[0].null_dim, 24);
  EXPECT_EQ(wbc.result().levels[1].null_dim, 12);
  EXPECT_EQ(wbc.result().levels[2].null_dim, 9);
  EXPECT_EQ(wbc.result().levels[3].null_dim, 0);
  const VectorX& x = wbc.x();
  EXPECT_LT(x.head<Robot::nv>().norm(), 1e-9);  // nothing moves
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT((x.segment<6>(Layout::forceIndex(c)) - F_static[c]).norm(), 1e-8) << "foot " << c;
    const auto w = soleWrench(dyn, x, c);
    EXPECT_NEAR(-w(4) / w(2), 0.0, 1e-6) << "CoP x, foot " << c;
    EXPECT_NEAR(w(3) / w(2), 0.0, 1e-6) << "CoP y, foot " << c;
  }
  const VectorJ tau = hqp::tasks::jointTorque<Layout>(dyn, x);
  const VectorJ expected = gravityCompensation(q, F_static);
  EXPECT_LT((tau - expected).cwiseAbs().maxCoeff(), 1e-9) << tau.transpose() << "\n"
                                                           << expected.transpose();
  // Not trivially zero: the knees carry the crouch.
  EXPECT_GT(std::abs(expected(Robot::Joints::l_knee)), 5.0);
}

// WqpWbc: one QP whose level weights are 1, 1e-3, 1e-6, 1e-9 (priority ratio 1e3) times the
// row weights, so level-4 force rows (row weight 1e-3) weigh 1e-12 against level-1 rows. Here
// every level can be met exactly, so the answer is the same point as HqpWbc's, but it is found
// through one QP whose Hessian has a condition number near 1e12 rather than one well-scaled QP
// per level: rounding can be amplified by up to ~1e12 · 1e-16 relative, so the tolerances are
// 1e-6 (m, N·m) instead of 1e-9 (observed errors are ~1e-14 on this pose).
TEST_F(BalanceHierarchy, QuietStandingWqp) {
  Wqp wbc;
  ASSERT_EQ(solve(wbc, refs), hqp::QpStatus::Optimal);
  const VectorX& x = wbc.x();
  for (int p = 0; p < Wqp::num_levels; ++p)
    EXPECT_LT(wbc.result().residual[p], 1e-10) << "level " << p;
  EXPECT_LT(x.head<Robot::nv>().norm(), 1e-6);
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT((x.segment<6>(Layout::forceIndex(c)) - F_static[c]).norm(), 1e-6) << "foot " << c;
    const auto w = soleWrench(dyn, x, c);
    EXPECT_NEAR(-w(4) / w(2), 0.0, 1e-6) << "CoP x, foot " << c;
    EXPECT_NEAR(w(3) / w(2), 0.0, 1e-6) << "CoP y, foot " << c;
  }
  const VectorJ tau = hqp::tasks::jointTorque<Layout>(dyn, x);
  EXPECT_LT((tau - gravityCompensation(q, F_static)).cwiseAbs().maxCoeff(), 1e-6);
}

// CoM reference 0.3 m ahead with a stiff CoM loop (kp = 100 /s², set here: the Walker3 default
// is softer): k_p e = 30 m/s² asks for ~1300 N of horizontal force, ~3× what friction allows.
// The contact constraints must hold, the feet must stay put (level 2 exact), and levels 3 and 4
// absorb the conflict.
TEST_F(BalanceHierarchy, ExcessiveComDemandKeepsContactsAndFeet) {
  params.com = {100.0, 20.0};
  Hqp nominal;
  ASSERT_EQ(solve(nominal, refs), hqp::QpStatus::Optimal);
  Refs far = refs;
  far.com.x() += 0.3;
  Hqp wbc;
  solve(wbc, far);
  for (int p = 0; p < Hqp::num_levels; ++p)
    EXPECT_EQ(wbc.result().levels[p].status, hqp::QpStatus::Optimal) << "level " << p;
  const VectorX& x = wbc.x();
  expectContactConstraints(x, 1e-9);
  // Torque limits (URDF efforts).
  const VectorJ tau = hqp::tasks::jointTorque<Layout>(dyn, x);
  EXPECT_TRUE((tau.cwiseAbs().array() <= params.tau_max.array() + 1e-9).all()) << tau.transpose();
  // Level 1: the dynamics hold. Level 2: both feet keep zero acceleration (J q̈ + J̇v = 0,
  // computed from the model's Jacobians, not from the task).
  EXPECT_LT(wbc.result().levels[0].residual, 1e-16 * kMass * kMass * kG * kG);
  for (int c = 0; c < 2; ++c) {
    const hqp::model::Vector6 acc = dyn.J(c) * x.head<Robot::nv>() + dyn.dJv(c);
    EXPECT_LT(acc.norm(), 1e-9) << "foot " << c;
  }
  EXPECT_LT(wbc.result().levels[1].residual, 1e-16);
  // The demand is not met: horizontal force bounded by friction, μ/√2 Σ f_z.
  const double fx = x(Layout::forceIndex(0)) + x(Layout::forceIndex(1));
  const double fz = x(Layout::forceIndex(0) + 2) + x(Layout::forceIndex(1) + 2);
  EXPECT_LE(fx, params.mu / std::sqrt(2.0) * fz + 1e-9);
  EXPECT_GT(fx, 0.0);  // but pushed forward
  EXPECT_GT(wbc.result().levels[2].residual, 1e4);  // (N)², vs ~0 in the nominal case
  EXPECT_LT(nominal.result().levels[2].residual, 1e-12);
  EXPECT_GT(wbc.result().levels[3].residual, nominal.result().levels[3].residual + 1.0);
}

// Soft versus strict priority on the same demand: WqpWbc keeps every constraint (they are hard
// in its single QP) but, unlike HqpWbc above, lets the higher tasks give a little to level 3.
TEST_F(BalanceHierarchy, ExcessiveComDemandWqpKeepsConstraints) {
  params.com = {100.0, 20.0};  // the same stiff CoM loop as above
  Refs far = refs;
  far.com.x() += 0.3;
  Wqp wbc;
  solve(wbc, far);
  EXPECT_EQ(wbc.result().status, hqp::QpStatus::Optimal);
  expectContactConstraints(wbc.x(), 1e-9);
  const VectorJ tau = hqp::tasks::jointTorque<Layout>(dyn, wbc.x());
  EXPECT_TRUE((tau.cwiseAbs().array() <= params.tau_max.array() + 1e-9).all()) << tau.transpose();
  EXPECT_GT(wbc.result().residual[2], 1e4);
  EXPECT_GT(wbc.result().residual[0] + wbc.result().residual[1], 1e-12);  // soft: traded
}

TEST_F(BalanceHierarchy, KneeTorqueSaturation) {
  const double limit = 8.0;  // N·m, under half of the ~18 N·m the crouch needs at each knee
  params.tau_max(Robot::Joints::l_knee) = limit;
  params.tau_max(Robot::Joints::r_knee) = limit;
  ASSERT_GT(std::abs(gravityCompensation(q, F_static)(Robot::Joints::l_knee)), 2.0 * limit);
  Hqp wbc;
  solve(wbc, refs);
  EXPECT_EQ(wbc.result().levels[0].status, hqp::QpStatus::Optimal);
  const VectorX& x = wbc.x();
  const VectorJ tau = hqp::tasks::jointTorque<Layout>(dyn, x);
  for (int j = 0; j < Robot::nj; ++j) EXPECT_LE(std::abs(tau(j)), params.tau_max(j) + 1e-9) << "joint " << j;
  EXPECT_NEAR(std::abs(tau(Robot::Joints::l_knee)), limit, 1e-6);
  EXPECT_NEAR(std::abs(tau(Robot::Joints::r_knee)), limit, 1e-6);
  // The dynamics still hold (level 1), and a level reports the knee rows at their bound
  // (level 1's constraint rows are the joints in model order).
  EXPECT_LT(wbc.result().levels[0].residual, 1e-16 * kMass * kMass * kG * kG);
  bool l_knee_active = false, r_knee_active = false;
  for (const auto& lr : wbc.result().levels) {
    for (int a = 0; a < lr.num_active; ++a) {
      l_knee_active |= lr.active_row[a] == Robot::Joints::l_knee;
      r_knee_active |= lr.active_row[a] == Robot::Joints::r_knee;
    }
  }
  EXPECT_TRUE(l_knee_active);
  EXPECT_TRUE(r_knee_active);
  expectContactConstraints(x, 1e-9);
  // The crouch cannot be held as it is: a lower level gives way (here the torso and forces).
  EXPECT_GT(wbc.result().levels[2].residual + wbc.result().levels[3].residual, 1.0);
}

// A sole turned and tilted in the world (base yaw 0.5, roll 0.15): wrenches built in the sole
// frame with a chosen CoP and force, rotated to the world, must meet the CoP and friction rows
// exactly when inside and violate them when outside (catches R versus Rᵀ).
TEST_F(BalanceHierarchy, ContactConstraintsInTheSoleFrame) {
  VectorQ qt = q;
  const Eigen::Quaterniond rot = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitX());
  qt(3) = rot.w(), qt(4) = rot.x(), qt(5) = rot.y(), qt(6) = rot.z();
  qt(7 + Robot::Joints::l_ankle_roll) = 0.2;
  Dyn d(frames());
  d.calcWbcDependence(qt, VectorV::Zero());
  hqp::tasks::CopConstraint<Layout> cop;
  hqp::tasks::FrictionConstraint<Layout> fric;
  cop.configure(params);
  fric.configure(params);
  cop.update(d, refs);
  fric.update(d, refs);
  const double k = params.mu / std::sqrt(2.0);
  // x with foot 0's wrench [f; p × f] in the sole frame, rotated to the world; foot 1 at rest.
  auto wrench = [&](const Eigen::Vector2d& p, const Eigen::Vector3d& fs) {
    VectorX x = VectorX::Zero();
    const Eigen::Matrix3d R = d.placement(0).linear();
    x.segment<3>(Layout::forceIndex(0)) = R * fs;
    x.segment<3>(Layout::forceIndex(0) + 3) = R * Eigen::Vector3d(p.x(), p.y(), 0.0).cross(fs);
    x.segment<3>(Layout::forceIndex(1)) = d.placement(1).linear() * Eigen::Vector3d(0, 0, 100.0);
    return x;
  };
  const Eigen::Vector3d f_in(0.9 * k * 200.0, -0.9 * k * 200.0, 200.0);
  const double eps = 1e-3;
  // Inside, at the corners (less eps).
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      const Eigen::Vector2d p(sx > 0 ? params.sole_x_max - eps : params.sole_x_min + eps,
                              sy > 0 ? params.sole_y_max - eps : params.sole_y_min + eps);
      EXPECT_LE(cop.violation(wrench(p, f_in)), 1e-12) << p.transpose();
      EXPECT_LE(fric.violation(wrench(p, f_in)), 1e-12) << p.transpose();
    }
  // Outside, one side at a time: violated by about eps · f_z.
  const Eigen::Vector2d out[] = {{params.sole_x_max + eps, 0.0}, {params.sole_x_min - eps, 0.0},
                                 {0.0, params.sole_y_max + eps}, {0.0, params.sole_y_min - eps}};
  for (const auto& p : out) EXPECT_NEAR(cop.violation(wrench(p, f_in)), eps * 200.0, 1e-9) << p.transpose();
  // Friction: tangential force 10 % beyond the pyramid on each axis; normal force below fz_min.
  for (int axis = 0; axis < 2; ++axis)
    for (double sign : {-1.0, 1.0}) {
      Eigen::Vector3d f(0, 0, 200.0);
      f(axis) = sign * 1.1 * k * 200.0;
      EXPECT_NEAR(fric.violation(wrench(Eigen::Vector2d::Zero(), f)), 0.1 * k * 200.0, 1e-9);
    }
  EXPECT_NEAR(fric.violation(wrench(Eigen::Vector2d::Zero(), Eigen::Vector3d(0, 0, params.fz_min - 1.0))),
              1.0, 1e-9);
}

// The PD signs of eq. 2 at rest (J̇v = 0): a reference displaced by +δ asks for a = kp δ.
TEST_F(BalanceHierarchy, OperationalTasksPullTowardsTheReference) {
  Refs r = refs;
  r.contact_pose[1].translation() += Eigen::Vector3d(0.01, -0.02, 0.03);
  r.contact_pose[1].linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                               r.contact_pose[1].linear();
  r.com += Eigen::Vector3d(0.02, 0.0, -0.01);
  r.torso_orientation = Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                        r.torso_orientation;
  hqp::tasks::ContactPoseTask<Layout> feet;
  hqp::tasks::LinearMomentumTask<Layout> com;
  hqp::tasks::TorsoPostureTask<Layout> torso;
  feet.configure(params);
  com.configure(params);
  torso.configure(params);
  feet.update(dyn, r);
  com.update(dyn, r);
  torso.update(dyn, r);
  const double kf = params.foot_linear.kp, ka = params.foot_angular.kp;
  EXPECT_LT(feet.b.head<6>().norm(), 1e-9);  // left foot: at its reference
  EXPECT_LT((feet.b.segment<3>(6) - kf * Eigen::Vector3d(0.01, -0.02, 0.03)).norm(), 1e-9);
  EXPECT_LT((feet.b.segment<3>(9) - ka * Eigen::Vector3d(0, 0.05, 0)).norm(), 1e-9);
  EXPECT_LT((feet.error().segment<3>(9) - Eigen::Vector3d(0, 0.05, 0)).norm(), 1e-12);
  // Horizontal rows with the CoM gains, the vertical row with its own.
  EXPECT_LT((com.b - kMass * Eigen::Vector3d(params.com.kp * 0.02, 0.0, params.com_vertical.kp * -0.01)).norm(),
            1e-9);
  EXPECT_NE(params.com.kp, params.com_vertical.kp);  // else the line above cannot tell them apart
  EXPECT_LT((torso.b - params.torso.kp * Eigen::Vector3d(-0.1, 0, 0)).norm(), 1e-9);
  // The saturated torso PD: the proportional term acts on the error shortened to its limit
  // (0.04 of the 0.1 rad), a limit above the error changes nothing.
  auto sat = params;
  sat.torso_error_limit = 0.04;
  torso.configure(sat);
  torso.update(dyn, r);
  EXPECT_LT((torso.b - params.torso.kp * Eigen::Vector3d(-0.04, 0, 0)).norm(), 1e-9);
  EXPECT_LT((torso.error() - Eigen::Vector3d(-0.1, 0, 0)).norm(), 1e-9);  // reported unsaturated
  sat.torso_error_limit = 0.2;
  torso.configure(sat);
  torso.update(dyn, r);
  EXPECT_LT((torso.b - params.torso.kp * Eigen::Vector3d(-0.1, 0, 0)).norm(), 1e-9);
  // Rows: the feet's Jacobians, A_G's linear rows (m × CoM Jacobian), the torso's angular rows.
  EXPECT_TRUE((feet.A.block<6, Robot::nv>(6, 0).isApprox(dyn.J(1), 1e-15)));
  EXPECT_TRUE(com.A.leftCols<Robot::nv>().isApprox(kMass * dyn.Jcom(), 1e-12));
  EXPECT_TRUE(torso.A.leftCols<Robot::nv>().isApprox(dyn.J(2).bottomRows<3>(), 1e-15));
  EXPECT_TRUE(torso.A.rightCols<12>().isZero(0.0));
}

// The CoM task's two extensions beyond the paper, at rest (Ȧ_G v = 0, ė = 0), against closed
// forms: the capture-point schedule blends the gains by s = (|e| − low)/(high − low) per axis
// (|e + ė/ω| = |e| here), and the integral adds ki Σ e dt, clamped, until resetState().
TEST_F(BalanceHierarchy, ComScheduleAndIntegral) {
  hqp::tasks::BalanceParameters<Robot::nj> p = params;
  p.com = {4.0, 3.0};
  p.com_high = {20.0, 10.0};
  p.com_dcm_low = 0.03;
  p.com_dcm_high = 0.06;
  p.com_ki = 3.0;
  p.com_integral_limit = 2e-4;
  p.dt = 0.001;
  Refs r = refs;
  r.com += Eigen::Vector3d(0.02, -0.05, 0.0);
  const Eigen::Vector2d e = (r.com - dyn.com()).head<2>();
  ASSERT_NEAR(e.x(), 0.02, 1e-9);
  hqp::tasks::LinearMomentumTask<Layout> com;
  com.configure(p);
  const double s_y = (0.05 - 0.03) / (0.06 - 0.03);
  const Eigen::Vector2d kp(4.0, (1.0 - s_y) * 4.0 + s_y * 20.0);
  for (int k = 1; k <= 5; ++k) {
    com.update(dyn, r);
    // Σ e dt after k ticks, clamped to ±2e-4 m·s per axis.
    const Eigen::Vector2d integral = (k * 0.001 * e).cwiseMax(-2e-4).cwiseMin(2e-4);
    const Eigen::Vector2d a = kp.cwiseProduct(e) + 3.0 * integral;
    EXPECT_LT((com.b.head<2>() - dyn.mass() * a).norm(), 1e-9) << "tick " << k;
  }
  com.resetState();
  com.update(dyn, r);
  EXPECT_LT((com.b.head<2>() - dyn.mass() * (kp.cwiseProduct(e) + 3.0 * 0.001 * e)).norm(), 1e-9);
  // Off (the paper's PD) with the defaults: ki = 0, no schedule.
  hqp::tasks::LinearMomentumTask<Layout> plain;
  plain.configure(params);
  plain.update(dyn, r);
  EXPECT_LT((plain.b.head<2>() - dyn.mass() * params.com.kp * e).norm(), 1e-9);
}

// The integral's reset on a sign change (a Clegg integrator), per axis: the reference steps to
// the other side of the CoM on x only. Expected: x's integral restarts from 0 at the step
// (then grows with the new error), y's keeps growing; without the reset x's integral first
// unwinds through the old sum. Closed forms from the error sequence, at rest (ė = 0).
TEST_F(BalanceHierarchy, ComIntegralResetOnSignChange) {
  hqp::tasks::BalanceParameters<Robot::nj> p = params;
  p.com_ki = 3.0;
  p.com_integral_limit = 1.0;  // no clamp in this test
  p.dt = 0.001;
  p.com_integral_reset = true;
  hqp::tasks::BalanceParameters<Robot::nj> q_off = p;
  q_off.com_integral_reset = false;
  Refs ahead = refs, behind = refs;
  ahead.com += Eigen::Vector3d(0.02, 0.01, 0.0);
  behind.com += Eigen::Vector3d(-0.03, 0.01, 0.0);
  const Eigen::Vector2d e1 = (ahead.com - dyn.com()).head<2>(), e2 = (behind.com - dyn.com()).head<2>();
  ASSERT_GT(e1.x(), 0.0);
  ASSERT_LT(e2.x(), 0.0);
  ASSERT_GT(e1.y() * e2.y(), 0.0);
  hqp::tasks::LinearMomentumTask<Layout> on, off;
  on.configure(p);
  off.configure(q_off);
  for (int k = 0; k < 10; ++k) {
    on.update(dyn, ahead);
    off.update(dyn, ahead);
  }
  EXPECT_LT((on.integral() - 10 * 0.001 * e1).norm(), 1e-12);
  EXPECT_LT((off.integral() - on.integral()).norm(), 1e-15);
  for (int k = 1; k <= 4; ++k) {
    on.update(dyn, behind);
    off.update(dyn, behind);
    EXPECT_NEAR(on.integral().x(), k * 0.001 * e2.x(), 1e-12) << "tick " << k;
    EXPECT_NEAR(off.integral().x(), 10 * 0.001 * e1.x() + k * 0.001 * e2.x(), 1e-12) << "tick " << k;
    EXPECT_NEAR(on.integral().y(), 10 * 0.001 * e1.y() + k * 0.001 * e2.y(), 1e-12) << "tick " << k;
    // The task's right-hand side carries the reset integral: b = m (kp e + ki ∫e dt) on x.
    EXPECT_NEAR(on.b.x(), dyn.mass() * (p.com.kp * e2.x() + 3.0 * on.integral().x()), 1e-9);
  }
}

// A robot in motion (every velocity non-zero) with velocity references equal to the current
// velocities: the feet (level 2) and the CoM (level 3) are asked for zero classical
// acceleration, which holds only if the tasks subtract J̇v and Ȧ_G v with the right sign.
// Checked by central differences of the model's frame and CoM velocities along (v, q̈*).
// Level-4 force rows: force_weight everywhere except the torsion m_z of each sole, which weighs
// force_weight / torsion_radius² (1 N·m of torsion as costly as 1 / r N of force).
// The hip-strategy budget of the CoM rows, at rest (L = 0), checked on the solution's contact
// wrenches: L̇_G = Σ_c (p_c − c) × f_c + m_c (Newton–Euler about the CoM; gravity has no moment
// there). A demand far beyond the soles (0.3 m ahead / to the side) may buy at most K θ_max of
// L̇ with the torso upright and none with the torso already θ_max from its reference; without the
// budget level 3 takes what it needs.
TEST_F(BalanceHierarchy, HipStrategyBudgetBoundsTheAngularMomentumRate) {
  const auto angularMomentumRate = [&](const VectorX& x) {
    Eigen::Vector3d dL = Eigen::Vector3d::Zero();
    for (int c = 0; c < 2; ++c) {
      const Eigen::Vector3d f = x.segment<3>(Layout::forceIndex(c)), m = x.segment<3>(Layout::forceIndex(c) + 3);
      dL += (dyn.placement(c).translation() - dyn.com()).cross(f) + m;
    }
    return dL;
  };
  const double K = 40.0, tilt = 0.5;
  hqp::tasks::BalanceParameters<Robot::nj> off = params;
  useHipBudget(tilt, K);
  ASSERT_EQ(angularMomentumRate(VectorX::Zero()).norm(), 0.0);
  Refs ahead = refs, aside = refs, tilted = refs;
  ahead.com.x() += 0.3;
  aside.com.y() += 0.3;
  tilted.com.x() += 0.3;
  // The reference pitched θ_max forward of the torso: the torso is θ_max back from it.
  tilted.torso_orientation = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()) * dyn.placement(Layout::torso_frame).linear();
  Hqp wbc;
  ASSERT_EQ(solve(wbc, ahead), hqp::QpStatus::Optimal);
  expectContactConstraints(wbc.x(), 1e-9);
  EXPECT_NEAR(angularMomentumRate(wbc.x()).y(), -K * tilt, 1e-6);
  for (int c = 0; c < 2; ++c) {  // on the heels: the CoP gives all it can
    const auto w = soleWrench(dyn, wbc.x(), c);
    EXPECT_NEAR(-w(4) / w(2), params.sole_x_min, 1e-9) << "foot " << c;
  }
  ASSERT_EQ(solve(wbc, tilted), hqp::QpStatus::Optimal);
  EXPECT_NEAR(angularMomentumRate(wbc.x()).y(), 0.0, 1e-6);
  // Sideways the net CoP cannot reach the outer edge (the other foot keeps f_z ≥ fz_min), so L̇_x
  // lies between K θ_max and K θ_max + fz_min · (distance between the feet).
  ASSERT_EQ(solve(wbc, aside), hqp::QpStatus::Optimal);
  const double gap = (dyn.placement(0).translation() - dyn.placement(1).translation()).norm();
  EXPECT_GE(angularMomentumRate(wbc.x()).x(), K * tilt - 1e-6);
  EXPECT_LE(angularMomentumRate(wbc.x()).x(), K * tilt + params.fz_min * gap + 1e-6);
  // Without the budget (the paper's task) the same demand pitches the torso much harder.
  params = off;
  ASSERT_EQ(solve(wbc, ahead), hqp::QpStatus::Optimal);
  EXPECT_LT(angularMomentumRate(wbc.x()).y(), -2.0 * K * tilt);
}

// The CoP rows' moment margin δ: a foot's CoP stops δ / f_z inside its region, so the lighter foot
// keeps further from its edge; the two y rows together imply f_z ≥ 2δ / (y_max − y_min).
TEST_F(BalanceHierarchy, CopMomentMarginGrowsAsTheFootUnloads) {
  const double delta = 1.0;
  params.cop_moment_margin = delta;
  useHipBudget(0.5, 40.0);  // the budget bounds the torso's share, so the CoPs must give all they can
  Refs ahead = refs, aside = refs;
  ahead.com.x() += 0.3;
  aside.com.y() += 0.3;
  Hqp wbc;
  ASSERT_EQ(solve(wbc, ahead), hqp::QpStatus::Optimal);
  expectContactConstraints(wbc.x(), 1e-9);
  for (int c = 0; c < 2; ++c) {  // both CoPs on the heel bound, δ / f_z in from it
    const auto w = soleWrench(dyn, wbc.x(), c);
    EXPECT_NEAR(w(4) + params.sole_x_min * w(2), -delta, 1e-6) << "foot " << c;  // m_y at its bound
    EXPECT_NEAR(-w(4) / w(2), params.sole_x_min + delta / w(2), 1e-8) << "foot " << c;
  }
  ASSERT_EQ(solve(wbc, aside), hqp::QpStatus::Optimal);
  expectContactConstraints(wbc.x(), 1e-9);
  const auto wl = soleWrench(dyn, wbc.x(), 0), wr = soleWrench(dyn, wbc.x(), 1);
  const double light_load = std::min(wl(2), wr(2)), heavy_load = std::max(wl(2), wr(2));
  ASSERT_LT(light_load, 0.5 * heavy_load);  // the demand aside unloads one foot
  EXPECT_GE(light_load, 2.0 * delta / (params.sole_y_max - params.sole_y_min) - 1e-9);
  for (const auto& w : {wl, wr}) {  // both on the bound towards −y, the lighter one further in
    EXPECT_NEAR(w(3) / w(2), params.sole_y_min + delta / w(2), 1e-9);
  }
  // The lighter foot measured at 12 N: its margin is capped at (y_max − y_min)·12 N / 4, which
  // asks it for at most 6 N, so fz_min alone holds it down and its CoP moves out to the cap's inset.
  const int light = wl(2) < wr(2) ? 0 : 1;
  const double cap = 0.25 * (params.sole_y_max - params.sole_y_min) * 12.0;
  ASSERT_LT(cap, delta);
  aside.contact_load[light] = 12.0;
  ASSERT_EQ(solve(wbc, aside), hqp::QpStatus::Optimal);
  std::array<double, 2> margins{delta, delta};
  margins[light] = cap;
  expectContactConstraints(wbc.x(), 1e-9, margins);
  const auto wc = soleWrench(dyn, wbc.x(), light);
  EXPECT_LT(wc(2), light_load - 1.0);  // let go: it carries less than with the full margin
  EXPECT_NEAR(wc(3) / wc(2), params.sole_y_min + cap / wc(2), 1e-9);
  const auto wh = soleWrench(dyn, wbc.x(), 1 - light);
  EXPECT_NEAR(wh(3) / wh(2), params.sole_y_min + delta / wh(2), 1e-9);
  // The same demand without the margin puts both CoPs on the region's edge.
  aside.contact_load[light] = std::numeric_limits<double>::infinity();
  params.cop_moment_margin = 0.0;
  ASSERT_EQ(solve(wbc, aside), hqp::QpStatus::Optimal);
  for (int c = 0; c < 2; ++c) {
    const auto w = soleWrench(dyn, wbc.x(), c);
    EXPECT_NEAR(w(3) / w(2), params.sole_y_min, 1e-9) << "foot " << c;
  }
}

TEST_F(BalanceHierarchy, TorsionRowsOfTheForceTaskWeighByTheTorsionRadius) {
  hqp::tasks::ContactForceTask<Layout> force;
  force.configure(params);
  ASSERT_GT(params.torsion_radius, 0.0);
  for (int c = 0; c < 2; ++c) {
    for (int k = 0; k < 6; ++k) {
      const double expected =
          k == 5 ? params.force_weight / (params.torsion_radius * params.torsion_radius) : params.force_weight;
      EXPECT_DOUBLE_EQ(force.weight(6 * c + k), expected) << "contact " << c << " row " << k;
    }
  }
  auto p = params;
  p.torsion_radius = 0.0;  // off: every row alike
  force.configure(p);
  EXPECT_TRUE(force.weight.isConstant(p.force_weight));
}

TEST_F(BalanceHierarchy, MovingRobotBiasTerms) {
  VectorV v;
  v.head<6>() << 0.1, 0.05, -0.02, 0.1, -0.2, 0.15;
  for (int j = 0; j < Robot::nj; ++j) v(6 + j) = 0.4 * std::sin(1.0 + j);
  Dyn d(frames());
  d.calcWbcDependence(q, v);
  Refs r = restingReferences(d);
  Hqp wbc;
  hqp::tasks::configureHierarchy(wbc, params);
  hqp::tasks::updateHierarchy(wbc, d, r);
  ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  for (int p = 0; p < 3; ++p) EXPECT_LT(wbc.result().levels[p].residual, 1e-16) << "level " << p;
  const VectorV a = wbc.x().head<Robot::nv>();
  const double dt = 1e-5;
  Dyn plus(frames()), minus(frames());
  plus.calcWbcDependence(hqp::model::integrate<Robot>(q, v, dt), v + a * dt);
  minus.calcWbcDependence(hqp::model::integrate<Robot>(q, v, -dt), v - a * dt);
  for (int c = 0; c < 2; ++c) {
    const hqp::model::Vector6 acc = (plus.velocity(c) - minus.velocity(c)) / (2 * dt);
    EXPECT_LT(acc.norm(), 1e-6) << "foot " << c << ": " << acc.transpose();
    // Not trivially zero: the bias it cancels.
    EXPECT_GT(d.dJv(c).norm(), 1e-2) << "foot " << c;
  }
  const Eigen::Vector3d acom = (plus.vcom() - minus.vcom()) / (2 * dt);
  EXPECT_LT(acom.norm(), 1e-6) << acom.transpose();
  EXPECT_GT(d.dAg_v().head<3>().norm(), 1e-2);
}

// Why the planner's C must leave the knees bent (controller.yaml, docs/tasks.md "Lateral
// pushes"): with one leg straight, the level-2 sole rows fix that leg's hip–ankle distance to first
// order, so in the null space of levels 2–3 (sole pose + CoM) the torso angular rows of level 4
// lose the roll. Smallest singular value of J_ω N, N = kernel of the level-2/3 task rows (q̈ part;
// the forces do not enter these rows), computed by SVD (Eigen), not by the hierarchy.
TEST(BalanceHierarchyGeometry, AStraightLegLeavesLevelFourNoTorsoRoll) {
  auto smallest = [](double right_knee, Eigen::Vector3d* axis) {
    VectorQ q = hqp::model::neutralConfiguration<Robot>();
    const int legs[2] = {Robot::Joints::l_hip_pitch, Robot::Joints::r_hip_pitch};
    const double knee[2] = {0.6, right_knee};
    for (int leg = 0; leg < 2; ++leg) {  // hip pitch, knee, ankle pitch; sole parallel to the base
      q(7 + legs[leg]) = -0.5 * knee[leg];
      q(7 + legs[leg] + 1) = knee[leg];
      q(7 + legs[leg] + 2) = -0.5 * knee[leg];
    }
    Dyn d(frames());
    d.calcWbcDependence(q, VectorV::Zero());
    const Refs r = restingReferences(d);
    hqp::tasks::ContactPoseTask<Layout> feet;
    hqp::tasks::LinearMomentumTask<Layout> com;
    hqp::tasks::TorsoPostureTask<Layout> torso;
    feet.update(d, r);
    com.update(d, r);
    torso.update(d, r);
    Eigen::Matrix<double, 15, Robot::nv> H;
    H << feet.A.leftCols<Robot::nv>(), com.A.leftCols<Robot::nv>();
    const Eigen::FullPivLU<Eigen::Matrix<double, 15, Robot::nv>> lu(H);
    EXPECT_EQ(lu.rank(), 15);
    const Eigen::MatrixXd N = lu.kernel();
    const Eigen::MatrixXd JwN = torso.A.leftCols<Robot::nv>() * N;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(JwN, Eigen::ComputeFullU);
    *axis = svd.matrixU().col(2);
    return svd.singularValues()(2);
  };
  Eigen::Vector3d axis;
  EXPECT_GT(smallest(0.6, &axis), 0.3) << "crouch: level 4 reaches every torso axis";
  EXPECT_LT(smallest(0.0, &axis), 0.02) << "straight right leg";
  EXPECT_GT(std::abs(axis.x()), 0.95) << "the lost torso axis is the roll: " << axis.transpose();
}

// e = log(R_ref Rᵀ) is a WORLD rotation vector: R_ref = exp(ω̂) R gives e = ω for any R,
// small angles included, and the shortest rotation near π.
TEST(OrientationError, WorldRotationVector) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) *
                             Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix();
  for (const Eigen::Vector3d& w : {Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0.3, -0.2, 0.5),
                                  Eigen::Vector3d(1e-9, -2e-9, 3e-9), Eigen::Vector3d(0, 0, 3.0)}) {
    const Eigen::Matrix3d R_ref = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * R;
    EXPECT_LT((hqp::tasks::orientationError(R_ref, R) - w).norm(), 1e-12 * std::max(1.0, w.norm()))
        << w.transpose();
  }
  EXPECT_LT(hqp::tasks::orientationError(R, R).norm(), 1e-15);
  // 3.3 rad about z is −(2π − 3.3) about z: the shorter way.
  const Eigen::Matrix3d R_far = Eigen::AngleAxisd(3.3, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
  EXPECT_LT((hqp::tasks::orientationError(R_far, R) - Eigen::Vector3d(0, 0, 3.3 - 2 * 3.14159265358979323846)).norm(), 1e-12);
}

// update() of every task and constraint, solve(), τ_opt and the planner: no heap.
TEST_F(BalanceHierarchy, NoAllocationInUpdateAndSolve) {
  Hqp hqp;
  Wqp wqp;
  hqp::tasks::configureHierarchy(hqp, params);
  hqp::tasks::configureHierarchy(wqp, params);
  hqp::tasks::TaskPlanner<2> planner;
  planner.configure(hqp::tasks::PlannerParameters{}, Robot::total_mass);
  Refs r;
  const std::array<Eigen::Vector2d, 2> cop{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  const std::array<bool, 2> contact{true, true};
  VectorJ tau = VectorJ::Zero();
  const long before = g_news.load();
  Eigen::internal::set_is_malloc_allowed(false);
  for (int it = 0; it < 3; ++it) {
    planner.update(dyn, cop, contact, r);
    hqp::tasks::updateHierarchy(hqp, dyn, r);
    hqp.solve();
    tau += hqp::tasks::jointTorque<Layout>(dyn, hqp.x());
    hqp::tasks::updateHierarchy(wqp, dyn, r);
    wqp.solve();
    tau += hqp::tasks::jointTorque<Layout>(dyn, wqp.x());
  }
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(g_news.load(), before);
  EXPECT_TRUE(tau.allFinite());
  EXPECT_EQ(hqp.result().levels[0].status, hqp::QpStatus::Optimal);
}

}  // namespace
