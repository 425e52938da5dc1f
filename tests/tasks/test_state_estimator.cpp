// State estimator: sensor readings are synthesised from a known true state with
// the model's world-frame kinematics (frame placements and velocities at the
// true base pose), an independent path from the estimator's base-relative one.
// One test checks that update() (and JointController::compute) never allocate.
#define EIGEN_RUNTIME_NO_MALLOC
#include <Eigen/Core>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <utility>

#include <gtest/gtest.h>

#include "model/configuration.hpp"
#include "model/frames.hpp"
#include "model/kinematics.hpp"
#include "tasks/joint_controller.hpp"
#include "tasks/state_estimator.hpp"
#include "quadruped_model.hpp"
#include "walker3_model.hpp"
#include "support/allocation_counter.hpp"

using hqp::testing::g_counting;
using hqp::testing::g_news;

namespace {

using Robot = walker3::Robot;
using Data = hqp::model::Data<Robot>;
using VectorQ = Data::VectorQ;
using VectorV = Data::VectorV;
using Estimator = hqp::tasks::StateEstimator<Robot, 2>;
using Sensors = hqp::tasks::SensorData<Robot::nj, 2>;
using hqp::tasks::Vector6;

constexpr int kSole[2] = {Robot::Frames::l_sole, Robot::Frames::r_sole};
constexpr int kFt[2] = {Robot::Frames::l_ft_sensor, Robot::Frames::r_ft_sensor};

Estimator makeEstimator() {
  Estimator e({kSole[0], kSole[1]}, {kFt[0], kFt[1]}, Robot::Frames::imu);
  hqp::tasks::EstimatorParameters p;
  p.contact_threshold = 30.0;
  e.configure(p);
  return e;
}

// Crouched stance, base yawed and tilted a little, soles on z = 0 (left sole at the
// given xy); legs adjusted so both soles are flat at the base attitude chosen.
VectorQ standingState(const Eigen::Vector3d& left_sole_xy) {
  VectorQ q = hqp::model::neutralConfiguration<Robot>();
  for (const char* side : {"l_", "r_"}) {
    const std::string s(side);
    q[7 + Robot::jointIndex(s + "hip_pitch")] = -0.35;
    q[7 + Robot::jointIndex(s + "knee")] = 0.7;
    q[7 + Robot::jointIndex(s + "ankle_pitch")] = -0.3;
    q[7 + Robot::jointIndex(s + "hip_roll")] = s == "l_" ? 0.05 : -0.04;
    q[7 + Robot::jointIndex(s + "ankle_roll")] = s == "l_" ? -0.05 : 0.04;
  }
  const Eigen::Quaterniond quat(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()));
  q[3] = quat.w();
  q[4] = quat.x();
  q[5] = quat.y();
  q[6] = quat.z();
  Data d;
  hqp::model::forwardKinematics<Robot>(d, q);
  const Eigen::Vector3d sole = hqp::model::framePlacement<Robot>(d, kSole[0]).translation();
  q.head<3>() += left_sole_xy - sole;  // left sole at (x, y, 0)
  return q;
}

// Joint and base velocities that keep both soles at rest (6-D): base twist from the
// left leg's rates, right leg's rates from the base twist (world Jacobians at q).
VectorV stanceVelocity(const VectorQ& q, const Eigen::Matrix<double, 6, 1>& dq_left) {
  Data d;
  hqp::model::forwardKinematics<Robot>(d, q);
  Data::Jacobian Jl, Jr;
  hqp::model::frameJacobian<Robot>(d, kSole[0], Jl);
  hqp::model::frameJacobian<Robot>(d, kSole[1], Jr);
  const int l0 = 6 + Robot::Joints::l_hip_yaw, r0 = 6 + Robot::Joints::r_hip_yaw;
  VectorV v = VectorV::Zero();
  v.segment<6>(l0) = dq_left;
  const Eigen::Matrix<double, 6, 1> base =
      -Jl.leftCols<6>().fullPivLu().solve(Jl.middleCols<6>(l0) * dq_left);
  v.head<6>() = base;
  v.segment<6>(r0) = -Jr.middleCols<6>(r0).fullPivLu().solve(Jr.leftCols<6>() * base);
  return v;
}

// World wrench [f; m about p] → F/T reading in the sensor frame about its origin.
Vector6 ftReading(const Eigen::Isometry3d& X_ws, const Eigen::Vector3d& f_w,
                  const Eigen::Vector3d& m_w, const Eigen::Vector3d& p) {
  Vector6 r;
  r.head<3>() = X_ws.linear().transpose() * f_w;
  r.tail<3>() = X_ws.linear().transpose() * (m_w + (p - X_ws.translation()).cross(f_w));
  return r;
}

struct Truth {
  Data d;
  VectorQ q;
  VectorV v;
  Sensors s;
  Eigen::Isometry3d sole[2];
};

// Sensors for (q, v) with the given sole-frame wrenches [f; m about the sole origin].
void synthesise(Truth& t, const Vector6 sole_wrench[2]) {
  hqp::model::forwardKinematics<Robot>(t.d, t.q, t.v);
  const Eigen::Isometry3d X_wi = hqp::model::framePlacement<Robot>(t.d, Robot::Frames::imu);
  const Vector6 V_wi = hqp::model::frameVelocity<Robot>(t.d, Robot::Frames::imu);
  t.s.q = t.q.tail<Robot::nj>();
  t.s.dq = t.v.tail<Robot::nj>();
  t.s.imu_orientation = Eigen::Quaterniond(X_wi.linear());
  t.s.imu_gyro = X_wi.linear().transpose() * V_wi.tail<3>();
  t.s.imu_accel = X_wi.linear().transpose() * Eigen::Vector3d(0, 0, 9.81);
  for (int c = 0; c < 2; ++c) {
    t.sole[c] = hqp::model::framePlacement<Robot>(t.d, kSole[c]);
    const Eigen::Isometry3d X_wf = hqp::model::framePlacement<Robot>(t.d, kFt[c]);
    const Eigen::Matrix3d& R = t.sole[c].linear();
    t.s.ft[c] = ftReading(X_wf, R * sole_wrench[c].head<3>(), R * sole_wrench[c].tail<3>(),
                          t.sole[c].translation());
  }
}

Vector6 wrench(double fx, double fy, double fz, double mx, double my, double mz) {
  Vector6 w;
  w << fx, fy, fz, mx, my, mz;
  return w;
}

TEST(StateEstimator, TestStateIsConsistent) {
  // The synthetic state really has both soles flat on z = 0 and at rest.
  const VectorQ q = standingState(Eigen::Vector3d(0.3, -0.2, 0.0));
  Eigen::Matrix<double, 6, 1> dql;
  dql << 0.1, -0.2, 0.3, 0.4, -0.3, 0.2;
  const VectorV v = stanceVelocity(q, dql);
  Data d;
  hqp::model::forwardKinematics<Robot>(d, q, v);
  for (int c = 0; c < 2; ++c) {
    EXPECT_NEAR(hqp::model::framePlacement<Robot>(d, kSole[c]).translation().z(), 0.0, 1e-3);
    EXPECT_LT(hqp::model::frameVelocity<Robot>(d, kSole[c]).norm(), 1e-12);
  }
  EXPECT_GT(v.head<6>().norm(), 0.1);  // the base does move
}

TEST(StateEstimator, RecoversStateFromSensors) {
  Truth t;
  t.q = standingState(Eigen::Vector3d(0.3, -0.2, 0.0));
  Eigen::Matrix<double, 6, 1> dql;
  dql << 0.1, -0.2, 0.3, 0.4, -0.3, 0.2;
  t.v = stanceVelocity(t.q, dql);
  const Vector6 w[2] = {wrench(5, -3, 200, 2, -4, 0.5), wrench(-2, 1, 220, -1, 3, -0.2)};
  synthesise(t, w);

  Estimator e = makeEstimator();
  ASSERT_TRUE(e.valid());
  ASSERT_TRUE(e.update(t.s, 0.001));
  // Orientation: same rotation (quaternion up to sign), joints, velocity.
  const Eigen::Quaterniond qt(t.q[3], t.q[4], t.q[5], t.q[6]);
  const Eigen::Quaterniond qe(e.q()[3], e.q()[4], e.q()[5], e.q()[6]);
  EXPECT_NEAR(std::abs(qt.dot(qe)), 1.0, 1e-12);
  EXPECT_TRUE(e.q().tail<Robot::nj>().isApprox(t.q.tail<Robot::nj>(), 1e-15));
  EXPECT_LT((e.v() - t.v).norm(), 1e-9) << (e.v() - t.v).transpose();
  // Position: world origin below the base at the lowest sole's height.
  const double zmin = std::min(t.sole[0].translation().z(), t.sole[1].translation().z());
  EXPECT_NEAR(e.q()[0], 0.0, 1e-15);
  EXPECT_NEAR(e.q()[1], 0.0, 1e-15);
  EXPECT_NEAR(e.q()[2], t.q[2] - zmin, 1e-12);
  EXPECT_TRUE(e.inContact(0));
  EXPECT_TRUE(e.inContact(1));
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT((e.soleWrench(c) - w[c]).norm(), 1e-10) << c;
    EXPECT_NEAR(e.cop(c).x(), -w[c][4] / w[c][2], 1e-12);
    EXPECT_NEAR(e.cop(c).y(), w[c][3] / w[c][2], 1e-12);
  }
}

TEST(StateEstimator, StanceFeetGiveBasePositionWhileMoving) {
  // The base moves with stance-consistent velocities; the estimate must equal the
  // true base position minus the (second-order) drift of the feet since touch-down.
  Truth t;
  t.q = standingState(Eigen::Vector3d(0.0, 0.0, 0.0));
  const Vector6 w[2] = {wrench(0, 0, 210, 0, 0, 0), wrench(0, 0, 210, 0, 0, 0)};
  Estimator e = makeEstimator();
  const double dt = 0.002;
  Eigen::Vector3d foot0[2];
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  for (int k = 0; k < 200; ++k) {
    Eigen::Matrix<double, 6, 1> dql;
    const double s = std::sin(0.05 * k);
    dql << 0.05 * s, 0.1 * s, -0.4 * s, 0.6 * s, -0.3 * s, -0.1 * s;
    t.v = stanceVelocity(t.q, dql);
    synthesise(t, w);
    ASSERT_TRUE(e.update(t.s, dt));
    if (k == 0) {
      e.setBasePosition(t.q.head<3>());
      for (int c = 0; c < 2; ++c) foot0[c] = t.sole[c].translation();
    }
    Eigen::Vector3d expected = t.q.head<3>();
    for (int c = 0; c < 2; ++c) expected -= 0.5 * (t.sole[c].translation() - foot0[c]);
    EXPECT_LT((e.q().head<3>() - expected).norm(), 1e-9) << k;
    EXPECT_LT((e.v() - t.v).norm(), 1e-9) << k;
    offset = t.q.head<3>() - e.q().head<3>();
    t.q = hqp::model::integrate<Robot>(t.q, t.v, dt);
  }
  EXPECT_LT(offset.norm(), 1e-3);  // the feet drift only at second order
}

TEST(StateEstimator, LiftOffAndTouchDownLatches) {
  Truth t;
  t.q = standingState(Eigen::Vector3d(0.1, 0.1, 0.0));
  t.v.setZero();
  Vector6 w[2] = {wrench(0, 0, 400, 0, 0, 0), wrench(0, 0, 20, 0, 0, 0)};  // right below 30 N
  synthesise(t, w);
  Estimator e = makeEstimator();
  e.setBasePosition(Eigen::Vector3d(1.0, 2.0, 3.0));
  ASSERT_TRUE(e.update(t.s, 0.001));
  EXPECT_TRUE(e.inContact(0));
  EXPECT_FALSE(e.inContact(1));
  EXPECT_EQ(e.cop(1), Eigen::Vector2d::Zero());
  EXPECT_EQ(e.q().head<3>(), Eigen::Vector3d(1.0, 2.0, 3.0));
  const Eigen::Vector3d left = e.latchedFootPosition(0);
  EXPECT_LT((left - (Eigen::Vector3d(1.0, 2.0, 3.0) + t.sole[0].translation() - t.q.head<3>())).norm(),
            1e-12);
  // Right foot touches down: latched where the left-stance estimate puts it.
  w[1] = wrench(0, 0, 40, 0, 0, 0);
  synthesise(t, w);
  ASSERT_TRUE(e.update(t.s, 0.001));
  EXPECT_TRUE(e.inContact(1));
  const Eigen::Vector3d expected_right =
      Eigen::Vector3d(1.0, 2.0, 3.0) + t.sole[1].translation() - t.q.head<3>();
  EXPECT_LT((e.latchedFootPosition(1) - expected_right).norm(), 1e-12);
  EXPECT_LT((e.q().head<3>() - Eigen::Vector3d(1.0, 2.0, 3.0)).norm(), 1e-12);
}

TEST(StateEstimator, NoContactIntegratesTheAccelerometer) {
  // Free fall from rest: specific force 0, so the base falls with g.
  Truth t;
  t.q = standingState(Eigen::Vector3d::Zero());
  t.v.setZero();
  const Vector6 zero[2] = {Vector6::Zero(), Vector6::Zero()};
  synthesise(t, zero);
  t.s.imu_accel.setZero();
  Estimator e = makeEstimator();
  e.setBasePosition(Eigen::Vector3d::Zero());
  const double dt = 0.001;
  const int n = 100;
  for (int k = 0; k < n; ++k) ASSERT_TRUE(e.update(t.s, dt));
  const Eigen::Quaterniond quat(e.q()[3], e.q()[4], e.q()[5], e.q()[6]);
  const Eigen::Vector3d v_world = quat * e.v().head<3>();
  EXPECT_NEAR(v_world.z(), -9.81 * n * dt, 1e-12);
  EXPECT_NEAR(v_world.head<2>().norm(), 0.0, 1e-12);
  // p_k = p_{k−1} + v_k dt, v_k = −g k dt (the first update only sets the position).
  EXPECT_NEAR(e.q()[2], -9.81 * dt * dt * (n * (n + 1) / 2 - 1), 1e-12);
}

TEST(StateEstimator, VerticalForceAtAPointGivesThatCop) {
  Truth t;
  t.q = standingState(Eigen::Vector3d(0.2, 0.0, 0.0));
  t.v.setZero();
  const Vector6 zero[2] = {Vector6::Zero(), Vector6::Zero()};
  synthesise(t, zero);
  // 300 N along each sole's normal, applied at a point of the sole: moment about the
  // sensor origin by hand in world coordinates.
  const Eigen::Vector2d point[2] = {Eigen::Vector2d(0.04, -0.015), Eigen::Vector2d(-0.07, 0.03)};
  for (int c = 0; c < 2; ++c) {
    const Eigen::Isometry3d X_wf = hqp::model::framePlacement<Robot>(t.d, kFt[c]);
    const Eigen::Vector3d f = 300.0 * t.sole[c].linear().col(2);
    const Eigen::Vector3d r = t.sole[c] * Eigen::Vector3d(point[c].x(), point[c].y(), 0.0);
    t.s.ft[c].head<3>() = X_wf.linear().transpose() * f;
    t.s.ft[c].tail<3>() = X_wf.linear().transpose() * (r - X_wf.translation()).cross(f);
  }
  Estimator e = makeEstimator();
  ASSERT_TRUE(e.update(t.s, 0.001));
  for (int c = 0; c < 2; ++c) {
    EXPECT_TRUE(e.inContact(c));
    EXPECT_LT((e.cop(c) - point[c]).norm(), 1e-12) << c;
    EXPECT_NEAR(e.soleWrench(c)[2], 300.0, 1e-10);
  }
}

TEST(StateEstimator, NonFiniteInputIsRejected) {
  Truth t;
  t.q = standingState(Eigen::Vector3d::Zero());
  t.v.setZero();
  const Vector6 w[2] = {wrench(0, 0, 210, 0, 0, 0), wrench(0, 0, 210, 0, 0, 0)};
  synthesise(t, w);
  Estimator e = makeEstimator();
  ASSERT_TRUE(e.update(t.s, 0.001));
  const VectorQ q0 = e.q();
  const VectorV v0 = e.v();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int which = 0; which < 8; ++which) {
    Sensors s = t.s;
    double dt = 0.001;
    switch (which) {
      case 0: s.q[3] = nan; break;
      case 1: s.dq[11] = inf; break;
      case 2: s.imu_orientation.x() = nan; break;
      case 3: s.imu_gyro.y() = -inf; break;
      case 4: s.imu_accel.z() = nan; break;
      case 5: s.ft[1][4] = nan; break;
      case 6: dt = nan; break;
      default: s.imu_orientation.coeffs().setZero(); break;
    }
    EXPECT_FALSE(e.update(s, dt)) << which;
    EXPECT_EQ(e.q(), q0) << which;
    EXPECT_EQ(e.v(), v0) << which;
  }
  EXPECT_TRUE(e.update(t.s, 0.001));
}

TEST(StateEstimator, UpdateAndJointControlDoNotAllocate) {
  Truth t;
  t.q = standingState(Eigen::Vector3d::Zero());
  Eigen::Matrix<double, 6, 1> dql;
  dql << 0.1, -0.2, 0.3, 0.4, -0.3, 0.2;
  t.v = stanceVelocity(t.q, dql);
  Vector6 w[2] = {wrench(0, 0, 210, 1, 2, 0), wrench(0, 0, 210, 0, -1, 0)};
  synthesise(t, w);
  Sensors flight = t.s;
  flight.ft[0].setZero();
  flight.ft[1].setZero();
  Sensors bad = t.s;
  bad.q[0] = std::numeric_limits<double>::quiet_NaN();
  Estimator e = makeEstimator();
  hqp::tasks::JointController<Robot::nj> jc;
  jc.configure(hqp::tasks::JointControlParameters<Robot::nj>{});
  hqp::tasks::ActuatorCommand<Robot::nj> out;
  const Eigen::Matrix<double, Robot::nj, 1> tau = Eigen::Matrix<double, Robot::nj, 1>::Constant(3.0);
  g_news = 0;
  g_counting = true;
  Eigen::internal::set_is_malloc_allowed(false);
  bool ok = true;
  for (int k = 0; k < 10; ++k) {
    ok = ok && e.update(k < 5 ? t.s : flight, 0.001);
    ok = ok && !e.update(bad, 0.001);
    jc.compute(tau, tau, t.s.dq, 0.001, out);
  }
  Eigen::internal::set_is_malloc_allowed(true);
  g_counting = false;
  EXPECT_TRUE(ok);
  EXPECT_EQ(g_news.load(), 0);
}

TEST(StateEstimator, InvalidFramesAreReported) {
  Estimator e({kSole[0], Robot::nframes}, {kFt[0], kFt[1]}, Robot::Frames::imu);
  EXPECT_FALSE(e.valid());
  Sensors s;
  EXPECT_FALSE(e.update(s, 0.001));
}

TEST(StateEstimator, RotatedImuMountIsUndone) {
  // The quadruped's IMU is mounted yawed by 90° on the trunk: the estimator must
  // undo that fixed rotation for both orientation and angular velocity.
  using Q = quadruped::Robot;
  using QData = hqp::model::Data<Q>;
  const int imu = Q::frameIndex("imu");
  ASSERT_GE(imu, 0);
  const Eigen::Matrix3d R_bi = hqp::model::framePlacement<Q>(QData(), imu).linear();
  ASSERT_GT((R_bi - Eigen::Matrix3d::Identity()).norm(), 1.0);  // the mount is rotated
  std::array<int, 4> feet;
  const char* names[4] = {"lf_foot", "rf_foot", "lh_foot", "rh_foot"};
  for (int c = 0; c < 4; ++c) feet[c] = Q::frameIndex(names[c]);
  hqp::tasks::StateEstimator<Q, 4> e(feet, feet, imu);
  ASSERT_TRUE(e.valid());
  QData::VectorQ q = hqp::model::neutralConfiguration<Q>();
  QData::VectorV v = QData::VectorV::Zero();
  const Eigen::Quaterniond quat(Eigen::AngleAxisd(1.0, Eigen::Vector3d(0.2, -0.5, 1.0).normalized()));
  q.head<3>() << 0.3, 0.1, 0.4;
  q[3] = quat.w();
  q[4] = quat.x();
  q[5] = quat.y();
  q[6] = quat.z();
  for (int j = 0; j < Q::nj; ++j) {
    q[7 + j] = 0.1 * std::sin(j + 1.0);
    v[6 + j] = 0.3 * std::cos(j + 2.0);
  }
  v.segment<3>(3) << 0.4, -0.7, 0.2;
  QData d;
  hqp::model::forwardKinematics<Q>(d, q, v);
  const Eigen::Isometry3d X_wi = hqp::model::framePlacement<Q>(d, imu);
  hqp::tasks::SensorData<Q::nj, 4> s;
  s.q = q.tail<Q::nj>();
  s.dq = v.tail<Q::nj>();
  s.imu_orientation = Eigen::Quaterniond(X_wi.linear());
  s.imu_gyro = X_wi.linear().transpose() * hqp::model::frameVelocity<Q>(d, imu).tail<3>();
  ASSERT_TRUE(e.update(s, 0.001));
  const Eigen::Quaterniond qe(e.q()[3], e.q()[4], e.q()[5], e.q()[6]);
  EXPECT_NEAR(std::abs(quat.dot(qe)), 1.0, 1e-12);
  EXPECT_LT((e.v().segment<3>(3) - v.segment<3>(3)).norm(), 1e-12);
  EXPECT_EQ(e.numContacts(), 0);
}

}  // namespace

namespace {

Estimator makeFusedEstimator() {
  Estimator e({kSole[0], kSole[1]}, {kFt[0], kFt[1]}, Robot::Frames::imu);
  hqp::tasks::EstimatorParameters p;
  p.contact_threshold = 8.0;
  p.method = hqp::tasks::EstimatorParameters::Method::KinematicInertial;
  e.configure(p);
  return e;
}

}  // namespace

TEST(ContactEstimator, HysteresisAndConfidenceRamp) {
  hqp::tasks::ContactEstimator c;
  const hqp::tasks::ContactParameters p{8.0, 9.5, 50.0};
  // (normal force, expected contact): in above 9.5 N, out below 8 N, nothing in between flips it.
  const std::pair<double, bool> seq[] = {{9.0, false}, {9.6, true}, {8.5, true}, {8.1, true},
                                         {7.9, false}, {9.0, false}, {9.4, false}, {12.0, true}};
  for (const auto& [fz, expected] : seq) {
    c.update(fz, p);
    EXPECT_EQ(c.inContact(), expected) << fz;
  }
  c.update(29.0, p);
  EXPECT_NEAR(c.confidence(), (29.0 - 8.0) / (50.0 - 8.0), 1e-12);
  c.update(80.0, p);
  EXPECT_EQ(c.confidence(), 1.0);
  c.update(std::numeric_limits<double>::quiet_NaN(), p);
  EXPECT_FALSE(c.inContact());
  EXPECT_EQ(c.confidence(), 0.0);
}

TEST(StateEstimator, InvalidImuQuaternionIsRefused) {
  // A garbage IMU packet must not become "upright": a component of 6.95e261 overflows norm() to
  // inf, and (1, 0, −6.95e261, 0) normalized by it was the identity.
  Truth t;
  t.q = standingState(Eigen::Vector3d::Zero());
  t.v.setZero();
  const Vector6 w[2] = {wrench(0, 0, 210, 0, 0, 0), wrench(0, 0, 210, 0, 0, 0)};
  synthesise(t, w);
  for (auto method : {hqp::tasks::EstimatorParameters::Method::Stance,
                      hqp::tasks::EstimatorParameters::Method::KinematicInertial}) {
    Estimator e = makeFusedEstimator();
    auto p = e.parameters();
    p.method = method;
    e.configure(p);
    ASSERT_TRUE(e.update(t.s, 0.001));
    const VectorQ q0 = e.q();
    Sensors s = t.s;
    s.imu_orientation = Eigen::Quaterniond(1.0, 0.0, -6.95e261, 0.0);
    EXPECT_FALSE(e.update(s, 0.001));
    s.imu_orientation = Eigen::Quaterniond(2.0 * t.s.imu_orientation.coeffs());  // norm 2
    EXPECT_FALSE(e.update(s, 0.001));
    EXPECT_EQ(e.q(), q0);
    s.imu_orientation = Eigen::Quaterniond(1.005 * t.s.imu_orientation.coeffs());  // within 1 %
    EXPECT_TRUE(e.update(s, 0.001));
  }
}

TEST(StateEstimator, KinematicInertialSeparatesAStillFootFromAMovingSupport) {
  // The base and the left leg stand still; the right leg moves, so the right sole moves in the
  // world as if a board carried it, while both feet stay loaded. The IMU reads gravity only.
  // The fused estimate must keep the base at rest and give the right support's true velocity;
  // the stance-foot estimator averages the feet and shows the phantom −v/2 (the test can fail).
  Truth t;
  t.q = standingState(Eigen::Vector3d::Zero());
  const Vector6 w[2] = {wrench(0, 0, 210, 0, 0, 0), wrench(0, 0, 210, 0, 0, 0)};
  Estimator fused = makeFusedEstimator();
  Estimator stance = makeEstimator();
  const double dt = 0.001, omega = 2.0 * M_PI * 1.5;
  const int r0 = Robot::Joints::r_hip_yaw;
  double worst_fused = 0.0, worst_support = 0.0, stance_phantom = 0.0;
  bool moving_seen = false;
  for (int k = 0; k < 1500; ++k) {
    const double s = std::sin(omega * k * dt);
    t.v.setZero();
    Eigen::Matrix<double, 6, 1> dqr;
    dqr << 0.0, 0.0, -1.2 * s, 2.0 * s, -0.8 * s, 0.0;  // the right sole swings along x (~0.35 m/s)
    t.v.segment<6>(6 + r0) = dqr;
    synthesise(t, w);
    ASSERT_TRUE(fused.update(t.s, dt));
    ASSERT_TRUE(stance.update(t.s, dt));
    const Eigen::Vector3d v_right = hqp::model::frameVelocity<Robot>(t.d, kSole[1]).head<3>();
    if (k >= 300) {  // after the gates have settled
      const Eigen::Quaterniond qb(fused.q()[3], fused.q()[4], fused.q()[5], fused.q()[6]);
      worst_fused = std::max(worst_fused, (qb * Eigen::Vector3d(fused.v().head<3>())).norm());
      worst_support = std::max(worst_support, (fused.supportVelocity(1) - v_right).norm());
      const Eigen::Quaterniond qs(stance.q()[3], stance.q()[4], stance.q()[5], stance.q()[6]);
      stance_phantom = std::max(stance_phantom, (qs * Eigen::Vector3d(stance.v().head<3>())).norm());
      if (v_right.norm() > 0.15) {
        EXPECT_TRUE(fused.footMoving(1)) << k;
        EXPECT_FALSE(fused.footMoving(0)) << k;
        EXPECT_EQ(fused.footTrust(1), 0.0) << k;
        moving_seen = true;
      }
    }
    t.q = hqp::model::integrate<Robot>(t.q, t.v, dt);
  }
  EXPECT_TRUE(moving_seen);
  EXPECT_LT(worst_fused, 0.03);     // m/s: the base stays at rest
  EXPECT_LT(worst_support, 0.03);   // m/s: the board's velocity
  EXPECT_GT(stance_phantom, 0.1);   // m/s: half the board's speed, in the stance estimate
}
