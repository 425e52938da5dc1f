// Self-check of the MuJoCo reference (tests/support/mujoco_reference.hpp) before it is trusted
// to judge the dynamics layer: closed forms on a floating box and a pendulum, and finite
// differences / energy balance on a small floating tree with off-diagonal inertias.
// Nothing from include/model is used here.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <string>

#include "support/mujoco_reference.hpp"

namespace {

using hqp::test::JointSlot;
using hqp::test::MujocoReference;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr double kG = 9.81;

// Error relative to the largest entry of the expected value (entry-wise relative errors are
// meaningless for near-zero entries).
double relErr(const Eigen::MatrixXd& got, const Eigen::MatrixXd& want) {
  const double scale = std::max(want.cwiseAbs().maxCoeff(), 1e-12);
  return (got - want).cwiseAbs().maxCoeff() / scale;
}

Eigen::VectorXd randomFloatingQ(std::mt19937& rng, int nq) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd q(nq);
  for (int i = 0; i < nq; ++i) q[i] = u(rng);
  q.segment<4>(3).normalize();
  return q;
}

Eigen::VectorXd randomV(std::mt19937& rng, int nv) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::VectorXd v(nv);
  for (int i = 0; i < nv; ++i) v[i] = n(rng);
  return v;
}

// ---- floating box: everything in closed form --------------------------------------------
const char* kBoxUrdf = R"(<?xml version="1.0"?>
<robot name="box">
  <link name="box">
    <inertial><origin xyz="0 0 0"/><mass value="2.5"/>
      <inertia ixx="0.1" iyy="0.2" izz="0.25" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.3 0.4 0.5"/></geometry></collision>
  </link>
</robot>)";

TEST(MujocoReferenceSelfCheck, FloatingBoxClosedForm) {
  MujocoReference ref(hqp::test::loadUrdfStringIntoMujoco(kBoxUrdf, true), true, "box", {}, 7, 6);
  const double m = 2.5;
  const Eigen::Vector3d I(0.1, 0.2, 0.25);
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd q = randomFloatingQ(rng, 7), v = randomV(rng, 6);
    ref.compute(q, v);
    const Eigen::Matrix3d R = MujocoReference::baseRotation(q);
    const Eigen::Vector3d vb = v.head<3>(), w = v.tail<3>();
    const Eigen::Vector3d Iw = I.asDiagonal() * w;

    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(6, 6);
    M.diagonal() << m, m, m, I;
    EXPECT_LT(relErr(ref.M, M), 1e-14);

    // Newton-Euler in the body frame: m (vdot + w x v) = f, I wdot + w x I w = n.
    Eigen::VectorXd G(6), h(6);
    G << m * R.transpose() * Eigen::Vector3d(0, 0, kG), Eigen::Vector3d::Zero();
    h << m * w.cross(vb) + G.head<3>(), w.cross(Iw);
    EXPECT_LT(relErr(ref.g, G), 1e-14);
    EXPECT_LT(relErr(ref.h, h), 1e-13);

    // Frame of the box: pdot = R v_b, world w = R w_b.
    const Eigen::Isometry3d X = ref.placement("box");
    EXPECT_LT((X.translation() - q.head<3>()).norm(), 1e-14);
    EXPECT_LT((X.linear() - R).norm(), 1e-14);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, 6);
    J.topLeftCorner<3, 3>() = R;
    J.bottomRightCorner<3, 3>() = R;
    EXPECT_LT(relErr(ref.jacobian("box"), J), 1e-14);
    EXPECT_LT(relErr(ref.velocity("box"), J * v), 1e-14);
    // d/dt (R v_b) = R (w x v_b); d/dt (R w_b) = R (w x w) = 0 at vdot = 0.
    Vector6d dJv;
    dJv << R * w.cross(vb), Eigen::Vector3d::Zero();
    EXPECT_LT(relErr(ref.biasAcceleration("box"), dJv), 1e-13);

    EXPECT_NEAR(ref.mass, m, 1e-14);
    EXPECT_LT((ref.com - q.head<3>()).norm(), 1e-14);
    EXPECT_LT(relErr(ref.Jcom, J.topRows<3>()), 1e-14);
    Vector6d hG, dhG;
    hG << m * R * vb, R * Iw;
    dhG << m * R * w.cross(vb), R * w.cross(Iw);
    EXPECT_LT(relErr(ref.hG, hG), 1e-13);
    EXPECT_LT(relErr(ref.hG_bodies, hG), 1e-13);
    EXPECT_LT(relErr(ref.Ag * v, hG), 1e-13);
    EXPECT_LT(relErr(ref.dhG, dhG), 1e-13);
  }
}

// ---- fixed-base pendulum: the welded root's mass must not count; massless links stay so ----
const char* kPendulumUrdf = R"(<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base">
    <inertial><origin xyz="0 0 0.1"/><mass value="5"/>
      <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0.1 0.2 0.3" rpy="0 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="10"/>
  </joint>
  <link name="arm">
    <inertial><origin xyz="0 0 -0.7"/><mass value="1.5"/>
      <inertia ixx="0.02" iyy="0.03" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="tip_joint" type="fixed">
    <parent link="arm"/><child link="tip"/><origin xyz="0 0 -0.7"/>
  </joint>
  <link name="tip">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
</robot>)";

TEST(MujocoReferenceSelfCheck, FixedBasePendulumClosedForm) {
  MujocoReference ref(hqp::test::loadUrdfStringIntoMujoco(kPendulumUrdf, false), false, "",
                      {JointSlot{"hinge", 0, 0}}, 1, 1);
  const double m = 1.5, l = 0.7, Iyy = 0.03;
  const Eigen::Vector3d pivot(0.1, 0.2, 0.3);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q(1), v(1);
    q << u(rng);
    v << u(rng);
    ref.compute(q, v);
    const double th = q[0], thd = v[0], s = std::sin(th), c = std::cos(th);
    EXPECT_NEAR(ref.M(0, 0), Iyy + m * l * l, 1e-14);
    // CoM at pivot + (-l sin, 0, -l cos): V = -m g l cos(th), G = m g l sin(th), no Coriolis.
    EXPECT_NEAR(ref.g[0], m * kG * l * s, 1e-13);
    EXPECT_NEAR(ref.h[0], m * kG * l * s, 1e-13);
    const Eigen::Vector3d r(-l * s, 0, -l * c);
    EXPECT_LT((ref.placement("tip").translation() - (pivot + r)).norm(), 1e-14);
    Eigen::MatrixXd J(6, 1);
    J << -l * c, 0, l * s, 0, 1, 0;
    EXPECT_LT(relErr(ref.jacobian("tip"), J), 1e-14);
    Vector6d dJv;
    dJv << thd * thd * l * s, 0, thd * thd * l * c, 0, 0, 0;
    EXPECT_LT((ref.biasAcceleration("tip") - dJv).norm(), 1e-13 * (1 + dJv.norm()));
    EXPECT_NEAR(ref.mass, m, 1e-14);  // not 5 + 1.5, and the collision box adds nothing
    EXPECT_LT((ref.com - (pivot + r)).norm(), 1e-14);
    EXPECT_LT(relErr(ref.Jcom, J.topRows<3>()), 1e-14);
    // About the CoM the arm spins: L_G = Iyy thd e_y; P = m thd dr/dth.
    Vector6d hG;
    hG << m * thd * J.topRows<3>(), 0, Iyy * thd, 0;
    EXPECT_LT((ref.hG - hG).norm(), 1e-13 * (1 + hG.norm()));
    Vector6d dhG;
    dhG << m * dJv.head<3>(), 0, 0, 0;
    EXPECT_LT((ref.dhG - dhG).norm(), 1e-13 * (1 + dhG.norm()));
  }
}

// ---- small floating tree: finite differences and energy -------------------------------------
const char* kTreeUrdf = R"(<?xml version="1.0"?>
<robot name="tree">
  <link name="torso">
    <inertial><origin xyz="0.05 -0.02 0.1" rpy="0.3 -0.2 0.5"/><mass value="4"/>
      <inertia ixx="0.3" iyy="0.25" izz="0.2" ixy="0.01" ixz="-0.02" iyz="0.015"/></inertial>
  </link>
  <joint name="b_slide" type="prismatic">
    <parent link="torso"/><child link="slider"/><origin xyz="0 0.2 0" rpy="0.1 0.2 0.3"/>
    <axis xyz="0.6 0 0.8"/><limit lower="-0.2" upper="0.2" effort="10" velocity="1"/>
  </joint>
  <link name="slider">
    <inertial><origin xyz="0.01 0.02 0.03"/><mass value="0.7"/>
      <inertia ixx="0.01" iyy="0.012" izz="0.008" ixy="0.001" ixz="0" iyz="-0.002"/></inertial>
  </link>
  <joint name="a_hip" type="revolute">
    <parent link="torso"/><child link="thigh"/><origin xyz="0 -0.1 -0.1" rpy="0.4 0 -0.3"/>
    <axis xyz="0 0.6 0.8"/><limit lower="-2" upper="2" effort="10" velocity="1"/>
  </joint>
  <link name="thigh">
    <inertial><origin xyz="0 0 -0.2" rpy="0.1 0.2 0"/><mass value="1.2"/>
      <inertia ixx="0.05" iyy="0.045" izz="0.02" ixy="0.002" ixz="0.001" iyz="0.003"/></inertial>
  </link>
  <joint name="knee" type="continuous">
    <parent link="thigh"/><child link="shank"/><origin xyz="0 0 -0.4"/><axis xyz="1 0 0"/>
  </joint>
  <link name="shank">
    <inertial><origin xyz="0 0.01 -0.2"/><mass value="0.9"/>
      <inertia ixx="0.03" iyy="0.03" izz="0.005" ixy="0" ixz="0.001" iyz="0"/></inertial>
  </link>
  <joint name="sole_joint" type="fixed">
    <parent link="shank"/><child link="sole"/><origin xyz="0.03 0 -0.42" rpy="0 0.2 0"/>
  </joint>
  <link name="sole">
    <inertial><origin xyz="0.02 0 0"/><mass value="0.3"/>
      <inertia ixx="0.001" iyy="0.002" izz="0.002" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>)";

// Our layout: depth-first, children by joint name: torso, a_hip (thigh), knee (shank), b_slide.
MujocoReference makeTree() {
  return MujocoReference(hqp::test::loadUrdfStringIntoMujoco(kTreeUrdf, true), true, "torso",
                         {JointSlot{"a_hip", 7, 6}, JointSlot{"knee", 8, 7}, JointSlot{"b_slide", 9, 8}},
                         10, 9);
}

struct Snapshot {
  Vector6d vel_sole, vel_torso, hG;
  double energy;
};

Snapshot snapshot(MujocoReference& ref, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  ref.compute(q, v);
  Snapshot s;
  s.vel_sole = ref.velocity("sole");
  s.vel_torso = ref.velocity("torso");
  s.hG = ref.hG;
  s.energy = 0.5 * v.dot(ref.M * v) + ref.mass * kG * ref.com.z();
  return s;
}

TEST(MujocoReferenceSelfCheck, FloatingTreeFiniteDifferences) {
  MujocoReference ref = makeTree();
  std::mt19937 rng(3);
  // Central differences along a path with our v held constant (vdot = 0). The path is MuJoCo's
  // first-order integration of v_mj(0); its second-order deviation from the true vdot = 0 path
  // is the same for +eps and -eps and cancels, so the error is O(eps^2) ~ 1e-10 relative.
  const double eps = 1e-5, tol = 1e-7;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q = randomFloatingQ(rng, 10), v = randomV(rng, 9);
    q[9] *= 0.2;
    ref.compute(q, v);
    const Eigen::MatrixXd M = ref.M, Jcom = ref.Jcom, Jsole = ref.jacobian("sole");
    const Eigen::VectorXd h = ref.h, g = ref.g;
    const Vector6d dJv_sole = ref.biasAcceleration("sole"), dJv_torso = ref.biasAcceleration("torso");
    const Vector6d hG = ref.hG, hG_bodies = ref.hG_bodies, dhG = ref.dhG;
    const Vector6d vel_sole = ref.velocity("sole");
    const Eigen::VectorXd qvel_mj = ref.S * v;

    EXPECT_NEAR(ref.mass, 7.1, 1e-14);
    EXPECT_LT(relErr(M, M.transpose()), 1e-15);
    EXPECT_LT(relErr(Jsole * v, vel_sole), 1e-14);
    EXPECT_LT(relErr(Jcom * v, ref.vcom), 1e-14);
    EXPECT_LT(relErr(hG_bodies, hG), 1e-12);  // subtree quantities vs per-body sums
    EXPECT_LT(relErr(ref.Ag * v, hG), 1e-12);

    Eigen::VectorXd qpos_p = ref.toQpos(q), qpos_m = qpos_p;
    mj_integratePos(ref.model(), qpos_p.data(), qvel_mj.data(), eps);
    mj_integratePos(ref.model(), qpos_m.data(), qvel_mj.data(), -eps);
    const Snapshot sp = snapshot(ref, ref.fromQpos(qpos_p), v);
    const Snapshot sm = snapshot(ref, ref.fromQpos(qpos_m), v);
    EXPECT_LT(relErr(dJv_sole, (sp.vel_sole - sm.vel_sole) / (2 * eps)), tol);
    EXPECT_LT(relErr(dJv_torso, (sp.vel_torso - sm.vel_torso) / (2 * eps)), tol);
    EXPECT_LT(relErr(dhG, (sp.hG - sm.hG) / (2 * eps)), tol);
    // Power balance at vdot = 0: the generalized force is h, so v.h = dE/dt.
    const double dE = (sp.energy - sm.energy) / (2 * eps);
    EXPECT_NEAR(v.dot(h), dE, tol * (std::abs(dE) + h.norm() * v.norm()));
    // Gravity alone: v.G = dV/dt.
    const double dV = 7.1 * kG * Jcom.row(2).dot(v);  // total mass 4 + 0.7 + 1.2 + 0.9 + 0.3
    EXPECT_NEAR(v.dot(g), dV, 1e-12 * (1 + std::abs(dV)));
  }
}

// The loader's inertia repair: principal axes from Eigen reproduce the URDF tensor to
// round-off, while MuJoCo's own solver is off by ~1e-7 relative on this tree.
Eigen::Matrix3d bodyTensor(const mjModel* m, int b) {
  const Eigen::Quaterniond q(m->body_iquat[4 * b], m->body_iquat[4 * b + 1], m->body_iquat[4 * b + 2],
                             m->body_iquat[4 * b + 3]);
  const Eigen::Vector3d I(m->body_inertia + 3 * b);
  return q.toRotationMatrix() * I.asDiagonal() * q.toRotationMatrix().transpose();
}

TEST(MujocoReferenceSelfCheck, ExactInertiaMatchesUrdfTensor) {
  auto exact = hqp::test::loadUrdfStringIntoMujoco(kTreeUrdf, true);
  auto raw = hqp::test::loadUrdfStringIntoMujoco(kTreeUrdf, true, {}, false);
  Eigen::Matrix3d slider, thigh0;  // URDF numbers; thigh's inertial frame has rpy (0.1, 0.2, 0)
  slider << 0.01, 0.001, 0, 0.001, 0.012, -0.002, 0, -0.002, 0.008;
  thigh0 << 0.05, 0.002, 0.001, 0.002, 0.045, 0.003, 0.001, 0.003, 0.02;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX())).toRotationMatrix();
  const Eigen::Matrix3d thigh = R * thigh0 * R.transpose();
  const int bs = mj_name2id(exact.get(), mjOBJ_BODY, "slider");
  const int bt = mj_name2id(exact.get(), mjOBJ_BODY, "thigh");
  EXPECT_LT(relErr(bodyTensor(exact.get(), bs), slider), 1e-15);
  EXPECT_LT(relErr(bodyTensor(exact.get(), bt), thigh), 1e-15);
  EXPECT_LT(relErr(bodyTensor(raw.get(), bs), slider), 1e-6);
  EXPECT_GT(relErr(bodyTensor(raw.get(), bs), slider), 1e-12);  // why the repair exists
  for (int b = 0; b < exact->nbody; ++b) EXPECT_EQ(exact->body_mass[b], raw->body_mass[b]);
}

// The rewriting keeps a URDF's own world link and floating joint, and rejects broken files
// with MuJoCo's message.
TEST(MujocoReferenceSelfCheck, LoaderHandlesWorldLinkAndErrors) {
  const std::string with_world = R"(<robot name="w"><link name="world"/>
    <joint name="fb" type="floating"><parent link="world"/><child link="box"/></joint>
    <link name="box"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>)";
  auto m = hqp::test::loadUrdfStringIntoMujoco(with_world, true);
  EXPECT_EQ(m->nq, 7);
  EXPECT_EQ(m->nv, 6);
  EXPECT_EQ(m->jnt_type[0], mjJNT_FREE);
  // Inertia violating the triangle inequality: MuJoCo must refuse (balanceinertia is off).
  const std::string bad = R"(<robot name="b"><link name="box"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.5" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>)";
  EXPECT_THROW(hqp::test::loadUrdfStringIntoMujoco(bad, true), std::runtime_error);
}

}  // namespace
