// Joint-level control (Sec. V-A): the friction law of eq. 7 and the current
// command of eqs. 5 and 8, against hand-computed numbers.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "tasks/friction_model.hpp"
#include "tasks/joint_controller.hpp"

namespace {

using hqp::tasks::JointFriction;
using hqp::tasks::frictionTorque;

const JointFriction kF{5.0, 2.0, 0.1};  // F_c = 5 N·m, F_v = 2 N·m·s/rad, q̇* = 0.1 rad/s

TEST(FrictionModel, UpperBranch) {
  EXPECT_NEAR(frictionTorque(kF, 0.3), 5.0 + 2.0 * 0.2, 1e-12);  // 5.4
  EXPECT_NEAR(frictionTorque(kF, 1.1), 7.0, 1e-12);
}

TEST(FrictionModel, LinearBand) {
  EXPECT_NEAR(frictionTorque(kF, 0.05), 2.5, 1e-12);  // F_c q̇ / q̇*
  EXPECT_NEAR(frictionTorque(kF, -0.02), -1.0, 1e-12);
  EXPECT_EQ(frictionTorque(kF, 0.0), 0.0);
}

TEST(FrictionModel, LowerBranch) {
  EXPECT_NEAR(frictionTorque(kF, -0.3), -5.4, 1e-12);
  EXPECT_NEAR(frictionTorque(kF, -1.1), -7.0, 1e-12);
}

TEST(FrictionModel, ContinuousAtBandEdges) {
  for (double edge : {kF.dq_star, -kF.dq_star}) {
    const double below = std::nextafter(edge, -1.0);
    const double above = std::nextafter(edge, 1.0);
    EXPECT_NEAR(frictionTorque(kF, below), frictionTorque(kF, above), 1e-12) << edge;
    EXPECT_NEAR(frictionTorque(kF, edge), std::copysign(kF.coulomb, edge), 1e-12);
  }
  // Slope inside the band F_c / q̇* = 50, outside F_v = 2: one-sided differences.
  const double h = 1e-7;
  EXPECT_NEAR((frictionTorque(kF, 0.1) - frictionTorque(kF, 0.1 - h)) / h, 50.0, 1e-5);
  EXPECT_NEAR((frictionTorque(kF, 0.1 + h) - frictionTorque(kF, 0.1)) / h, 2.0, 1e-5);
}

TEST(FrictionModel, OddSymmetry) {
  for (double v = -2.0; v <= 2.0; v += 0.0137) {
    EXPECT_DOUBLE_EQ(frictionTorque(kF, -v), -frictionTorque(kF, v)) << v;
  }
}

using Controller2 = hqp::tasks::JointController<2>;
using V2 = Eigen::Vector2d;

hqp::tasks::JointControlParameters<2> params() {
  hqp::tasks::JointControlParameters<2> p;
  p.k_f << 0.5, 1.0;
  p.k_dq << 10.0, 4.0;
  p.torque_constant << 2.0, 4.0;
  p.current_limit << 100.0, 1.0;
  p.friction = {kF, JointFriction{1.0, 0.0, 0.01}};
  p.leak_time = 0.0;
  return p;
}

TEST(JointController, CurrentCommandByHand) {
  Controller2 jc;
  jc.configure(params());
  jc.reset(V2(0.2, 0.0));
  hqp::tasks::ActuatorCommand<2> out;
  jc.compute(V2(3.0, -1.0), V2(10.0, 0.0), V2(0.25, 0.0), 0.01, out);
  // joint 0: q̇_des = 0.2 + 10·0.01 = 0.3; τ_f = 5 + 2·0.2 = 5.4; τ_q̇ = 10 (0.3 − 0.25) = 0.5;
  // τ = 3 + 0.5·5.4 + 0.5 = 6.2; i = 6.2 / 2 = 3.1.
  EXPECT_NEAR(jc.desiredVelocity()[0], 0.3, 1e-15);
  EXPECT_NEAR(out.current[0], 3.1, 1e-12);
  EXPECT_NEAR(out.torque[0], 6.2, 1e-12);
  // joint 1: at rest: τ = −1, i = −0.25.
  EXPECT_NEAR(out.current[1], -0.25, 1e-15);
  EXPECT_NEAR(out.torque[1], -1.0, 1e-15);
  EXPECT_TRUE(jc.status().input_finite);
  EXPECT_EQ(jc.status().num_saturated, 0);
  EXPECT_FALSE(out.safe_mode);

  // Next tick, q̇_des carries on from 0.3; joint 1 moves: q̇_des = −0.005 (linear band,
  // τ_f = −0.5), τ_q̇ = 4 (−0.005 − (−0.01)) = 0.02, τ = 0 + 1·(−0.5) + 0.02 = −0.48, i = −0.12.
  jc.compute(V2(0.0, 0.0), V2(0.0, -0.5), V2(0.3, -0.01), 0.01, out);
  EXPECT_NEAR(jc.desiredVelocity()[0], 0.3, 1e-15);
  EXPECT_NEAR(out.current[0], 0.5 * 5.4 / 2.0, 1e-12);
  EXPECT_NEAR(jc.desiredVelocity()[1], -0.005, 1e-15);
  EXPECT_NEAR(out.current[1], -0.12, 1e-12);
}

TEST(JointController, CurrentSaturation) {
  Controller2 jc;
  jc.configure(params());
  jc.reset(V2::Zero());
  hqp::tasks::ActuatorCommand<2> out;
  jc.compute(V2(-20.0, 10.0), V2::Zero(), V2::Zero(), 0.001, out);
  EXPECT_NEAR(out.current[0], -10.0, 1e-15);  // within 100 A
  EXPECT_EQ(out.current[1], 1.0);             // 2.5 A asked, 1 A limit
  EXPECT_EQ(out.torque[1], 4.0);              // what the clamped current produces
  EXPECT_EQ(jc.status().num_saturated, 1);
  EXPECT_FALSE(jc.status().saturated[0]);
  EXPECT_TRUE(jc.status().saturated[1]);
  jc.compute(V2(0.0, -1e300), V2::Zero(), V2::Zero(), 0.001, out);
  EXPECT_EQ(out.current[1], -1.0);
}

TEST(JointController, LeakTowardMeasuredVelocity) {
  auto p = params();
  p.leak_time = 0.1;
  Controller2 jc;
  jc.configure(p);
  jc.reset(V2::Zero());
  hqp::tasks::ActuatorCommand<2> out;
  // q̈* = 0, q̇ = 1: first-order lag, exact discretisation: 1 − exp(−t / T).
  for (int k = 0; k < 10; ++k) jc.compute(V2::Zero(), V2::Zero(), V2(1.0, -2.0), 0.01, out);
  EXPECT_NEAR(jc.desiredVelocity()[0], 1.0 - std::exp(-1.0), 1e-12);
  EXPECT_NEAR(jc.desiredVelocity()[1], -2.0 * (1.0 - std::exp(-1.0)), 1e-12);
}

// A joint's own leak time overrides the global one; NaN keeps the global one. Each joint is
// an exact first-order lag toward q̇ with its own T: q̇_des(t) = q̇ (1 − exp(−t / T)).
TEST(JointController, PerJointLeakTime) {
  auto p = params();
  p.leak_time = 0.5;
  p.joint_leak_time << 0.05, std::numeric_limits<double>::quiet_NaN();
  Controller2 jc;
  jc.configure(p);
  jc.reset(V2::Zero());
  hqp::tasks::ActuatorCommand<2> out;
  for (int k = 0; k < 100; ++k) jc.compute(V2::Zero(), V2::Zero(), V2(1.0, 1.0), 0.001, out);  // 0.1 s
  EXPECT_NEAR(jc.desiredVelocity()[0], 1.0 - std::exp(-0.1 / 0.05), 1e-12);
  EXPECT_NEAR(jc.desiredVelocity()[1], 1.0 - std::exp(-0.1 / 0.5), 1e-12);
  // An infinite own leak time on joint 1 is the pure integral even with a global leak.
  p.joint_leak_time << std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity();
  jc.configure(p);
  jc.reset(V2::Zero());
  for (int k = 0; k < 100; ++k) jc.compute(V2::Zero(), V2(2.0, 2.0), V2::Zero(), 0.001, out);
  // Joint 0: x' = a − x / T from 0, discretised exactly per step: x_n = a dt Σ_{i=1..n} r^i, r = e^{−dt/T}.
  const double r = std::exp(-0.001 / 0.5);
  EXPECT_NEAR(jc.desiredVelocity()[0], 2.0 * 0.001 * r * (1.0 - std::pow(r, 100)) / (1.0 - r), 1e-12);
  EXPECT_NEAR(jc.desiredVelocity()[1], 0.2, 1e-12);
}

TEST(JointController, NoLeakIsPureIntegral) {
  for (double T : {0.0, std::numeric_limits<double>::infinity()}) {
    auto p = params();
    p.leak_time = T;
    Controller2 jc;
    jc.configure(p);
    jc.reset(V2(0.5, 0.0));
    hqp::tasks::ActuatorCommand<2> out;
    for (int k = 0; k < 100; ++k) jc.compute(V2::Zero(), V2(1.0, -3.0), V2(7.0, 7.0), 0.001, out);
    EXPECT_NEAR(jc.desiredVelocity()[0], 0.6, 1e-12) << T;
    EXPECT_NEAR(jc.desiredVelocity()[1], -0.3, 1e-12) << T;
    jc.reset(V2(-1.0, 2.0));
    EXPECT_EQ(jc.desiredVelocity(), V2(-1.0, 2.0));
  }
}

TEST(JointController, NonFiniteInputGivesZeroCurrent) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Controller2 jc;
  jc.configure(params());
  jc.reset(V2(0.1, 0.2));
  hqp::tasks::ActuatorCommand<2> out;
  const V2 ok(1.0, 1.0);
  struct Case {
    V2 tau, ddq, dq;
    double dt;
  };
  const Case cases[] = {{V2(nan, 1.0), ok, ok, 0.001}, {ok, V2(1.0, inf), ok, 0.001},
                        {ok, ok, V2(-inf, 0.0), 0.001}, {ok, ok, ok, nan},
                        {ok, ok, ok, -0.001}};
  for (const Case& c : cases) {
    out.current.setConstant(5.0);
    out.torque.setConstant(5.0);
    out.safe_mode = false;
    jc.compute(c.tau, c.ddq, c.dq, c.dt, out);
    EXPECT_TRUE(out.current.isZero(0.0));
    EXPECT_TRUE(out.torque.isZero(0.0));
    EXPECT_TRUE(out.safe_mode);
    EXPECT_FALSE(jc.status().input_finite);
    EXPECT_EQ(jc.desiredVelocity(), V2(0.1, 0.2));  // integrator untouched
  }
  // A finite but overflowing demand with no current limit: still finite (zero) output.
  auto p = params();
  p.current_limit.setConstant(inf);
  p.torque_constant << 1e-300, 1.0;
  jc.configure(p);
  jc.compute(V2(1e300, 0.0), V2::Zero(), V2::Zero(), 0.001, out);
  EXPECT_TRUE(out.current.allFinite());
  EXPECT_TRUE(out.torque.allFinite());
}

}  // namespace
