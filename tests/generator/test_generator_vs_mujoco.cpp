// Generated headers against MuJoCo's own compilation of the same URDFs (random
// trees from tools/random_urdf.cpp, the robots, the test fixtures):
//  - with fusestatic="true" MuJoCo fuses fixed joints itself, so its bodies are
//    our bodies: tree structure, placements, masses, CoMs and joint data match;
//  - without fusion, MuJoCo's forward kinematics places every link, and summing
//    its links' inertias per body of ours checks our fused inertia tensors.

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <tinyxml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "gen_fixed_arm_model.hpp"
#include "gen_fused_pair_model.hpp"
#include "gen_wild_frames_arm_model.hpp"
#include "gen_wild_xacro_leg_model.hpp"
#include "random_tree0_model.hpp"
#include "random_tree1_model.hpp"
#include "random_tree2_model.hpp"
#include "random_tree3_model.hpp"
#include "random_tree4_model.hpp"
#ifdef HQP_HAVE_WALKER3
#include "walker3_model.hpp"
#endif
#ifdef HQP_HAVE_QUADRUPED
#include "quadruped_model.hpp"
#endif

namespace {

const std::string kData = HQP_TEST_DATA_DIR;

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;

// The URDF with our compiler settings for MuJoCo: fuse fixed joints or keep
// every link a body, no mass from geometry, inertias as written; geometry
// dropped (meshes need not exist); a floating base made explicit with a world
// link and a floating joint.
// `full_tensors` tells whether some <inertia> has products of inertia.
ModelPtr loadIntoMujoco(const std::string& urdf, bool floating, bool fuse, const std::string& tag,
                        bool* full_tensors = nullptr) {
  TiXmlDocument doc;
  if (!doc.LoadFile(urdf.c_str())) return nullptr;
  TiXmlElement* robot = doc.FirstChildElement("robot");
  while (TiXmlElement* mj = robot->FirstChildElement("mujoco")) robot->RemoveChild(mj);
  bool has_world = false;
  for (TiXmlElement* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link")) {
    while (TiXmlElement* v = l->FirstChildElement("visual")) l->RemoveChild(v);
    while (TiXmlElement* c = l->FirstChildElement("collision")) l->RemoveChild(c);
    has_world = has_world || std::string(l->Attribute("name")) == "world";
    const TiXmlElement* in = l->FirstChildElement("inertial");
    const TiXmlElement* I = in ? in->FirstChildElement("inertia") : nullptr;
    if (I && full_tensors) {
      for (const char* a : {"ixy", "ixz", "iyz"}) {
        *full_tensors = *full_tensors || (I->Attribute(a) && std::stod(I->Attribute(a)) != 0.0);
      }
    }
  }
  TiXmlElement mujoco("mujoco");
  TiXmlElement compiler("compiler");
  compiler.SetAttribute("fusestatic", fuse ? "true" : "false");
  compiler.SetAttribute("inertiafromgeom", "false");
  compiler.SetAttribute("balanceinertia", "false");
  compiler.SetAttribute("discardvisual", "true");
  mujoco.InsertEndChild(compiler);
  robot->InsertEndChild(mujoco);
  if (floating && !has_world) {
    std::string root;   // the link that is no joint's child
    for (TiXmlElement* l = robot->FirstChildElement("link"); l && root.empty(); l = l->NextSiblingElement("link")) {
      bool child = false;
      for (TiXmlElement* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
        child = child || std::string(j->FirstChildElement("child")->Attribute("link")) == l->Attribute("name");
      }
      if (!child) root = l->Attribute("name");
    }
    TiXmlElement world("link");
    world.SetAttribute("name", "world");
    robot->InsertEndChild(world);
    TiXmlElement joint("joint");
    joint.SetAttribute("name", "hqp_test_free");
    joint.SetAttribute("type", "floating");
    TiXmlElement parent("parent"), child("child");
    parent.SetAttribute("link", "world");
    child.SetAttribute("link", root);
    joint.InsertEndChild(parent);
    joint.InsertEndChild(child);
    robot->InsertEndChild(joint);
  }
  std::filesystem::create_directories(HQP_TEST_TMP_DIR);
  const std::string path = std::string(HQP_TEST_TMP_DIR) + "/" + tag + (fuse ? "_fused" : "_links") + ".urdf";
  if (!doc.SaveFile(path.c_str())) return nullptr;
  char error[1000] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, error, sizeof error));
  EXPECT_TRUE(m) << error;
  return m;
}

Eigen::Matrix3d quatToMatrix(const mjtNum* quat) {
  mjtNum R[9];
  mju_quat2Mat(R, quat);
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R);
}

Eigen::Matrix3d rowMajor(const double* r) { return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r); }

// MuJoCo with fusestatic: its bodies are our bodies.
template <class Robot>
void compareBodiesWithMujoco(const std::string& urdf, const std::string& tag) {
  const ModelPtr m = loadIntoMujoco(urdf, Robot::floating_base, true, tag);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->nq, Robot::nq);
  EXPECT_EQ(m->nv, Robot::nv);
  EXPECT_EQ(m->nbody, Robot::nb + 1) << "MuJoCo's bodies: world + ours";

  double mj_mass = 0;
  for (int i = 0; i < Robot::nb; ++i) {
    const auto& b = Robot::bodies[i];
    SCOPED_TRACE(std::string(tag) + " body " + b.name);
    const int id = mj_name2id(m.get(), mjOBJ_BODY, b.name);
    ASSERT_GE(id, 1);
    const int parent = b.parent < 0 ? 0 : mj_name2id(m.get(), mjOBJ_BODY, Robot::bodies[b.parent].name);
    EXPECT_EQ(m->body_parentid[id], parent);

    // Placement, mass, CoM. Not the inertia tensor: MuJoCo stores a fused
    // tensor in principal axes found by its Jacobi eigen-solver (mju_eig3), and
    // on these trees they came out up to 1.4e-7 off (relative; moments up to
    // 5e-9) from the tensor that its own unfused links sum to, which agrees with
    // ours to 1e-12 (compareInertiaWithMujocoLinks).
    const Eigen::Vector3d pos(m->body_pos + 3 * id);
    EXPECT_LT((pos - Eigen::Vector3d(b.xyz[0], b.xyz[1], b.xyz[2])).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((quatToMatrix(m->body_quat + 4 * id) - rowMajor(b.rot)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_NEAR(m->body_mass[id], b.mass, 1e-12 * b.mass);
    mj_mass += m->body_mass[id];
    const Eigen::Vector3d ipos(m->body_ipos + 3 * id);
    EXPECT_LT((ipos - Eigen::Vector3d(b.com[0], b.com[1], b.com[2])).cwiseAbs().maxCoeff(), 1e-12);

    // Joint.
    if (b.type == hqp::model::JointType::Free) {
      ASSERT_EQ(m->body_jntnum[id], 1);
      EXPECT_EQ(m->jnt_type[m->body_jntadr[id]], mjJNT_FREE);
      continue;
    }
    const int jid = mj_name2id(m.get(), mjOBJ_JOINT, b.joint);
    ASSERT_GE(jid, 0) << b.joint;
    EXPECT_EQ(m->jnt_bodyid[jid], id);
    EXPECT_EQ(m->body_jntnum[id], 1);
    EXPECT_EQ(m->jnt_type[jid], b.type == hqp::model::JointType::Prismatic ? mjJNT_SLIDE : mjJNT_HINGE);
    const Eigen::Vector3d jpos(m->jnt_pos + 3 * jid), jaxis(m->jnt_axis + 3 * jid);
    EXPECT_LT(jpos.norm(), 1e-12) << "the joint sits at the body origin";
    EXPECT_LT((jaxis - Eigen::Vector3d(b.axis[0], b.axis[1], b.axis[2])).norm(), 1e-12);
    const bool limited = std::isfinite(b.lower);
    EXPECT_EQ(m->jnt_limited[jid] != 0, limited);
    if (limited) {
      EXPECT_EQ(m->jnt_range[2 * jid], b.lower);
      EXPECT_EQ(m->jnt_range[2 * jid + 1], b.upper);
    }
    EXPECT_EQ(m->dof_damping[m->jnt_dofadr[jid]], b.damping);
    EXPECT_EQ(m->dof_frictionloss[m->jnt_dofadr[jid]], b.friction);
  }
  EXPECT_NEAR(mj_mass, Robot::total_mass, 1e-12 * Robot::total_mass);
}

Eigen::Matrix3d tensor(const double* i6) {
  Eigen::Matrix3d I;
  I << i6[0], i6[3], i6[4],
       i6[3], i6[1], i6[5],
       i6[4], i6[5], i6[2];
  return I;
}

// MuJoCo without fusion, at q = 0: every link is a body whose diagonal inertia
// and inertial frame MuJoCo keeps as written (all URDFs here have diagonal
// <inertia>, so nothing goes through its eigen-solver; should a robot get
// products of inertia, the bound falls back to what that solver delivers). Summing the
// links of each of our bodies in world coordinates (MuJoCo's forward
// kinematics) must give our fused mass, CoM and inertia tensor; every frame must
// sit where MuJoCo puts its link.
template <class Robot>
void compareInertiaWithMujocoLinks(const std::string& urdf, const std::string& tag) {
  bool full_tensors = false;
  const ModelPtr m = loadIntoMujoco(urdf, Robot::floating_base, false, tag, &full_tensors);
  ASSERT_TRUE(m);
  const double tol_inertia = full_tensors ? 1e-6 : 1e-12;
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m.get()), mj_deleteData);
  mj_kinematics(m.get(), d.get());
  auto xpos = [&](int id) { return Eigen::Vector3d(d->xpos + 3 * id); };
  auto xmat = [&](int id) { return Eigen::Matrix3d(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->xmat + 9 * id)); };

  // Frames (links) in the world.
  for (const auto& f : Robot::frames) {
    SCOPED_TRACE(std::string(tag) + " frame " + f.name);
    const int id = mj_name2id(m.get(), mjOBJ_BODY, f.name);
    ASSERT_GE(id, 0);   // 0: a URDF link named 'world' is MuJoCo's world body
    Eigen::Vector3d p = Eigen::Vector3d(f.xyz[0], f.xyz[1], f.xyz[2]);
    Eigen::Matrix3d R = rowMajor(f.rot);
    if (f.body >= 0) {
      const int b = mj_name2id(m.get(), mjOBJ_BODY, Robot::bodies[f.body].name);
      p = xpos(b) + xmat(b) * p;
      R = xmat(b) * R;
    }
    EXPECT_LT((p - xpos(id)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((R - xmat(id)).cwiseAbs().maxCoeff(), 1e-12);
  }

  // Sum of MuJoCo's links per body of ours (in the world at q = 0).
  std::vector<double> mass(Robot::nb, 0.0);
  std::vector<Eigen::Vector3d> h(Robot::nb, Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> I_origin(Robot::nb, Eigen::Matrix3d::Zero());   // about the world origin
  for (int id = 1; id < m->nbody; ++id) {
    const int f = Robot::frameIndex(mj_id2name(m.get(), mjOBJ_BODY, id));
    ASSERT_GE(f, 0) << mj_id2name(m.get(), mjOBJ_BODY, id);
    const int b = Robot::frames[f].body;
    if (b < 0) continue;   // fixed to the world
    const double mk = m->body_mass[id];
    const Eigen::Vector3d c(d->xipos + 3 * id);
    const Eigen::Matrix3d Rk = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->ximat + 9 * id);
    const Eigen::Matrix3d Ic = Rk * Eigen::Vector3d(m->body_inertia + 3 * id).asDiagonal() * Rk.transpose();
    mass[b] += mk;
    h[b] += mk * c;
    I_origin[b] += Ic + mk * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  }
  for (int i = 0; i < Robot::nb; ++i) {
    const auto& b = Robot::bodies[i];
    SCOPED_TRACE(std::string(tag) + " body " + b.name);
    ASSERT_GT(mass[i], 0.0);
    const Eigen::Vector3d c = h[i] / mass[i];
    const Eigen::Matrix3d I_mj =
        I_origin[i] - mass[i] * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    const int id = mj_name2id(m.get(), mjOBJ_BODY, b.name);
    const Eigen::Matrix3d R = xmat(id);
    const Eigen::Vector3d c_ours = xpos(id) + R * Eigen::Vector3d(b.com[0], b.com[1], b.com[2]);
    const Eigen::Matrix3d I_ours = R * tensor(b.inertia) * R.transpose();
    EXPECT_NEAR(b.mass, mass[i], 1e-12 * mass[i]);
    EXPECT_LT((c_ours - c).cwiseAbs().maxCoeff(), 1e-12);
    // Moving inertias to the CoM cancels m |c|^2 terms of the size of the
    // whole body's offset from the world origin: relative to those, not to I.
    const double scale = std::max(I_ours.cwiseAbs().maxCoeff(), mass[i] * c.squaredNorm());
    EXPECT_LT((I_ours - I_mj).cwiseAbs().maxCoeff(), tol_inertia * scale);
  }
}

std::string tree(int k) { return std::string(HQP_RANDOM_TREE_DIR) + "/tree" + std::to_string(k) + ".urdf"; }

template <class Robot>
void compareWithMujoco(const std::string& urdf, const std::string& tag) {
  compareBodiesWithMujoco<Robot>(urdf, tag);
  compareInertiaWithMujocoLinks<Robot>(urdf, tag);
}

TEST(GeneratedVsMujoco, RandomTree0) { compareWithMujoco<random_tree0::Robot>(tree(0), "tree0"); }
TEST(GeneratedVsMujoco, RandomTree1) { compareWithMujoco<random_tree1::Robot>(tree(1), "tree1"); }
TEST(GeneratedVsMujoco, RandomTree2) { compareWithMujoco<random_tree2::Robot>(tree(2), "tree2"); }
TEST(GeneratedVsMujoco, RandomTree3) { compareWithMujoco<random_tree3::Robot>(tree(3), "tree3"); }
TEST(GeneratedVsMujoco, RandomTree4FixedBase) {
  static_assert(!random_tree4::Robot::floating_base);
  compareWithMujoco<random_tree4::Robot>(tree(4), "tree4");
}
TEST(GeneratedVsMujoco, FusedPair) { compareWithMujoco<fused_pair::Robot>(kData + "/fused_pair.urdf", "fused_pair"); }
TEST(GeneratedVsMujoco, FixedArm) { compareWithMujoco<fixed_arm::Robot>(kData + "/fixed_arm.urdf", "fixed_arm"); }
// Exported files: xacro namespace, comments, mesh-only links, <transmission>, <gazebo>,
// <ros2_control>, 1e-9 kg zero-inertia frame links and a point-mass payload on fixed joints.
TEST(GeneratedVsMujoco, WildXacroLeg) {
  compareWithMujoco<wild_xacro_leg::Robot>(kData + "/wild_xacro_leg.urdf", "wild_xacro_leg");
}
TEST(GeneratedVsMujoco, WildFramesArm) {
  compareWithMujoco<wild_frames_arm::Robot>(kData + "/wild_frames_arm.urdf", "wild_frames_arm");
}
#ifdef HQP_HAVE_WALKER3
TEST(GeneratedVsMujoco, Walker3) { compareWithMujoco<walker3::Robot>(HQP_WALKER3_URDF, "walker3"); }
#endif
#ifdef HQP_HAVE_QUADRUPED
TEST(GeneratedVsMujoco, Quadruped) { compareWithMujoco<quadruped::Robot>(HQP_QUADRUPED_URDF, "quadruped"); }
#endif

// The random trees exercise what they are meant to: every joint type, fixed
// joints (fusion), and more than one child per body somewhere.
template <class Robot>
void countFeatures(int& revolute, int& continuous, int& prismatic, int& fused, int& branching) {
  int children[Robot::nb] = {};
  for (const auto& b : Robot::bodies) {
    revolute += b.type == hqp::model::JointType::Revolute;
    continuous += b.type == hqp::model::JointType::Continuous;
    prismatic += b.type == hqp::model::JointType::Prismatic;
    if (b.parent >= 0) ++children[b.parent];
  }
  for (int c : children) branching += c > 1;
  fused += Robot::nframes - Robot::nb;
}

TEST(RandomTrees, CoverEveryJointTypeFusionAndBranching) {
  int rev = 0, cont = 0, pri = 0, fused = 0, branching = 0;
  countFeatures<random_tree0::Robot>(rev, cont, pri, fused, branching);
  countFeatures<random_tree1::Robot>(rev, cont, pri, fused, branching);
  countFeatures<random_tree2::Robot>(rev, cont, pri, fused, branching);
  countFeatures<random_tree3::Robot>(rev, cont, pri, fused, branching);
  countFeatures<random_tree4::Robot>(rev, cont, pri, fused, branching);
  EXPECT_GT(rev, 0);
  EXPECT_GT(cont, 0);
  EXPECT_GT(pri, 0);
  EXPECT_GT(fused, 0);
  EXPECT_GT(branching, 0);
}

}  // namespace
