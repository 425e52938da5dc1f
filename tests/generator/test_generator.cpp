// The URDF -> header generator (tools/urdf2model.cpp):
//  - every malformed URDF in tests/data/bad_*.urdf is rejected with exit code 1
//    and one line naming the file and the element;
//  - generated headers agree with an independent reading of the URDF by urdfdom
//    (joint order, placements, frames, masses, limits);
//  - fixed-joint fusion matches a closed form worked out by hand;
//  - the header does not depend on the order of elements in the file.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <tinyxml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "gen_fixed_arm_model.hpp"
#include "gen_fused_pair_frames_model.hpp"
#include "gen_fused_heavy_light_model.hpp"
#include "gen_fused_pair_model.hpp"
#include "gen_wild_frames_arm_model.hpp"
#include "gen_wild_xacro_leg_model.hpp"
#include "urdf_reference.hpp"
#ifdef HQP_HAVE_WALKER3
#include "walker3_model.hpp"
#endif
#ifdef HQP_HAVE_QUADRUPED
#include "quadruped_model.hpp"
#endif

namespace {

using hqp::test::Pose;
using hqp::test::UrdfReference;

const std::string kData = HQP_TEST_DATA_DIR;
const std::string kTmp = HQP_TEST_TMP_DIR;

struct RunResult {
  int exit_code = -1;
  std::string output;   // stdout and stderr
};

RunResult runGenerator(const std::string& args) {
  const std::string cmd = "'" + std::string(HQP_URDF2MODEL) + "' " + args + " 2>&1";
  RunResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) r.output += buf;
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string tmpPath(const std::string& name) {
  std::filesystem::create_directories(kTmp);
  return kTmp + "/" + name;
}

// ---------------------------------------------------------------------------
// Rejections

struct BadCase {
  const char* file;
  const char* message;   // what must follow "<file>: "
};

class Rejection : public ::testing::TestWithParam<BadCase> {};

TEST_P(Rejection, ExitsWithOneMessageNamingTheElement) {
  const BadCase c = GetParam();
  const std::string urdf = kData + "/" + c.file;
  const std::string out = tmpPath(std::string(c.file) + ".hpp");
  std::remove(out.c_str());
  const RunResult r = runGenerator("'" + urdf + "' -o '" + out + "' --floating-base");
  EXPECT_EQ(r.exit_code, 1);
  const std::string expected_start = urdf + ": " + c.message;
  EXPECT_EQ(r.output.rfind(expected_start, 0), 0u) << "got: " << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line, got: " << r.output;
  EXPECT_FALSE(std::filesystem::exists(out)) << "no header may be written";
}

INSTANTIATE_TEST_SUITE_P(
    BadUrdf, Rejection,
    ::testing::Values(
        BadCase{"bad_two_parents.urdf", "link 'foot': has two parents"},
        BadCase{"bad_loop.urdf", "joint 'j_ab': closes a kinematic loop"},
        BadCase{"bad_mimic.urdf", "joint 'ankle': mimic joints are not supported"},
        BadCase{"bad_planar.urdf", "joint 'slide': planar joints are not supported"},
        BadCase{"bad_floating_inner.urdf", "joint 'payload_free': floating joints are only supported"},
        BadCase{"bad_world_not_floating.urdf", "joint 'world_free': floating joints are only supported"},
        BadCase{"bad_world_fixed_but_floating.urdf", "link 'world': the robot floats (--floating-base)"},
        BadCase{"bad_massless_moving.urdf", "link 'shank': joint 'knee' moves it, but it has no mass"},
        BadCase{"bad_negative_mass.urdf", "link 'thigh': negative or invalid mass"},
        BadCase{"bad_mass_not_a_number.urdf", "link 'thigh': <mass value='heavy'> is not a number"},
        BadCase{"bad_not_positive_definite.urdf", "link 'thigh': the inertia is not positive semi-definite"},
        // Zero inertias are fine on links, not on a body that moves.
        BadCase{"bad_moving_zero_inertia.urdf",
                "link 'shank': joint 'knee' moves it, but its inertia (with the links fixed to it) is not "
                "positive definite"},
        BadCase{"bad_triangle_inequality.urdf", "link 'shank': the inertia violates the triangle inequality"},
        BadCase{"bad_missing_link.urdf", "joint 'knee': child link 'shank_typo' does not exist"},
        BadCase{"bad_zero_axis.urdf", "joint 'knee': zero axis"},
        BadCase{"bad_link_name_collision.urdf", "link 'foot_l': name collides with link 'foot.l'"},
        BadCase{"bad_joint_name_collision.urdf", "joint 'hip_l': name collides with joint 'hip-l'"},
        BadCase{"bad_two_roots.urdf", "link 'spare': has no parent joint"},
        BadCase{"bad_duplicate_link.urdf", "link 'thigh': defined twice"},
        BadCase{"bad_revolute_without_limit.urdf", "joint 'knee': revolute joint without <limit>"},
        BadCase{"bad_xml.urdf", "line 5: XML error"},
        // Input contract of numbers: finite, physically valid, checked before anything uses them.
        BadCase{"bad_axis_overflow.urdf", "joint 'knee': <axis xyz='1e200 1e200 1e200'> is too large"},
        BadCase{"bad_negative_effort.urdf", "joint 'knee': <limit effort='-20'> must be a finite number > 0"},
        BadCase{"bad_zero_effort.urdf", "joint 'knee': <limit effort='0'> must be a finite number > 0"},
        BadCase{"bad_negative_velocity.urdf", "joint 'knee': <limit velocity='-5'> must be a finite number > 0"},
        BadCase{"bad_continuous_negative_effort.urdf",
                "joint 'knee': <limit effort='-20'> must be a finite number > 0"},
        // Text from the file is escaped: the message stays one line.
        BadCase{"bad_multiline_attribute.urdf", "link 'base': <inertia iyy='0.01\\n  kg'> is not a number"},
        BadCase{"bad_urdfdom_multiline.urdf", "urdfdom: Unable to parse component [0.5\\n]"},
        BadCase{"bad_inertial_overflow.urdf", "link 'thigh': <origin xyz='0.5e200 0 0'> is outside ±1000 m"},
        BadCase{"bad_joint_origin_too_far.urdf", "joint 'hip': <origin xyz='0 0 -1500'> is outside ±1000 m"},
        BadCase{"bad_huge_mass.urdf", "link 'l0': mass 2.93799e+15 kg is above 1e+06 kg"},
        BadCase{"bad_huge_inertia.urdf", "link 'thigh': <inertia ixx='2e6'> is outside ±1e+06 kg m²"},
        BadCase{"bad_lower_above_upper.urdf", "joint 'knee': <limit lower='1'> is above <limit upper='-1'>"},
        // Caught by urdfdom only: its own message, after the file name.
        BadCase{"bad_urdfdom_safety.urdf", "urdfdom: joint safety: no k_velocity"}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
      std::string n = info.param.file;
      n = n.substr(4, n.size() - 9);   // strip "bad_" and ".urdf"
      return n;
    });

// With a fixed base the links fused into the world drop their inertia, but a negative mass
// is still an error in the file (docs/adding-a-robot.md: mass >= 0 on every link).
TEST(GeneratorCli, RejectsNegativeMassOnALinkFusedIntoTheWorld) {
  const std::string urdf = kData + "/bad_world_negative_mass.urdf";
  const std::string out = tmpPath("bad_world_negative_mass.hpp");
  std::remove(out.c_str());
  const RunResult r = runGenerator("'" + urdf + "' -o '" + out + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.output, urdf + ": link 'plate': negative or invalid mass -2\n");
  EXPECT_FALSE(std::filesystem::exists(out)) << "no header may be written";
}

TEST(GeneratorCli, RejectsUnknownFrame) {
  const std::string urdf = kData + "/fused_pair.urdf";
  const RunResult r = runGenerator("'" + urdf + "' -o '" + tmpPath("f.hpp") + "' --frames tip,nope");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.output, urdf + ": --frames: link 'nope' does not exist\n");
}

TEST(GeneratorCli, RejectsBadNamespace) {
  const std::string urdf = kData + "/fused_pair.urdf";
  const RunResult r = runGenerator("'" + urdf + "' -o '" + tmpPath("f.hpp") + "' --namespace 9lives");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.output, urdf + ": --namespace: '9lives' is not a C++ namespace name\n");
}

TEST(GeneratorCli, RejectsMissingFile) {
  const std::string urdf = kData + "/no_such_robot.urdf";
  const RunResult r = runGenerator("'" + urdf + "' -o '" + tmpPath("f.hpp") + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.output, urdf + ": cannot open the file\n");
}

// ---------------------------------------------------------------------------
// Agreement with urdfdom, for every generated robot

Pose framePose(const double* xyz, const double* rot) {
  Pose T;
  T.p = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  T.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rot);
  return T;
}

void expectPoseNear(const Pose& a, const Pose& b, const std::string& what) {
  EXPECT_LT((a.p - b.p).cwiseAbs().maxCoeff(), 1e-12) << what;
  EXPECT_LT((a.R - b.R).cwiseAbs().maxCoeff(), 1e-12) << what;
}

template <class Robot>
void checkAgainstUrdfdom(const std::string& urdf_path, bool all_frames) {
  const UrdfReference ref(urdf_path);
  ASSERT_TRUE(ref.ok());
  const urdf::ModelInterface& um = ref.model();
  const int fb = Robot::floating_base ? 1 : 0;
  const std::string start = ref.startLink();

  // Sizes and joint order.
  const std::vector<std::string> order = ref.jointOrder();
  ASSERT_EQ(static_cast<int>(order.size()), Robot::nj);
  EXPECT_EQ(Robot::nb, Robot::nj + fb);
  EXPECT_EQ(Robot::nq, Robot::nj + 7 * fb);
  EXPECT_EQ(Robot::nv, Robot::nj + 6 * fb);
  for (int i = 0; i < Robot::nj; ++i) {
    EXPECT_EQ(std::string(Robot::bodies[i + fb].joint), order[i]) << "joint " << i;
    EXPECT_EQ(Robot::jointIndex(order[i]), i);
  }
  EXPECT_EQ(Robot::jointIndex("no such joint"), -1);

  // Bodies: link, parent, placement, axis, limits, mass.
  for (int i = 0; i < Robot::nb; ++i) {
    const auto& b = Robot::bodies[i];
    SCOPED_TRACE(std::string("body ") + b.name);
    EXPECT_EQ(Robot::bodyIndex(b.name), i);
    double mass = 0;
    std::vector<urdf::LinkSharedPtr> links;
    um.getLinks(links);
    for (const auto& l : links) {
      if (l->inertial && ref.bodyOf(l->name).first == b.name) mass += l->inertial->mass;
    }
    EXPECT_NEAR(b.mass, mass, 1e-12 * mass);
    if (i == 0 && fb) {
      EXPECT_EQ(b.type, hqp::model::JointType::Free);
      EXPECT_EQ(std::string(b.name), start);
      EXPECT_EQ(b.parent, -1);
      EXPECT_EQ(b.idx_q, 0);
      EXPECT_EQ(b.idx_v, 0);
      continue;
    }
    const urdf::JointConstSharedPtr j = um.getJoint(b.joint);
    ASSERT_TRUE(j);
    EXPECT_EQ(std::string(b.name), j->child_link_name);
    EXPECT_EQ(b.idx_q, 7 * fb + i - fb);
    EXPECT_EQ(b.idx_v, 6 * fb + i - fb);
    const auto [parent_link, T_parent] = ref.bodyOf(j->parent_link_name);
    if (b.parent < 0) {
      EXPECT_FALSE(Robot::floating_base);
      EXPECT_EQ(parent_link, start);
    } else {
      EXPECT_LT(b.parent, i);   // depth-first: parents first
      EXPECT_EQ(parent_link, Robot::bodies[b.parent].name);
    }
    expectPoseNear(framePose(b.xyz, b.rot), T_parent * hqp::test::toPose(j->parent_to_joint_origin_transform),
                   "placement");
    const Eigen::Vector3d axis = Eigen::Vector3d(j->axis.x, j->axis.y, j->axis.z).normalized();
    EXPECT_LT((Eigen::Vector3d(b.axis[0], b.axis[1], b.axis[2]) - axis).norm(), 1e-15);
    using JT = hqp::model::JointType;
    switch (j->type) {
      case urdf::Joint::REVOLUTE: EXPECT_EQ(b.type, JT::Revolute); break;
      case urdf::Joint::CONTINUOUS: EXPECT_EQ(b.type, JT::Continuous); break;
      case urdf::Joint::PRISMATIC: EXPECT_EQ(b.type, JT::Prismatic); break;
      default: ADD_FAILURE() << "not a 1-DoF joint";
    }
    if (j->type == urdf::Joint::CONTINUOUS) {
      EXPECT_TRUE(std::isinf(b.lower) && b.lower < 0);
      EXPECT_TRUE(std::isinf(b.upper) && b.upper > 0);
    } else {
      EXPECT_EQ(b.lower, j->limits->lower);
      EXPECT_EQ(b.upper, j->limits->upper);
    }
    if (j->limits) {
      EXPECT_EQ(b.effort, j->limits->effort);
      EXPECT_EQ(b.velocity, j->limits->velocity);
    } else {
      EXPECT_TRUE(std::isinf(b.effort));
      EXPECT_TRUE(std::isinf(b.velocity));
    }
    EXPECT_EQ(b.damping, j->dynamics ? j->dynamics->damping : 0.0);
    EXPECT_EQ(b.friction, j->dynamics ? j->dynamics->friction : 0.0);
  }

  // Frames: each where urdfdom puts it; frame i < nb is body i.
  for (int i = 0; i < Robot::nframes; ++i) {
    const auto& f = Robot::frames[i];
    SCOPED_TRACE(std::string("frame ") + f.name);
    EXPECT_EQ(Robot::frameIndex(f.name), i);
    if (i < Robot::nb) {
      EXPECT_EQ(std::string(f.name), Robot::bodies[i].name);
    }
    const auto [body_link, T] = ref.bodyOf(f.name);
    const int body = (!Robot::floating_base && body_link == start) ? -1 : Robot::bodyIndex(body_link);
    EXPECT_EQ(f.body, body);
    expectPoseNear(framePose(f.xyz, f.rot), T, "frame placement");
  }
  if (all_frames) {
    std::vector<urdf::LinkSharedPtr> links;
    um.getLinks(links);
    const int world_link = start != um.getRoot()->name ? 1 : 0;   // 'world' + floating joint
    EXPECT_EQ(Robot::nframes, static_cast<int>(links.size()) - world_link);
  }
  EXPECT_EQ(Robot::frameIndex("no such frame"), -1);

  EXPECT_NEAR(Robot::total_mass, ref.mass(Robot::floating_base), 1e-12 * Robot::total_mass);
}

TEST(GeneratedVsUrdfdom, FusedPair) { checkAgainstUrdfdom<fused_pair::Robot>(kData + "/fused_pair.urdf", true); }
TEST(GeneratedVsUrdfdom, FusedPairSelectedFrames) {
  checkAgainstUrdfdom<fused_pair_frames::Robot>(kData + "/fused_pair.urdf", false);
}
TEST(GeneratedVsUrdfdom, FixedArm) { checkAgainstUrdfdom<fixed_arm::Robot>(kData + "/fixed_arm.urdf", true); }
TEST(GeneratedVsUrdfdom, WildXacroLeg) {
  checkAgainstUrdfdom<wild_xacro_leg::Robot>(kData + "/wild_xacro_leg.urdf", true);
}
TEST(GeneratedVsUrdfdom, WildFramesArm) {
  checkAgainstUrdfdom<wild_frames_arm::Robot>(kData + "/wild_frames_arm.urdf", true);
}
#ifdef HQP_HAVE_WALKER3
TEST(GeneratedVsUrdfdom, Walker3) { checkAgainstUrdfdom<walker3::Robot>(HQP_WALKER3_URDF, true); }
#endif
#ifdef HQP_HAVE_QUADRUPED
TEST(GeneratedVsUrdfdom, Quadruped) { checkAgainstUrdfdom<quadruped::Robot>(HQP_QUADRUPED_URDF, true); }
#endif

// ---------------------------------------------------------------------------
// Fixed-joint fusion by hand (tests/data/fused_pair.urdf)

static_assert(fused_pair::Robot::floating_base);
static_assert(fused_pair::Robot::nb == 2 && fused_pair::Robot::nj == 1);
static_assert(fused_pair::Robot::nq == 8 && fused_pair::Robot::nv == 7);
static_assert(fused_pair::Robot::nframes == 4);
static_assert(fused_pair::Robot::Frames::tool == 2 && fused_pair::Robot::Frames::tip == 3);
static_assert(fused_pair::Robot::frameIndex("tip") == 3);
static_assert(fused_pair::Robot::Joints::shoulder == 0);
static_assert(fused_pair::Robot::jointIndex("shoulder") == 0);
static_assert(fused_pair::Robot::jointIndex("") == -1, "the free root has no joint index");
static_assert(fused_pair::Robot::jointIndex("tool_mount") == -1, "fixed joints are not joints");

TEST(Fusion, RotatedChildAndRotatedInertialGiveTheClosedForm) {
  // arm: m1 = 2 at c1 = (0.1, 0, 0), I1 = diag(0.01, 0.02, 0.03).
  // tool: joint at (0.3, 0, 0) with R_j = Rx(90 deg); inertial at (0.1, 0.2, 0)
  // with Rz(90 deg), m2 = 1, diag(0.004, 0.005, 0.006) in its inertial frame.
  // R_j Rz(90) sends inertial x -> arm z, y -> -arm x, z -> -arm y, so in arm
  // axes I2 = diag(0.005, 0.006, 0.004), and c2 = (0.3,0,0) + R_j (0.1,0.2,0)
  // = (0.4, 0, 0.2).
  // m = 3, c = (2 c1 + c2) / 3 = (0.2, 0, 0.2/3).
  // Parallel axis for two masses: mu (|r|^2 E - r r^T), mu = m1 m2 / m = 2/3,
  // r = c2 - c1 = (0.3, 0, 0.2), |r|^2 = 0.13.
  const double mu = 2.0 / 3.0;
  const double xx = 0.01 + 0.005 + mu * (0.13 - 0.09);
  const double yy = 0.02 + 0.006 + mu * 0.13;
  const double zz = 0.03 + 0.004 + mu * (0.13 - 0.04);
  const double xz = -mu * 0.3 * 0.2;
  const auto& arm = fused_pair::Robot::bodies[1];
  const double tol = 1e-15;
  EXPECT_NEAR(arm.mass, 3.0, tol);
  EXPECT_NEAR(arm.com[0], 0.2, tol);
  EXPECT_NEAR(arm.com[1], 0.0, tol);
  EXPECT_NEAR(arm.com[2], 0.2 / 3.0, tol);
  EXPECT_NEAR(arm.inertia[0], xx, tol);
  EXPECT_NEAR(arm.inertia[1], yy, tol);
  EXPECT_NEAR(arm.inertia[2], zz, tol);
  EXPECT_NEAR(arm.inertia[3], 0.0, tol);   // xy
  EXPECT_NEAR(arm.inertia[4], xz, tol);
  EXPECT_NEAR(arm.inertia[5], 0.0, tol);   // yz

  // The massless sensor frame 'tip' adds nothing but stays a frame:
  // (0.3,0,0) + R_j (0, 0, 0.05) = (0.3, -0.05, 0), rotation R_j.
  const auto& tip = fused_pair::Robot::frames[fused_pair::Robot::Frames::tip];
  EXPECT_EQ(tip.body, 1);
  EXPECT_NEAR(tip.xyz[0], 0.3, tol);
  EXPECT_NEAR(tip.xyz[1], -0.05, tol);
  EXPECT_NEAR(tip.xyz[2], 0.0, tol);
  const double Rx90[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0};
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(tip.rot[k], Rx90[k], tol) << k;

  // Joint data: axis "0 0 2" normalized, limits, friction; the base keeps its own inertia.
  EXPECT_EQ(arm.axis[2], 1.0);
  EXPECT_EQ(arm.lower, -2.0);
  EXPECT_EQ(arm.upper, 2.0);
  EXPECT_EQ(arm.effort, 30.0);
  EXPECT_EQ(arm.velocity, 4.0);
  EXPECT_EQ(arm.damping, 0.2);
  EXPECT_EQ(arm.friction, 0.7);
  EXPECT_EQ(fused_pair::Robot::bodies[0].mass, 4.0);
  EXPECT_EQ(fused_pair::Robot::total_mass, 7.0);
}

// A heavy and a light link fused far from the body origin (tests/data/fused_heavy_light.urdf):
// summing both about the origin and shifting back lost the light link's inertia to rounding
// (a negative principal moment for a 2.9e15 kg link). Closed form as above: m = m1 + m2,
// I = I1 + I2 + mu (|r|^2 E - r r^T), r = c2 - c1 = (0, -1, 0), mu = m1 m2 / m.
TEST(Fusion, HeavyAndLightLinkFarOutGiveTheClosedForm) {
  const auto& b = fused_heavy_light::Robot::bodies[1];
  const double m1 = 1e6, m2 = 1.0, m = m1 + m2, mu = m1 * m2 / m;
  EXPECT_EQ(b.mass, m);
  EXPECT_NEAR(b.com[0], 1000.0, 1e-12);
  EXPECT_NEAR(b.com[1], 1000.0 - m2 / m, 1e-12);
  EXPECT_NEAR(b.com[2], 1000.0, 1e-12);
  const double small = 2e-4, big = 2e-4 + mu;   // yy is along r: only the two own inertias
  const double tol = 1e-9 * small;
  EXPECT_NEAR(b.inertia[0], big, 1e-9 * big);
  EXPECT_NEAR(b.inertia[1], small, tol);
  EXPECT_NEAR(b.inertia[2], big, 1e-9 * big);
  for (int k = 3; k < 6; ++k) EXPECT_NEAR(b.inertia[k], 0.0, tol) << k;
}

TEST(Frames, OnlyTheListedOnesBesidesTheBodies) {
  using R = fused_pair_frames::Robot;   // FRAMES tip
  static_assert(R::nframes == 3);
  EXPECT_STREQ(R::frames[0].name, "base");
  EXPECT_STREQ(R::frames[1].name, "arm");
  EXPECT_STREQ(R::frames[2].name, "tip");
  EXPECT_EQ(R::frameIndex("tool"), -1);
  EXPECT_EQ(R::Frames::tip, 2);
}

// ---------------------------------------------------------------------------
// Fixed base (tests/data/fixed_arm.urdf)

static_assert(!fixed_arm::Robot::floating_base);
static_assert(fixed_arm::Robot::nb == 3 && fixed_arm::Robot::nq == 3 && fixed_arm::Robot::nv == 3);
// Sanitized names: "2nd-link" -> _2nd_link, joint "new" -> new_.
static_assert(fixed_arm::Robot::Frames::_2nd_link == 2);
static_assert(fixed_arm::Robot::Joints::new_ == 2);
static_assert(fixed_arm::Robot::Joints::j0 == 0 && fixed_arm::Robot::Joints::j1 == 1);

TEST(FixedBase, WorldLinksAreFramesOfBodyMinusOneAndTheirMassIsDropped) {
  using R = fixed_arm::Robot;
  for (const char* name : {"pedestal", "camera", "plate"}) {
    const int f = R::frameIndex(name);
    ASSERT_GE(f, R::nb) << name;
    EXPECT_EQ(R::frames[f].body, -1) << name;
  }
  EXPECT_EQ(R::bodyIndex("pedestal"), -1);
  EXPECT_EQ(R::total_mass, 0.5 + 1.0 + 1.5);   // pedestal (10) and plate (3) never move
  // link1 hangs off 'plate' (fixed at z 0.2, yaw 0.5) at (0, 0, 0.1): in the
  // world, z = 0.3 and the yaw carries over.
  const auto& link1 = R::bodies[R::bodyIndex("link1")];
  EXPECT_EQ(link1.parent, -1);
  EXPECT_NEAR(link1.xyz[2], 0.3, 1e-15);
  EXPECT_NEAR(link1.rot[0], std::cos(0.5), 1e-15);
  EXPECT_NEAR(link1.rot[3], std::sin(0.5), 1e-15);
  EXPECT_EQ(R::bodies[R::bodyIndex("2nd-link")].parent, R::bodyIndex("link1"));
  EXPECT_EQ(R::bodies[R::bodyIndex("slider")].type, hqp::model::JointType::Prismatic);
}

// ---------------------------------------------------------------------------
// The header does not depend on the order of elements in the URDF.

// Shuffles the children of <robot> and of every <link>/<joint>.
void shuffleChildren(TiXmlElement* e, std::mt19937& rng, bool recurse) {
  std::vector<TiXmlNode*> kids;
  for (TiXmlNode* n = e->FirstChild(); n != nullptr; n = n->NextSibling()) kids.push_back(n->Clone());
  e->Clear();
  std::shuffle(kids.begin(), kids.end(), rng);
  for (TiXmlNode* k : kids) {
    e->LinkEndChild(k);
    if (recurse && k->ToElement() != nullptr) shuffleChildren(k->ToElement(), rng, false);
  }
}

void expectShuffleInvariant(const std::string& urdf, const std::string& built_header, const std::string& args,
                            const std::string& tag) {
  TiXmlDocument doc;
  ASSERT_TRUE(doc.LoadFile(urdf.c_str())) << urdf;
  std::mt19937 rng(20240611);
  shuffleChildren(doc.FirstChildElement("robot"), rng, true);
  const std::string shuffled = tmpPath(tag + "_shuffled.urdf");
  ASSERT_TRUE(doc.SaveFile(shuffled.c_str()));
  ASSERT_NE(readFile(shuffled), readFile(urdf)) << "the shuffle must change the file";
  const std::string out = tmpPath(tag + "_shuffled.hpp");
  const RunResult r = runGenerator("'" + shuffled + "' -o '" + out + "' " + args);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string expected = readFile(built_header);
  ASSERT_FALSE(expected.empty()) << built_header;
  EXPECT_TRUE(readFile(out) == expected) << "header of the shuffled URDF differs from " << built_header;
}

TEST(Determinism, ShuffledFusedPairGivesTheSameBytes) {
  expectShuffleInvariant(kData + "/fused_pair.urdf", HQP_FUSED_PAIR_HEADER, "--floating-base --namespace fused_pair",
                         "fused_pair");
}
TEST(Determinism, ShuffledFixedArmGivesTheSameBytes) {
  expectShuffleInvariant(kData + "/fixed_arm.urdf", HQP_FIXED_ARM_HEADER, "--namespace fixed_arm", "fixed_arm");
}
#ifdef HQP_HAVE_WALKER3
TEST(Determinism, ShuffledWalker3GivesTheSameBytes) {
  expectShuffleInvariant(HQP_WALKER3_URDF, HQP_WALKER3_HEADER, "--floating-base --namespace walker3", "walker3");
}
#endif
#ifdef HQP_HAVE_QUADRUPED
TEST(Determinism, ShuffledQuadrupedGivesTheSameBytes) {
  expectShuffleInvariant(HQP_QUADRUPED_URDF, HQP_QUADRUPED_HEADER, "--floating-base --namespace quadruped",
                         "quadruped");
}
#endif

// ---------------------------------------------------------------------------
// The robots the controller is built for

#ifdef HQP_HAVE_WALKER3
static_assert(walker3::Robot::floating_base);
static_assert(walker3::Robot::nq == 19 && walker3::Robot::nv == 18 && walker3::Robot::nj == 12);

TEST(Walker3, SolesAndFeetAreThere) {
  using R = walker3::Robot;
  for (const char* sole : {"l_sole", "r_sole"}) {
    const int f = R::frameIndex(sole);
    ASSERT_GE(f, 0) << sole;
    const int body = R::frames[f].body;
    ASSERT_GE(body, 1) << sole;
    // The sole moves with the last joint of its leg (ankle roll): a leaf body.
    for (int i = 0; i < R::nb; ++i) EXPECT_NE(R::bodies[i].parent, body) << sole;
  }
  EXPECT_GE(R::frameIndex("imu"), 0);
  EXPECT_EQ(R::frames[R::frameIndex("imu")].body, 0);
}
#endif

#ifdef HQP_HAVE_QUADRUPED
static_assert(quadruped::Robot::floating_base);
static_assert(quadruped::Robot::nq == quadruped::Robot::nj + 7);
#endif

}  // namespace
