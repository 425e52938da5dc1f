// The task planner of Section III-A on the Walker3 model: the safe-region rule (follow /
// hold, both margins, contact flag, NaN), the CoM midpoint + C rule, the mean velocity, the
// upright torso at the feet's heading, F_ref = m g / 2, and reset(). Expected values are
// closed forms of the crouch in robots/walker3/README.md (soles at (0.02, ±0.09, 0) below a
// base at the origin of x and y) and that file's MuJoCo figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "model/configuration.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/task_planner.hpp"
#include "walker3_model.hpp"

namespace {

using Robot = walker3::Robot;
using Dyn = hqp::tasks::ContactLayout<Robot, 2, 6>::Dynamics;
using VectorQ = Eigen::Matrix<double, Robot::nq, 1>;
using VectorV = Eigen::Matrix<double, Robot::nv, 1>;
using Refs = hqp::tasks::References<2>;
using Cop = std::array<Eigen::Vector2d, 2>;

constexpr double kBaseHeight = 0.976055732;  // crouch, soles on z = 0 (README, MuJoCo)
constexpr double kSoleX = 0.02, kSoleY = 0.09;

// The README crouch: hip pitch −0.3, knee 0.6, ankle pitch −0.3; base at (x, y, 0.976) with yaw.
VectorQ crouch(double x = 0.0, double y = 0.0, double yaw = 0.0) {
  VectorQ q = hqp::model::neutralConfiguration<Robot>();
  q(0) = x;
  q(1) = y;
  q(2) = kBaseHeight;
  q(3) = std::cos(0.5 * yaw);
  q(6) = std::sin(0.5 * yaw);
  for (int j : {Robot::Joints::l_hip_pitch, Robot::Joints::r_hip_pitch}) q(7 + j) = -0.3;
  for (int j : {Robot::Joints::l_knee, Robot::Joints::r_knee}) q(7 + j) = 0.6;
  for (int j : {Robot::Joints::l_ankle_pitch, Robot::Joints::r_ankle_pitch}) q(7 + j) = -0.3;
  return q;
}

class Planner : public ::testing::Test {
 protected:
  Planner() : dyn({Robot::Frames::l_sole, Robot::Frames::r_sole, Robot::Frames::imu}) {
    params.safe_margin = 0.02;
    params.com_height = 0.8;
    params.sole_x_min = -0.11;
    params.sole_x_max = 0.11;
    params.sole_y_min = -0.05;
    params.sole_y_max = 0.05;
    planner.configure(params, Robot::total_mass);
  }
  void at(const VectorQ& q, const VectorV& v = VectorV::Zero()) { dyn.calcWbcDependence(q, v); }
  void step(const Cop& cop, std::array<bool, 2> contact = {true, true}) {
    planner.update(dyn, cop, contact, refs);
  }

  Dyn dyn;
  hqp::tasks::PlannerParameters params;
  hqp::tasks::TaskPlanner<2> planner;
  Refs refs;
  Cop centre{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
};

TEST_F(Planner, CrouchGeometry) {
  // Premise of the closed forms below, on the model.
  at(crouch());
  EXPECT_LT((dyn.placement(0).translation() - Eigen::Vector3d(kSoleX, kSoleY, 0)).norm(), 1e-8);
  EXPECT_LT((dyn.placement(1).translation() - Eigen::Vector3d(kSoleX, -kSoleY, 0)).norm(), 1e-8);
}

TEST_F(Planner, FollowsFeetWithZmpInSafeRegion) {
  at(crouch());
  step(centre);
  for (int c = 0; c < 2; ++c) {
    EXPECT_TRUE(planner.inSafeRegion(c));
    EXPECT_TRUE(refs.contact_pose[c].matrix().isApprox(dyn.placement(c).matrix(), 1e-15));
    EXPECT_TRUE(refs.contact_velocity[c].isZero(0.0));
    EXPECT_TRUE(refs.contact_acceleration[c].isZero(0.0));
  }
  // The robot moves 5 cm forward with both ZMPs well inside: the references follow.
  at(crouch(0.05));
  step(centre);
  EXPECT_NEAR(refs.contact_pose[0].translation().x(), kSoleX + 0.05, 1e-8);
  EXPECT_NEAR(refs.contact_pose[1].translation().x(), kSoleX + 0.05, 1e-8);
}

TEST_F(Planner, ComIsMidpointOfFeetPlusC) {
  at(crouch());
  step(centre);
  EXPECT_NEAR(refs.com.x(), kSoleX, 1e-8);
  EXPECT_NEAR(refs.com.y(), 0.0, 1e-8);
  EXPECT_NEAR(refs.com.z(), 0.0 + params.com_height, 1e-8);
  EXPECT_TRUE(refs.com_velocity.isZero(0.0));
  EXPECT_TRUE(refs.com_acceleration.isZero(0.0));
}

TEST_F(Planner, AutomaticCIsTheCoMHeightOfTheStartPose) {
  params.com_height = 0.0;
  planner.configure(params, Robot::total_mass);
  at(crouch());
  step(centre);
  EXPECT_NEAR(planner.comHeight(), 0.83812, 1e-5);  // README: CoM z in the crouch (MuJoCo)
  EXPECT_NEAR(refs.com.z(), 0.83812, 1e-5);
}

TEST_F(Planner, ForceReferenceIsHalfTheWeight) {
  at(crouch());
  step(centre);
  for (int c = 0; c < 2; ++c) {
    hqp::model::Vector6 expected = hqp::model::Vector6::Zero();
    expected(2) = 43.0 * 9.81 / 2.0;
    EXPECT_LT((refs.contact_force[c] - expected).norm(), 1e-9);
  }
}

TEST_F(Planner, TorsoUprightAtTheFeetHeading) {
  at(crouch());
  step(centre);
  EXPECT_TRUE(refs.torso_orientation.isIdentity(1e-12));
  EXPECT_TRUE(refs.torso_angular_velocity.isZero(0.0));
  // Whole robot turned by 0.4 rad and moved: torso reference turned with it, still upright;
  // the CoM reference is the rotated midpoint.
  planner.reset();
  const double yaw = 0.4;
  at(crouch(0.3, -0.2, yaw));
  step(centre);
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(refs.torso_orientation.isApprox(Rz, 1e-12));
  const Eigen::Vector3d mid = Eigen::Vector3d(0.3, -0.2, 0) + Rz * Eigen::Vector3d(kSoleX, 0, 0);
  EXPECT_NEAR(refs.com.x(), mid.x(), 1e-8);
  EXPECT_NEAR(refs.com.y(), mid.y(), 1e-8);
}

TEST_F(Planner, HoldsFootWhoseZmpLeavesTheSafeRegion) {
  at(crouch());
  step(centre);
  at(crouch(0.05));
  // Left ZMP 1 mm beyond the front margin (0.11 − 0.02 = 0.09), right ZMP 0.1 mm inside it.
  step({Eigen::Vector2d(0.091, 0.0), Eigen::Vector2d(0.0899, 0.0)});
  EXPECT_FALSE(planner.inSafeRegion(0));
  EXPECT_TRUE(planner.inSafeRegion(1));
  EXPECT_NEAR(refs.contact_pose[0].translation().x(), kSoleX, 1e-8);          // held
  EXPECT_NEAR(refs.contact_pose[1].translation().x(), kSoleX + 0.05, 1e-8);   // follows
  EXPECT_TRUE(refs.contact_velocity[0].isZero(0.0));
  // The CoM reference uses the held reference: midpoint of 0.02 and 0.07.
  EXPECT_NEAR(refs.com.x(), kSoleX + 0.025, 1e-8);
  // Back at the centre: follows again.
  step(centre);
  EXPECT_TRUE(planner.inSafeRegion(0));
  EXPECT_NEAR(refs.contact_pose[0].translation().x(), kSoleX + 0.05, 1e-8);
}

TEST_F(Planner, SafeRegionMarginsOnEverySide) {
  at(crouch());
  const double m = params.safe_margin;
  const struct { Eigen::Vector2d zmp; bool safe; } cases[] = {
      {{0.11 - m - 1e-4, 0.0}, true},  {{0.11 - m + 1e-4, 0.0}, false},
      {{-0.11 + m + 1e-4, 0.0}, true}, {{-0.11 + m - 1e-4, 0.0}, false},
      {{0.0, 0.05 - m - 1e-4}, true},  {{0.0, 0.05 - m + 1e-4}, false},
      {{0.0, -0.05 + m + 1e-4}, true}, {{0.0, -0.05 + m - 1e-4}, false},
  };
  for (const auto& k : cases) {
    step({k.zmp, Eigen::Vector2d::Zero()});
    EXPECT_EQ(planner.inSafeRegion(0), k.safe) << k.zmp.transpose();
    EXPECT_TRUE(planner.inSafeRegion(1));
  }
}

TEST_F(Planner, HoldsFootOutOfContactOrWithNonFiniteZmp) {
  at(crouch());
  step(centre);
  at(crouch(0.05));
  step(centre, {false, true});
  EXPECT_FALSE(planner.inSafeRegion(0));
  EXPECT_NEAR(refs.contact_pose[0].translation().x(), kSoleX, 1e-8);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  step({Eigen::Vector2d(nan, 0.0), Eigen::Vector2d(0.0, nan)});
  EXPECT_FALSE(planner.inSafeRegion(0));
  EXPECT_FALSE(planner.inSafeRegion(1));
  EXPECT_NEAR(refs.contact_pose[0].translation().x(), kSoleX, 1e-8);
  EXPECT_NEAR(refs.contact_pose[1].translation().x(), kSoleX + 0.05, 1e-8);
  EXPECT_TRUE(refs.com.allFinite());
}

TEST_F(Planner, ComVelocityIsTheMeanFootVelocity) {
  // Every frame of a robot translating rigidly (base twist only, identity orientation) moves
  // with the base velocity: both feet and so their mean.
  VectorV v = VectorV::Zero();
  v.head<3>() << 0.1, -0.2, 0.05;
  at(crouch(), v);
  step(centre);
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT((refs.contact_velocity[c].head<3>() - v.head<3>()).norm(), 1e-12);
    EXPECT_LT(refs.contact_velocity[c].tail<3>().norm(), 1e-12);
  }
  EXPECT_LT((refs.com_velocity - v.head<3>()).norm(), 1e-12);
  // One foot held (zero velocity reference): the mean halves.
  step({Eigen::Vector2d(0.1, 0.0), Eigen::Vector2d::Zero()});
  EXPECT_LT((refs.com_velocity - 0.5 * v.head<3>()).norm(), 1e-12);
}

TEST_F(Planner, ResetReinitialisesFromTheState) {
  at(crouch());
  step(centre);
  at(crouch(0.05));
  step({Eigen::Vector2d(0.1, 0.0), Eigen::Vector2d(0.1, 0.0)});  // both held
  EXPECT_NEAR(refs.contact_pose[0].translation().x(), kSoleX, 1e-8);
  planner.reset();
  step({Eigen::Vector2d(0.1, 0.0), Eigen::Vector2d(0.1, 0.0)});  // still outside, but re-initialised
  EXPECT_NEAR(refs.contact_pose[0].translation().x(), kSoleX + 0.05, 1e-8);
  EXPECT_NEAR(refs.contact_pose[1].translation().x(), kSoleX + 0.05, 1e-8);
  EXPECT_FALSE(planner.inSafeRegion(0));
}

}  // namespace

// Moving-support extensions (docs/tasks.md "Moving supports"): a foot whose ZMP left the safe
// region keeps following its translation but holds its orientation.
TEST_F(Planner, FollowTranslationHoldsOnlyTheOrientation) {
  params.follow_translation = true;
  planner.configure(params, Robot::total_mass);
  at(crouch());
  step(centre);
  // The whole robot turned by 0.2 rad, moved 5 cm and translating at v: left ZMP outside.
  VectorV v = VectorV::Zero();
  v.head<3>() << 0.1, -0.2, 0.05;
  at(crouch(0.05, 0.0, 0.2), v);
  step({Eigen::Vector2d(0.095, 0.0), Eigen::Vector2d::Zero()});
  EXPECT_FALSE(planner.inSafeRegion(0));
  EXPECT_LT((refs.contact_pose[0].translation() - dyn.placement(0).translation()).norm(), 1e-12);
  EXPECT_TRUE(refs.contact_pose[0].linear().isIdentity(1e-12)) << "orientation held at the start pose";
  EXPECT_LT((refs.contact_velocity[0].head<3>() - dyn.velocity(0).head<3>()).norm(), 1e-12);
  EXPECT_TRUE(refs.contact_velocity[0].tail<3>().isZero(0.0));
  // The right foot follows everything, as in the paper.
  EXPECT_TRUE(refs.contact_pose[1].matrix().isApprox(dyn.placement(1).matrix(), 1e-12));
  // Out of contact, the whole pose is held even with the option.
  const Eigen::Vector3d held = refs.contact_pose[0].translation();
  at(crouch(0.1, 0.0, 0.2), v);
  step(centre, {false, true});
  EXPECT_LT((refs.contact_pose[0].translation() - held).norm(), 1e-12);
  EXPECT_TRUE(refs.contact_velocity[0].isZero(0.0));
}

// A following foot gets the low-passed finite difference of its velocity as feed-forward
// acceleration: for a constant acceleration a the filter (gain α = 1 − exp(−2π f_c dt) per
// tick) gives a (1 − (1 − α)^n) after n differences.
TEST_F(Planner, FeedForwardAccelerationOfAFollowingFoot) {
  const double fc = 20.0, dt = 0.001, a = 2.0;
  params.follow_acceleration_cutoff = fc;
  planner.configure(params, Robot::total_mass, dt);
  const double alpha = 1.0 - std::exp(-2.0 * M_PI * fc * dt);
  VectorV v = VectorV::Zero();
  for (int k = 0; k <= 50; ++k) {
    v(0) = a * k * dt;  // the robot translates rigidly along x with acceleration a
    at(crouch(0.5 * a * k * dt * k * dt), v);
    step(centre);
    const double expected = a * (1.0 - std::pow(1.0 - alpha, k));
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(refs.contact_acceleration[c](0), expected, 1e-9) << "tick " << k;
      EXPECT_NEAR(refs.contact_acceleration[c].tail<5>().norm(), 0.0, 1e-9);
    }
  }
  // A held foot gets no feed-forward.
  step({Eigen::Vector2d(0.1, 0.0), Eigen::Vector2d::Zero()});
  EXPECT_TRUE(refs.contact_acceleration[0].isZero(0.0));
  EXPECT_GT(refs.contact_acceleration[1](0), 0.5 * a);
}

// Two cascaded stages and a deadband: a constant acceleration a through two identical first-order
// stages (gain α) gives the closed form a (1 − βᵏ − α k βᵏ), β = 1 − α (the step response of the
// cascade), and the deadband d takes max(· − d, 0) of it.
TEST_F(Planner, FeedForwardThroughTwoStagesAndADeadband) {
  const double fc = 20.0, dt = 0.001, a = 2.0, d = 0.5;
  params.follow_acceleration_cutoff = fc;
  params.follow_acceleration_order = 2;
  params.follow_acceleration_deadband_linear = d;
  params.follow_acceleration_deadband_angular = 0.1;
  planner.configure(params, Robot::total_mass, dt);
  const double alpha = 1.0 - std::exp(-2.0 * M_PI * fc * dt), beta = 1.0 - alpha;
  VectorV v = VectorV::Zero();
  for (int k = 0; k <= 300; ++k) {
    v(0) = a * k * dt;
    at(crouch(0.5 * a * k * dt * k * dt), v);
    step(centre);
    const double filtered = a * (1.0 - std::pow(beta, k) - alpha * k * std::pow(beta, k));
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(refs.contact_acceleration[c](0), std::max(filtered - d, 0.0), 1e-9) << "tick " << k;
      EXPECT_NEAR(refs.contact_acceleration[c].tail<5>().norm(), 0.0, 1e-9);
    }
  }
  EXPECT_NEAR(refs.contact_acceleration[0](0), a - d, 1e-6);  // settled
}

// White noise on the measured foot velocity: two stages pass far less of its finite difference
// than one (the second stage rolls off the derivative's high frequencies), and a deadband above
// what remains gives no feed-forward at all, so a foot on still ground is not shaken.
TEST_F(Planner, FeedForwardRejectsVelocityNoise) {
  auto noiseStd = [&](int order, double deadband) {
    params.follow_acceleration_cutoff = 20.0;
    params.follow_acceleration_order = order;
    params.follow_acceleration_deadband_linear = deadband;
    params.follow_acceleration_deadband_angular = deadband;
    planner.configure(params, Robot::total_mass, 0.001);
    std::mt19937 rng(7);
    std::normal_distribution<double> n(0.0, 0.02);  // rad/s, the plant's encoder velocity noise
    double sum2 = 0.0;
    int count = 0;
    for (int k = 0; k < 4000; ++k) {
      VectorV v = VectorV::Zero();
      for (int j = 6; j < Robot::nv; ++j) v(j) = n(rng);
      at(crouch(), v);
      step(centre);
      if (k < 500) continue;  // the filters' start
      sum2 += refs.contact_acceleration[0].squaredNorm();
      ++count;
    }
    return std::sqrt(sum2 / count);
  };
  const double one = noiseStd(1, 0.0), two = noiseStd(2, 0.0);
  EXPECT_GT(one, 1.0);  // m/s², rad/s²: the raw feed-forward is mostly noise
  EXPECT_LT(two, 0.4 * one);
  EXPECT_EQ(noiseStd(2, 10.0 * two), 0.0);
}

// hold_tipping_axis: outside the safe region only the rotation about the edge the ZMP is near
// is held (x edge: pitch about the sole's y axis; y edge: roll about its x axis); yaw and the
// other tilt follow the foot. The whole robot is rotated rigidly about one world axis, so the
// soles' measured orientation is that rotation (the soles are level in the crouch).
TEST_F(Planner, HoldTippingAxisHoldsOnlyTheAxisOfTheNearEdge) {
  params.follow_translation = true;
  params.hold_tipping_axis = true;
  const Eigen::Vector2d near_x_edge(0.095, 0.0), near_y_edge(0.0, 0.045);
  struct Case {
    Eigen::Vector3d axis;
    Eigen::Vector2d zmp;
    bool followed;
  };
  const Case cases[] = {{Eigen::Vector3d::UnitX(), near_x_edge, true},   // roll, toe edge: follows
                        {Eigen::Vector3d::UnitX(), near_y_edge, false},  // roll, side edge: held
                        {Eigen::Vector3d::UnitY(), near_x_edge, false},  // pitch, toe edge: held
                        {Eigen::Vector3d::UnitY(), near_y_edge, true},   // pitch, side edge: follows
                        {Eigen::Vector3d::UnitZ(), near_x_edge, true},   // yaw: always follows
                        {Eigen::Vector3d::UnitZ(), near_y_edge, true}};
  for (const Case& k : cases) {
    planner.configure(params, Robot::total_mass);
    at(crouch());
    step(centre);
    VectorQ q = crouch();
    const Eigen::Quaterniond rot(Eigen::AngleAxisd(0.05, k.axis));
    q(3) = rot.w();
    q.segment<3>(4) = rot.vec();
    VectorV v = VectorV::Zero();
    v.segment<3>(3) = 0.3 * k.axis;  // base angular velocity (base frame = world axes here up to 0.05 rad)
    at(q, v);
    step({k.zmp, Eigen::Vector2d::Zero()});
    SCOPED_TRACE(testing::Message() << "axis " << k.axis.transpose() << ", ZMP " << k.zmp.transpose());
    const Eigen::Matrix3d expected = k.followed ? Eigen::Matrix3d(dyn.placement(0).linear()) : Eigen::Matrix3d::Identity();
    EXPECT_TRUE(refs.contact_pose[0].linear().isApprox(expected, 1e-9)) << refs.contact_pose[0].linear();
    const Eigen::Vector3d w = dyn.velocity(0).tail<3>();
    EXPECT_GT(w.norm(), 0.1);
    EXPECT_LT((refs.contact_velocity[0].tail<3>() - (k.followed ? w : Eigen::Vector3d::Zero())).norm(), 1e-9);
    EXPECT_LT((refs.contact_pose[0].translation() - dyn.placement(0).translation()).norm(), 1e-12);
  }
}

// hold_one_sided: a held axis is held only against tipping over the edge the ZMP is at. Tipping
// over a +y side edge is a negative roll, over the toe a positive pitch (the sole centre lifts);
// a sole turned the other way from the held (level) orientation is followed.
TEST_F(Planner, HoldOneSidedFollowsASoleTurnedAwayFromTipping) {
  params.follow_translation = true;
  params.hold_tipping_axis = true;
  params.hold_one_sided = true;
  struct Case {
    Eigen::Vector3d axis;
    double angle;
    Eigen::Vector2d zmp;
    bool followed;
  };
  const Case cases[] = {{Eigen::Vector3d::UnitX(), -0.05, {0.0, 0.045}, false},  // rolls over the +y edge: held
                        {Eigen::Vector3d::UnitX(), 0.05, {0.0, 0.045}, true},    // pressed flatter: followed
                        {Eigen::Vector3d::UnitX(), 0.05, {0.0, -0.045}, false},  // over the −y edge: held
                        {Eigen::Vector3d::UnitX(), -0.05, {0.0, -0.045}, true},
                        {Eigen::Vector3d::UnitY(), 0.05, {0.095, 0.0}, false},   // over the toe: held
                        {Eigen::Vector3d::UnitY(), -0.05, {0.095, 0.0}, true},
                        {Eigen::Vector3d::UnitY(), -0.05, {-0.095, 0.0}, false},  // over the heel: held
                        {Eigen::Vector3d::UnitY(), 0.05, {-0.095, 0.0}, true}};
  for (const Case& k : cases) {
    planner.configure(params, Robot::total_mass);
    at(crouch());
    step(centre);
    VectorQ q = crouch();
    const Eigen::Quaterniond rot(Eigen::AngleAxisd(k.angle, k.axis));
    q(3) = rot.w();
    q.segment<3>(4) = rot.vec();
    VectorV v = VectorV::Zero();
    v.segment<3>(3) = (k.angle > 0.0 ? 0.3 : -0.3) * k.axis;
    at(q, v);
    step({k.zmp, Eigen::Vector2d::Zero()});
    SCOPED_TRACE(testing::Message() << "axis " << k.axis.transpose() << " angle " << k.angle << ", ZMP " << k.zmp.transpose());
    // The sole is level in the crouch, so the held orientation is the identity.
    const Eigen::Matrix3d expected = k.followed ? Eigen::Matrix3d(dyn.placement(0).linear()) : Eigen::Matrix3d::Identity();
    EXPECT_TRUE(refs.contact_pose[0].linear().isApprox(expected, 1e-9)) << refs.contact_pose[0].linear();
    const Eigen::Vector3d w = dyn.velocity(0).tail<3>();
    EXPECT_LT((refs.contact_velocity[0].tail<3>() - (k.followed ? w : Eigen::Vector3d::Zero())).norm(), 1e-9);
  }
}
