// Configuration: the shipped robots/walker3/controller.yaml loads and agrees with
// the URDF (read here as text, independently of the generated model), and broken
// files are rejected with a message that names the file and the offending key.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "tasks/controller_config_yaml.hpp"
#include "walker3_model.hpp"

namespace {

using Robot = walker3::Robot;
using Config = hqp::tasks::ControllerConfig<Robot::nj>;

const std::string kYaml = std::string(HQP_SOURCE_DIR) + "/robots/walker3/controller.yaml";
const std::string kUrdf = std::string(HQP_SOURCE_DIR) + "/robots/walker3/walker3.urdf";

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Attribute `attr` of the element `tag` (limit, dynamics) inside <joint name="joint">.
double urdfJointAttribute(const std::string& joint, const std::string& tag, const std::string& attr) {
  const std::string urdf = readText(kUrdf);
  const std::size_t start = urdf.find("<joint name=\"" + joint + "\"");
  if (start == std::string::npos) return std::nan("");
  const std::size_t end = urdf.find("</joint>", start);
  const std::string block = urdf.substr(start, end - start);
  std::smatch m;
  if (!std::regex_search(block, m, std::regex("<" + tag + "[^>]*\\s" + attr + "=\"([^\"]+)\""))) {
    return std::nan("");
  }
  return std::stod(m[1].str());
}

// The shipped file with one edit, written to a temporary file.
class EditedConfig {
 public:
  EditedConfig(const std::string& from, const std::string& to) {
    std::string text = readText(kYaml);
    const std::size_t at = text.find(from);
    found_ = at != std::string::npos;
    if (found_) text.replace(at, from.size(), to);
    path_ = ::testing::TempDir() + "controller_" + std::to_string(::getpid()) + "_" +
            std::to_string(counter_++) + ".yaml";
    std::ofstream(path_) << text;
  }
  ~EditedConfig() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }
  bool found() const { return found_; }

 private:
  static inline int counter_ = 0;
  std::string path_;
  bool found_ = false;
};

// The error message of loading `path`, or "" if it loads.
std::string loadError(const std::string& path) {
  try {
    hqp::tasks::loadControllerConfig<Robot>(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

void expectRejected(const std::string& from, const std::string& to,
                    const std::string& must_name) {
  EditedConfig f(from, to);
  ASSERT_TRUE(f.found()) << "test edit not applicable: " << from;
  const std::string msg = loadError(f.path());
  EXPECT_NE(msg.find(f.path()), std::string::npos) << msg;
  EXPECT_NE(msg.find(must_name), std::string::npos) << "expected '" << must_name << "' in: " << msg;
}

TEST(ControllerConfig, ShippedFileLoads) {
  const Config c = hqp::tasks::loadControllerConfig<Robot>(kYaml);
  EXPECT_EQ(c.solver, Config::Solver::Hqp);
  EXPECT_EQ(c.dt, 0.001);
  EXPECT_EQ(c.balance.mu, 0.6);
  EXPECT_EQ(c.balance.com.kp, 4.0);
  EXPECT_EQ(c.balance.com.kd, 3.0);
  EXPECT_EQ(c.balance.com_high.kp, 9.0);
  EXPECT_EQ(c.balance.com_high.kd, 6.0);
  EXPECT_EQ(c.balance.com_dcm_low, 0.07);
  EXPECT_EQ(c.balance.com_dcm_high, 0.10);
  EXPECT_EQ(c.balance.com_ki, 4.0);
  EXPECT_EQ(c.balance.com_integral_limit, 0.03);
  EXPECT_TRUE(c.balance.com_integral_reset);
  EXPECT_EQ(c.balance.torso_error_limit, 0.2);
  EXPECT_EQ(c.balance.hip_max_tilt, 0.7);
  EXPECT_EQ(c.balance.hip_stiffness, 100.0);
  EXPECT_EQ(c.balance.hip_damping, 10.0);
  EXPECT_EQ(c.balance.cop_moment_margin, 1.0);
  EXPECT_TRUE(c.planner.hold_tipping_axis);
  EXPECT_EQ(c.balance.com_vertical.kp, 9.0);
  EXPECT_EQ(c.balance.com_vertical.kd, 6.0);
  EXPECT_EQ(c.balance.torsion_radius, 0.05);
  EXPECT_EQ(c.estimator.contact_threshold, 8.0);
  EXPECT_LT(c.estimator.contact_threshold, c.balance.fz_min);
  EXPECT_EQ(c.joint.leak_time, 0.5);
  EXPECT_LT(c.balance.sole_x_min, c.balance.sole_x_max);
  EXPECT_GE(c.balance.sole_x_min, c.planner.sole_x_min);  // CoP region inside the sole
  EXPECT_LE(c.balance.sole_y_max, c.planner.sole_y_max);
  EXPECT_GT(c.safe.max_tilt, 0.0);
}

TEST(ControllerConfig, KneeTorqueLimitIsTheUrdfEffort) {
  const Config c = hqp::tasks::loadControllerConfig<Robot>(kYaml);
  EXPECT_EQ(urdfJointAttribute("l_knee", "limit", "effort"), 250.0);
  EXPECT_EQ(c.balance.tau_max[Robot::Joints::l_knee], 250.0);
  EXPECT_EQ(c.balance.tau_max[Robot::Joints::r_knee], 250.0);
}

TEST(ControllerConfig, PerJointValuesMatchTheUrdfByName) {
  const Config c = hqp::tasks::loadControllerConfig<Robot>(kYaml);
  for (const char* side : {"l_", "r_"}) {
    for (const char* j : {"hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll"}) {
      const std::string name = std::string(side) + j;
      const int k = Robot::jointIndex(name);
      ASSERT_GE(k, 0) << name;
      const double effort = urdfJointAttribute(name, "limit", "effort");
      EXPECT_EQ(c.balance.tau_max[k], effort) << name;
      // The current clamp is the same torque as the limit.
      EXPECT_NEAR(c.joint.current_limit[k] * c.joint.torque_constant[k], effort, 1e-9) << name;
      EXPECT_EQ(c.joint.friction[static_cast<std::size_t>(k)].coulomb,
                urdfJointAttribute(name, "dynamics", "friction")) << name;
      EXPECT_EQ(c.joint.friction[static_cast<std::size_t>(k)].viscous,
                urdfJointAttribute(name, "dynamics", "damping")) << name;
      EXPECT_GT(c.joint.friction[static_cast<std::size_t>(k)].dq_star, 0.0);
      EXPECT_GE(c.joint.k_f[k], 0.0);
      EXPECT_LE(c.joint.k_f[k], 1.0);
    }
  }
}

TEST(ControllerConfig, MissingKeyNamesKeyAndFile) {
  expectRejected("  mu: 0.6", "  # mu removed", "balance.mu");
  expectRejected("  max_tilt: 0.8", "  # gone", "safe_mode.max_tilt");
  expectRejected("com:          {kp: 4, kd: 3}", "com:          {kp: 4}", "balance.com.kd");
  expectRejected("com_integral: {ki: 4, limit: 0.03,", "com_integral: {ki: 4,", "balance.com_integral.limit");
  expectRejected("  com_vertical: {kp: 9, kd: 6}", "  # com_vertical gone", "balance.com_vertical");
  expectRejected("  torsion_radius: 0.05", "  # torsion_radius gone", "balance.torsion_radius");
  expectRejected("    r_knee:         250", "    # r_knee", "balance.torque_limit.r_knee");
  expectRejected("torque_constant: 5, current_limit: 16", "current_limit: 16",  // the left one
                 "joint_control.joints.l_ankle_roll.torque_constant");
}

TEST(ControllerConfig, UnknownJointIsNamed) {
  expectRejected("    l_knee:         {torque_constant", "    l_kneee:        {torque_constant",
                 "unknown joint 'l_kneee'");
  expectRejected("    r_hip_yaw:      100", "    r_hip_yawn:     100", "unknown joint 'r_hip_yawn'");
}

TEST(ControllerConfig, UnknownKeyIsRejected) {
  expectRejected("  mu: 0.6", "  muu: 0.6", "balance.muu");
  expectRejected("dq_star: 0.05, k_f: 0.8", "dq_star: 0.05, kf: 0.8", "kf");
}

TEST(ControllerConfig, NegativeOrInvalidValuesAreRejected) {
  expectRejected("com:          {kp: 4, kd: 3}", "com:          {kp: -4, kd: 3}", "balance.com.kp");
  expectRejected("reset_on_crossing: true", "reset_on_crossing: 1.5", "balance.com_integral.reset_on_crossing");
  expectRejected("  torso_error_limit: 0.2", "  torso_error_limit: 0", "balance.torso_error_limit");
  expectRejected("  cop_moment_margin: 1.0", "  cop_moment_margin: -0.1", "balance.cop_moment_margin");
  expectRejected("{max_tilt: 0.7,", "{max_tilt: 0,", "balance.hip_strategy.max_tilt");
  expectRejected("stiffness: 100, damping: 10}", "stiffness: 100, damping: -1}", "balance.hip_strategy.damping");
  expectRejected("stiffness: 100, damping: 10}", "stiffness: 100}", "balance.hip_strategy.damping");
  expectRejected("dcm_low: 0.07, dcm_high: 0.10", "dcm_low: 0.10, dcm_high: 0.07", "balance.com_schedule.dcm_high");
  expectRejected("com_integral: {ki: 4,", "com_integral: {ki: -4,", "balance.com_integral.ki");
  expectRejected("  hold_tipping_axis: true", "  hold_tipping_axis: 2x", "planner.hold_tipping_axis");
  expectRejected("com_vertical: {kp: 9, kd: 6}", "com_vertical: {kp: 9, kd: -6}", "balance.com_vertical.kd");
  expectRejected("  torsion_radius: 0.05", "  torsion_radius: 0", "balance.torsion_radius");
  // A foot loaded with fz_min must count as in contact.
  expectRejected("  contact_threshold: 8", "  contact_threshold: 10", "estimator.contact_threshold");
  expectRejected("torso:        {kp: 200, kd: 28.28}", "torso:        {kp: 200, kd: -1}",
                 "balance.torso.kd");
  expectRejected("k_dq: 20}", "k_dq: -20}", "joint_control.joints.l_knee.k_dq");
  expectRejected("  mu: 0.6", "  mu: abc", "balance.mu");
  expectRejected("  dt: 0.001", "  dt: 0", "controller.dt");
  expectRejected("  solver: hqp", "  solver: lqp", "controller.solver");
  expectRejected("    l_knee:         250", "    l_knee:         300", "balance.torque_limit.l_knee");
  expectRejected("x_min: -0.105, x_max: 0.105", "x_min: 0.105, x_max: -0.105", "balance.cop_region");
  expectRejected("  mu: 0.6", "  mu: .nan", "balance.mu");
  expectRejected("  follow_acceleration_cutoff: 20", "  follow_acceleration_cutoff: -1",
                 "planner.follow_acceleration_cutoff");
  expectRejected("  follow_translation: true", "  follow_translation: maybe", "planner.follow_translation");
  expectRejected("  follow_acceleration_order: 2", "  follow_acceleration_order: 3",
                 "planner.follow_acceleration_order");
  expectRejected("  hold_one_sided: true", "  hold_one_sided: yes please", "planner.hold_one_sided");
  // The one-sided hold refines hold_tipping_axis and needs it.
  expectRejected("  hold_tipping_axis: true", "  hold_tipping_axis: false", "planner.hold_one_sided");
  expectRejected("  follow_translation: true",
                 "  follow_translation: true\n  follow_acceleration_deadband: {linear: 0.5, angular: -1}",
                 "planner.follow_acceleration_deadband.angular");
}

// The feed-forward filter's stages and deadband reach the planner; absent, one stage and none.
TEST(ControllerConfig, FeedForwardOrderAndDeadband) {
  const Config shipped = hqp::tasks::loadControllerConfig<Robot>(kYaml);
  EXPECT_EQ(shipped.planner.follow_acceleration_order, 2);
  EXPECT_EQ(shipped.planner.follow_acceleration_deadband_linear, 0.0);
  EditedConfig f("  follow_translation: true",
                 "  follow_translation: true\n"
                 "  follow_acceleration_deadband: {linear: 0.5, angular: 1.0}");
  ASSERT_TRUE(f.found());
  const Config c = hqp::tasks::loadControllerConfig<Robot>(f.path());
  EXPECT_EQ(c.planner.follow_acceleration_order, 2);
  EXPECT_EQ(c.planner.follow_acceleration_deadband_linear, 0.5);
  EXPECT_EQ(c.planner.follow_acceleration_deadband_angular, 1.0);
  EditedConfig g("  follow_acceleration_order: 2", "  # (removed)");
  ASSERT_TRUE(g.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(g.path()).planner.follow_acceleration_order, 1);
}

// The moving-support options are optional; without them the planner is the paper's rule.
TEST(ControllerConfig, MovingSupportOptionsDefaultToThePaperRule) {
  const Config shipped = hqp::tasks::loadControllerConfig<Robot>(kYaml);
  EXPECT_EQ(shipped.planner.follow_acceleration_cutoff, 20.0);
  EXPECT_TRUE(shipped.planner.follow_translation);
  EditedConfig f("  follow_acceleration_cutoff: 20", "  # (removed)");
  ASSERT_TRUE(f.found());
  EditedConfig g("  follow_translation: true", "  # (removed)");
  ASSERT_TRUE(g.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(f.path()).planner.follow_acceleration_cutoff, 0.0);
  EXPECT_FALSE(hqp::tasks::loadControllerConfig<Robot>(g.path()).planner.follow_translation);
  EXPECT_TRUE(shipped.planner.hold_one_sided);
  EditedConfig o("  hold_one_sided: true", "  # (removed)");
  ASSERT_TRUE(o.found());
  EXPECT_FALSE(hqp::tasks::loadControllerConfig<Robot>(o.path()).planner.hold_one_sided);
  // The CoM extensions beyond the paper are off without their keys: the paper's PD.
  EditedConfig h("  com_schedule: {", "  # com_schedule: {");
  ASSERT_TRUE(h.found());
  EditedConfig i("  com_integral: {", "  # com_integral: {");
  ASSERT_TRUE(i.found());
  EXPECT_FALSE(hqp::tasks::loadControllerConfig<Robot>(h.path()).balance.com_dcm_high > 0.0);
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(i.path()).balance.com_ki, 0.0);
  EditedConfig j(", reset_on_crossing: true}", "}");  // the reset is optional too: off
  ASSERT_TRUE(j.found());
  EXPECT_FALSE(hqp::tasks::loadControllerConfig<Robot>(j.path()).balance.com_integral_reset);
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(j.path()).balance.com_ki, 4.0);
  EditedConfig k("  torso_error_limit: 0.2", "  # (removed)");  // the saturated torso PD: off
  ASSERT_TRUE(k.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(k.path()).balance.torso_error_limit,
            std::numeric_limits<double>::infinity());
  EditedConfig m("  hip_strategy: {", "  # hip_strategy: {");  // the hip-strategy budget: off
  ASSERT_TRUE(m.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(m.path()).balance.hip_max_tilt,
            std::numeric_limits<double>::infinity());
  EditedConfig r("  cop_moment_margin: 1.0", "  # cop_moment_margin: 1.0");  // optional: off
  ASSERT_TRUE(r.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(r.path()).balance.cop_moment_margin, 0.0);
}

TEST(ControllerConfig, OtherSolverAndInfiniteLeakLoad) {
  EditedConfig f("  solver: hqp", "  solver: wqp");
  ASSERT_TRUE(f.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(f.path()).solver, Config::Solver::Wqp);
  EditedConfig g("  leak_time: 0.5", "  leak_time: .inf");
  ASSERT_TRUE(g.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(g.path()).joint.leak_time,
            std::numeric_limits<double>::infinity());
}

// A joint's own leak time is optional: absent = the global leak_time (NaN in the parameters).
TEST(ControllerConfig, PerJointLeakTime) {
  const Config shipped = hqp::tasks::loadControllerConfig<Robot>(kYaml);
  EditedConfig e("k_dq: 20}  # ratio 100", "k_dq: 20, leak_time: 0.05}  # ratio 100");
  ASSERT_TRUE(e.found());  // the first knee entry: l_knee
  const Config c = hqp::tasks::loadControllerConfig<Robot>(e.path());
  const int knee = Robot::Joints::l_knee;
  EXPECT_TRUE(std::isnan(shipped.joint.joint_leak_time[knee]));
  EXPECT_EQ(c.joint.joint_leak_time[knee], 0.05);
  for (int j = 0; j < Robot::nj; ++j) {
    if (j != knee) {
      EXPECT_EQ(std::isnan(c.joint.joint_leak_time[j]), std::isnan(shipped.joint.joint_leak_time[j])) << j;
    }
  }
  EditedConfig bad("k_dq: 20}  # ratio 100", "k_dq: 20, leak_time: -1}  # ratio 100");
  try {
    (void)hqp::tasks::loadControllerConfig<Robot>(bad.path());
    ADD_FAILURE() << "negative leak_time accepted";
  } catch (const std::exception& ex) {
    EXPECT_NE(std::string(ex.what()).find("joint_control.joints.l_knee.leak_time"), std::string::npos) << ex.what();
  }
}

// The shipped `qp` section holds the solvers' defaults (behaviour as without it), and a file
// without the section loads with those defaults.
TEST(ControllerConfig, QpSectionDefaultsAreTheSolversDefaults) {
  const hqp::HqpSettings h;
  const hqp::QpSettings q;
  {
    // Without the section (it is the file's last).
    std::string text = readText(kYaml);
    text = text.substr(0, text.find("\nqp:\n"));
    const std::string path = ::testing::TempDir() + "no_qp_" + std::to_string(::getpid()) + ".yaml";
    std::ofstream(path) << text;
    const Config c = hqp::tasks::loadControllerConfig<Robot>(path);
    std::remove(path.c_str());
    EXPECT_EQ(c.qp.hqp.qp.max_iterations, h.qp.max_iterations);
    EXPECT_EQ(c.qp.hqp.rank_tol, h.rank_tol);
    EXPECT_TRUE(c.qp.wqp_dual_method);
  }
  const Config c = hqp::tasks::loadControllerConfig<Robot>(kYaml);
  for (const hqp::QpSettings* s : {&c.qp.hqp.qp, &c.qp.wqp}) {
    EXPECT_EQ(s->max_iterations, q.max_iterations);
    EXPECT_EQ(s->feasibility_tol, q.feasibility_tol);
    EXPECT_EQ(s->rank_tol, q.rank_tol);
    EXPECT_EQ(s->dual_tol, q.dual_tol);
    EXPECT_EQ(s->max_magnitude, q.max_magnitude);
  }
  EXPECT_EQ(c.qp.hqp.rank_tol, h.rank_tol);
  EXPECT_EQ(c.qp.hqp.warm_start, h.warm_start);
  EXPECT_EQ(c.qp.hqp.dual_last_level, h.dual_last_level);
  EXPECT_EQ(c.qp.hqp.defer_constraints, h.defer_constraints);
  EXPECT_EQ(c.qp.hqp.residual_rise_tol, h.residual_rise_tol);
  EXPECT_EQ(c.qp.hqp.budget_us, 0.0);  // no budget unless asked for
  EXPECT_EQ(c.qp.hqp.budget_iterations, 0);
  EXPECT_TRUE(c.qp.wqp_warm_start);
  EXPECT_TRUE(c.qp.wqp_dual_method);
  EditedConfig seven("max_iterations: 100", "max_iterations: 7");
  ASSERT_TRUE(seven.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(seven.path()).qp.hqp.qp.max_iterations, 7);
}

TEST(ControllerConfig, BudgetKeysSetTheSolversBudget) {
  EditedConfig us("budget_us: 0 ", "budget_us: 250.5 ");
  ASSERT_TRUE(us.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(us.path()).qp.hqp.budget_us, 250.5);
  EditedConfig it("budget_iterations: 0 ", "budget_iterations: 40 ");
  ASSERT_TRUE(it.found());
  EXPECT_EQ(hqp::tasks::loadControllerConfig<Robot>(it.path()).qp.hqp.budget_iterations, 40);
  EXPECT_TRUE(hqp::tasks::loadControllerConfig<Robot>(kYaml).qp.hqp.time_levels);
  EditedConfig tl("time_levels: true ", "time_levels: false ");
  ASSERT_TRUE(tl.found());
  EXPECT_FALSE(hqp::tasks::loadControllerConfig<Robot>(tl.path()).qp.hqp.time_levels);
}

TEST(ControllerConfig, BadQpValuesNameTheKey) {
  expectRejected("max_iterations: 100", "max_iterations: 0", "qp.hqp.max_iterations");
  expectRejected("max_iterations: 100", "max_iterations: 2.5", "qp.hqp.max_iterations");
  expectRejected("feasibility_tol: 1.0e-9", "feasibility_tol: -1.0e-9", "qp.hqp.feasibility_tol");
  expectRejected("level_rank_tol: 1.0e-9", "level_rank_tol: 2", "qp.hqp.level_rank_tol");
  expectRejected("residual_rise_tol: 1.0e-6", "residual_rise_tol: .nan", "qp.hqp.residual_rise_tol");
  expectRejected("max_magnitude: 1.0e50", "max_magnitude: 1.0e200", "qp.hqp.max_magnitude");
  expectRejected("budget_us: 0 ", "budget_us: -1 ", "qp.hqp.budget_us");
  expectRejected("budget_us: 0 ", "budget_us: .inf ", "qp.hqp.budget_us");
  expectRejected("budget_iterations: 0 ", "budget_iterations: 1.5 ", "qp.hqp.budget_iterations");
  expectRejected("budget_iterations: 0 ", "budget_iterations: -3 ", "qp.hqp.budget_iterations");
  expectRejected("time_levels: true ", "time_levels: often ", "qp.hqp.time_levels");
  expectRejected("    dual_method: true", "    dual_method: sometimes", "qp.wqp.dual_method");
  expectRejected("    dual_method: true", "    dual_methods: true", "qp.wqp.dual_methods");
  expectRejected("    warm_start: true          #", "    warmstart: true          #", "qp.hqp.warmstart");
}

TEST(ControllerConfig, MissingOrBrokenFileNamesTheFile) {
  const std::string missing = ::testing::TempDir() + "no_such_controller.yaml";
  const std::string msg = loadError(missing);
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;
  EditedConfig broken("controller:", "controller: [");
  ASSERT_TRUE(broken.found());
  const std::string msg2 = loadError(broken.path());
  EXPECT_NE(msg2.find(broken.path()), std::string::npos) << msg2;
}

TEST(ControllerConfig, DefaultConfigFollowsTheModel) {
  const Config c = hqp::tasks::defaultControllerConfig<Robot>();
  EXPECT_EQ(c.balance.tau_max[Robot::Joints::l_knee], 250.0);
  EXPECT_EQ(c.joint.friction[Robot::Joints::l_knee].coulomb, 5.0);
  EXPECT_EQ(c.joint.current_limit[Robot::Joints::l_knee], 250.0);
}

}  // namespace
