// Plant perturbations (sim_demo/plant_perturbation.hpp) and the pass rules (sim_demo/run.hpp)
// against references that do not use the code under test: MuJoCo's own model and state,
// plant.yaml read here with yaml-cpp, closed forms (centre of mass with a point mass, weight on
// the feet), and the unperturbed plant run with the same open-loop commands.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "run.hpp"
#include "scenario.hpp"
#include "simulation.hpp"

namespace {

using hqp::sim::Command;
using hqp::sim::kContacts;
using hqp::sim::kJoints;
using hqp::sim::PlantPerturbation;
using hqp::sim::Robot;
using hqp::sim::Sensors;
using hqp::sim::Simulation;
using hqp::sim::SimulationOptions;

SimulationOptions options(const PlantPerturbation& p = {}) {
  SimulationOptions o;
  o.scene = HQP_SIM_SCENE;
  o.plant = HQP_SIM_PLANT;
  o.perturbation = p;
  return o;
}

double robotMass(const mjModel* m) {
  const int torso = mj_name2id(m, mjOBJ_BODY, "torso");
  double mass = 0.0;
  for (int b = 1; b < m->nbody; ++b) mass += m->body_rootid[b] == torso ? m->body_mass[b] : 0.0;
  return mass;
}

// Open-loop currents, the same for every plant: a slow sinusoid on every joint.
Command openLoop(int k) {
  Command c;
  for (int i = 0; i < kJoints; ++i) c.current[i] = 0.5 * std::sin(0.05 * k + i);
  return c;
}

// Sum of the noise-free F/T normal forces after `seconds` of the joint PD holding the pose.
double weightOnFeet(Simulation& sim, double seconds) {
  auto pd = hqp::sim::makeJointPdDriver(sim);
  Sensors s;
  Command cmd;
  const int ticks = static_cast<int>(seconds / sim.controlDt());
  double fz = 0.0;
  for (int k = 0; k < ticks; ++k) {
    sim.readSensors(s);
    pd->tick(s, cmd);
    sim.applyCommand(cmd);
    sim.step();
    if (k >= ticks - 100) {  // mean of the last 0.1 s
      for (int c = 0; c < kContacts; ++c) fz += sim.wrenchInSole(c, sim.trueForceTorque(c))[2] / 100.0;
    }
  }
  return fz;
}

TEST(PlantPerturbation, OffByDefaultAndTheModelIsUnchanged) {
  Simulation a(options());
  EXPECT_FALSE(PlantPerturbation{}.any());
  char error[1024] = {0};
  mjModel* m = mj_loadXML(HQP_SIM_SCENE, nullptr, error, sizeof(error));
  ASSERT_TRUE(m) << error;
  for (int b = 0; b < m->nbody; ++b) {
    EXPECT_EQ(a.model()->body_mass[b], m->body_mass[b]);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.model()->body_inertia[3 * b + k], m->body_inertia[3 * b + k]);
  }
  mj_deleteModel(m);
}

// A 5 kg point mass 0.2 m above and 0.05 m in front of the torso frame: the robot's mass and
// centre of mass follow the closed form, and the feet carry the extra weight.
TEST(PlantPerturbation, PayloadAddsItsMassAtItsPoint) {
  Simulation nominal(options());
  PlantPerturbation p;
  p.payload_link = "torso";
  p.payload_mass = 5.0;
  p.payload_position = Eigen::Vector3d(0.05, 0.0, 0.2);
  Simulation loaded(options(p));
  const double m0 = robotMass(nominal.model());
  EXPECT_NEAR(robotMass(loaded.model()), m0 + 5.0, 1e-9);
  const int torso = mj_name2id(nominal.model(), mjOBJ_BODY, "torso");
  EXPECT_NEAR(loaded.model()->body_subtreemass[torso], m0 + 5.0, 1e-9) << "mj_setConst not applied";
  // Same pose after reset (the standing pose lands on the floor in both).
  const double* R = nominal.data()->xmat + 9 * torso;
  const Eigen::Matrix3d Rt = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R);
  const Eigen::Vector3d p_world = Eigen::Vector3d(nominal.data()->xpos + 3 * torso) + Rt * p.payload_position;
  const Eigen::Vector3d expected = (m0 * nominal.centerOfMass() + 5.0 * p_world) / (m0 + 5.0);
  EXPECT_LT((loaded.centerOfMass() - expected).norm(), 1e-9);
  // The body's inertia stays symmetric positive definite in principal form.
  for (int k = 0; k < 3; ++k) EXPECT_GT(loaded.model()->body_inertia[3 * torso + k], 0.0);
  const double g = 9.81;
  EXPECT_NEAR(weightOnFeet(loaded, 1.0), (m0 + 5.0) * g, 0.01 * (m0 + 5.0) * g);
  EXPECT_NEAR(weightOnFeet(nominal, 1.0), m0 * g, 0.01 * m0 * g);
}

TEST(PlantPerturbation, MassScalesPerLinkAndForAll) {
  Simulation nominal(options());
  PlantPerturbation p;
  p.link_mass_scale = {{"torso", 1.1}};
  Simulation heavy_torso(options(p));
  const mjModel* a = nominal.model();
  const mjModel* b = heavy_torso.model();
  const int torso = mj_name2id(a, mjOBJ_BODY, "torso");
  for (int body = 0; body < a->nbody; ++body) {
    const double f = body == torso ? 1.1 : 1.0;
    EXPECT_NEAR(b->body_mass[body], f * a->body_mass[body], 1e-12) << body;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(b->body_inertia[3 * body + k], f * a->body_inertia[3 * body + k], 1e-12);
  }
  PlantPerturbation all;
  all.mass_scale = 0.9;
  Simulation light(options(all));
  EXPECT_NEAR(robotMass(light.model()), 0.9 * robotMass(a), 1e-9);
  const int ball = mj_name2id(a, mjOBJ_BODY, "ball");
  if (ball >= 0) {
    EXPECT_EQ(light.model()->body_mass[ball], a->body_mass[ball]) << "the ball is not the robot";
  }
}

// Each sensor group reads what the unperturbed plant read that many ticks earlier (same
// open-loop commands, so the same motion); the other groups are not delayed.
TEST(PlantPerturbation, SensorLatencyDelaysEachGroup) {
  PlantPerturbation p;
  p.encoder_latency = 2;
  p.imu_latency = 3;
  p.ft_latency = 0;
  Simulation nominal(options()), late(options(p));
  std::vector<Sensors> history;
  Sensors s0, s1;
  for (int k = 0; k < 60; ++k) {
    nominal.readSensors(s0);
    late.readSensors(s1);
    history.push_back(s0);
    const Sensors& enc = history[static_cast<std::size_t>(std::max(0, k - 2))];
    const Sensors& imu = history[static_cast<std::size_t>(std::max(0, k - 3))];
    EXPECT_EQ(s1.time, s0.time);
    EXPECT_EQ((s1.q - enc.q).norm(), 0.0) << k;
    EXPECT_EQ((s1.dq - enc.dq).norm(), 0.0) << k;
    EXPECT_EQ((s1.imu_gyro - imu.imu_gyro).norm(), 0.0) << k;
    EXPECT_EQ((s1.imu_accel - imu.imu_accel).norm(), 0.0) << k;
    EXPECT_EQ(s1.imu_orientation.coeffs(), imu.imu_orientation.coeffs()) << k;
    for (int c = 0; c < kContacts; ++c) EXPECT_EQ((s1.ft[c] - s0.ft[c]).norm(), 0.0) << k;
    const Command cmd = openLoop(k);
    nominal.applyCommand(cmd);
    late.applyCommand(cmd);
    nominal.step();
    late.step();
  }
  EXPECT_GT((history.back().q - history.front().q).norm(), 1e-3) << "the robot did not move: the test proves nothing";
}

// The motors apply the current of `actuator_latency` ticks ago (nothing before the first), times
// the plant's torque constant with its errors (plant.yaml read here).
TEST(PlantPerturbation, ActuatorLatencyAndTorqueConstantError) {
  PlantPerturbation p;
  p.actuator_latency = 3;
  p.torque_constant_error = 0.1;
  p.torque_constant_error_joint = {{"l_knee", -0.2}};
  Simulation sim(options(p));
  const YAML::Node plant = YAML::LoadFile(HQP_SIM_PLANT);
  for (int k = 0; k < 10; ++k) {
    sim.applyCommand(openLoop(k));
    for (int i = 0; i < kJoints; ++i) {
      const std::string joint = Robot::bodies[i + 1].joint;
      double kt = plant["joints"][joint.substr(2)]["torque_constant"].as<double>() * 1.1;
      if (joint == "l_knee") kt *= 0.8;
      const double expected = k < 3 ? 0.0 : kt * openLoop(k - 3).current[i];
      EXPECT_NEAR(sim.data()->ctrl[sim.actuator(i)], expected, 1e-12) << joint << " tick " << k;
    }
    sim.step();
  }
}

TEST(PlantPerturbation, ForceTorqueOffsetsFrictionAndContacts) {
  PlantPerturbation p;
  p.ft_offset[1] << 1, 2, 3, 0.1, 0.2, 0.3;
  p.joint_friction_scale = 1.3;
  p.ground_friction = 0.4;
  Simulation sim(options(p));
  Sensors s;
  sim.readSensors(s);
  EXPECT_LT((s.ft[1] - sim.trueForceTorque(1) - p.ft_offset[1]).norm(), 1e-12);
  EXPECT_LT((s.ft[0] - sim.trueForceTorque(0)).norm(), 1e-12);
  const YAML::Node plant = YAML::LoadFile(HQP_SIM_PLANT);
  for (int i = 0; i < kJoints; ++i) {
    const YAML::Node j = plant["joints"][std::string(Robot::bodies[i + 1].joint).substr(2)];
    EXPECT_NEAR(sim.model()->dof_frictionloss[sim.jointDofAdr(i)], 1.3 * j["coulomb"].as<double>(), 1e-12);
    EXPECT_NEAR(sim.jointDamping(i), 1.3 * j["viscous"].as<double>(), 1e-12);
    EXPECT_EQ(sim.model()->dof_damping[sim.jointDofAdr(i)], 0.0) << "damping is applied explicitly";
  }
  for (int g = 0; g < sim.model()->ngeom; ++g) EXPECT_EQ(sim.model()->geom_friction[3 * g], 0.4);
}

// Softer contacts let the standing robot sink further into the floor (MuJoCo's penetration).
TEST(PlantPerturbation, ContactPresetsChangeThePenetration) {
  auto sink = [](const std::string& preset) {
    PlantPerturbation p;
    p.contact = preset;
    Simulation sim(options(p));
    weightOnFeet(sim, 0.5);
    const int sole = mj_name2id(sim.model(), mjOBJ_BODY, "l_sole");
    return -sim.data()->xpos[3 * sole + 2];  // the sole frame is the plate's underside, the floor z = 0
  };
  const double soft = sink("soft"), normal = sink("default"), hard = sink("hard");
  EXPECT_GT(soft, normal);
  EXPECT_GT(normal, hard);
  EXPECT_GT(hard, 0.0);
  EXPECT_THROW(hqp::sim::contactPreset("squishy"), std::invalid_argument);
}

TEST(PlantPerturbation, UnknownNamesAreErrorsNamingThem) {
  PlantPerturbation p;
  p.payload_link = "tail";
  p.payload_mass = 1.0;
  try {
    Simulation sim(options(p));
    ADD_FAILURE() << "accepted an unknown link";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'tail'"), std::string::npos) << e.what();
  }
  PlantPerturbation q;
  q.torque_constant_error_joint = {{"l_elbow", 0.1}};
  EXPECT_THROW(Simulation sim(options(q)), std::runtime_error);
  // --set spelling of the same parameters.
  hqp::sim::ScenarioParams sp = hqp::sim::presetScenario("stand");
  hqp::sim::applyAssignment(sp, "payload=torso:5:0:0:0.3");
  hqp::sim::applyAssignment(sp, "link_mass_scale=torso:1.1,l_thigh:0.9");
  hqp::sim::applyAssignment(sp, "sensor_latency=2");
  EXPECT_EQ(sp.perturbation.payload_link, "torso");
  EXPECT_DOUBLE_EQ(sp.perturbation.payload_position.z(), 0.3);
  ASSERT_EQ(sp.perturbation.link_mass_scale.size(), 2u);
  EXPECT_EQ(sp.perturbation.link_mass_scale[1].first, "l_thigh");
  EXPECT_EQ(sp.perturbation.imu_latency, 2);
  EXPECT_EQ(sp.perturbation.ft_latency, 2);
  EXPECT_THROW(hqp::sim::applyAssignment(sp, "payload=torso:5"), std::invalid_argument);
  EXPECT_THROW(hqp::sim::applyAssignment(sp, "contact=squishy"), std::invalid_argument);
  EXPECT_THROW(hqp::sim::applyAssignment(sp, "sensor_latency=-1"), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Pass rules, with the balance controller.

hqp::sim::RunSummary runPreset(const std::string& name, const std::vector<std::string>& sets) {
  hqp::sim::ScenarioParams p = hqp::sim::presetScenario(name);
  for (const std::string& s : sets) hqp::sim::applyAssignment(p, s);
  SimulationOptions so = options(p.perturbation);
  so.scene = hqp::sim::scenePath(p, so.scene);
  Simulation sim(so);
  auto controller = hqp::sim::makeBalanceController(
      (std::filesystem::path(HQP_SIM_URDF).parent_path() / "controller.yaml").string(), p.controller == "wqp");
  return hqp::sim::runScenario(sim, *controller, hqp::sim::runOptions(p));
}

const hqp::sim::RuleResult& rule(const hqp::sim::RunSummary& r, const std::string& name) {
  for (const auto& x : r.rules) {
    if (x.name == name) return x;
  }
  throw std::runtime_error("no rule " + name);
}

// A 10 N·s push on a floor of friction 0.04: the robot stands and keeps its ZMP, but the soles
// slide (MuJoCo's sole positions), which only the slide rule catches. With friction 1 nothing slides.
TEST(PassRules, ASlidingSoleFailsTheRun) {
  if (!hqp::sim::balanceControllerAvailable()) GTEST_SKIP() << "built without the balance controller";
  const auto slippery = runPreset("push_x", {"pushes=1.5:10:0", "duration=3.5", "ground_friction=0.04"});
  EXPECT_FALSE(slippery.fell);
  EXPECT_TRUE(slippery.zmp_inside);
  EXPECT_GT(slippery.sole_slide[0], 0.005);
  EXPECT_FALSE(rule(slippery, "sole_slide").passed);
  EXPECT_FALSE(slippery.passed);
  const auto grippy = runPreset("push_x", {"pushes=1.5:10:0", "duration=3.5"});
  EXPECT_LT(std::max(grippy.sole_slide[0], grippy.sole_slide[1]), 0.001);
  for (const auto& x : grippy.rules) EXPECT_TRUE(x.passed) << x.name << " = " << x.value;
  EXPECT_TRUE(grippy.passed);
  // The threshold comes from the scenario parameters.
  const auto lenient =
      runPreset("push_x", {"pushes=1.5:10:0", "duration=3.5", "ground_friction=0.04", "rule_sole_slide=0.5"});
  EXPECT_TRUE(rule(lenient, "sole_slide").passed);
}

// The CoM's return between pushes: measured on still ground from the second rest point on (a
// push, or the end), off as a rule unless its threshold is set, and not measured on a moving
// support (the CoM follows the boards there).
TEST(PassRules, ComReturnComparesTheRestsBetweenPushes) {
  if (!hqp::sim::balanceControllerAvailable()) GTEST_SKIP() << "built without the balance controller";
  const std::vector<std::string> two = {"pushes=1.5:10:0,3.5:0.001:0", "duration=4"};
  auto with = [&](const std::string& extra) {
    auto v = two;
    v.push_back(extra);
    return runPreset("push_x", v);
  };
  const auto lenient = with("rule_com_return=0.5");
  ASSERT_FALSE(lenient.fell);
  ASSERT_TRUE(std::isfinite(lenient.com_return));
  // A 10 N·s push moves the CoM 4–6 cm; 2 s later it has come back, but not to the micrometre.
  EXPECT_GT(lenient.com_return, 1e-5);
  EXPECT_LT(lenient.com_return, 0.5 * (lenient.com_x_max - lenient.com_x_min));
  EXPECT_TRUE(rule(lenient, "com_return").passed);
  EXPECT_EQ(rule(lenient, "com_return").value, lenient.com_return);
  const auto strict = with("rule_com_return=0.00001");
  EXPECT_EQ(strict.com_return, lenient.com_return);  // the same deterministic run
  EXPECT_FALSE(rule(strict, "com_return").passed);
  EXPECT_FALSE(strict.passed);
  const auto plain = runPreset("push_x", two);  // the preset: measured, not a rule
  EXPECT_EQ(plain.com_return, lenient.com_return);
  // The pushes listed out of time order: the same rests.
  EXPECT_EQ(runPreset("push_x", {"pushes=3.5:0.001:0,1.5:10:0", "duration=4"}).com_return, lenient.com_return);
  EXPECT_THROW(rule(plain, "com_return"), std::runtime_error);
  const auto board = runPreset("seesaw_x", {"pushes=0.5:1:0", "duration=1", "rule_com_return=0.00001"});
  EXPECT_TRUE(std::isnan(board.com_return));
  EXPECT_THROW(rule(board, "com_return"), std::runtime_error);
}

// A rigid robot (joint PD) with 30 kg 0.4 m in front of its torso tips over its toes: the feet
// tilt on the floor. The metric is the angle between the sole's and the support's (world) z
// axes; on the floor it is at least the sole's world pitch, which MuJoCo's frame gives directly.
TEST(PassRules, FootTiltIsMeasuredAgainstTheSupport) {
  Simulation quiet_sim(options());
  auto pd = hqp::sim::makeJointPdDriver(quiet_sim);
  hqp::sim::RunOptions o;
  o.duration = 1.0;
  const auto quiet = hqp::sim::runScenario(quiet_sim, *pd, o);
  for (int c = 0; c < kContacts; ++c) EXPECT_LT(quiet.max_foot_tilt[c], 0.5 * M_PI / 180.0);
  EXPECT_EQ(rule(quiet, "foot_tilt_time").value, 0.0);
  EXPECT_TRUE(quiet.passed);
  PlantPerturbation p;
  p.payload_link = "torso";
  p.payload_mass = 30.0;
  p.payload_position = Eigen::Vector3d(0.4, 0.0, 0.0);
  Simulation sim(options(p));
  auto pd2 = hqp::sim::makeJointPdDriver(sim);
  o.duration = 3.0;
  const auto tipped = hqp::sim::runScenario(sim, *pd2, o);
  const double world_tilt = std::max(tipped.max_abs_foot_pitch[0], tipped.max_abs_foot_pitch[1]);
  EXPECT_GT(world_tilt, 5.0 * M_PI / 180.0) << "the robot did not tip: the test proves nothing";
  EXPECT_GE(std::max(tipped.max_foot_tilt[0], tipped.max_foot_tilt[1]) + 1e-6, 2.0 * M_PI / 180.0);
  EXPECT_GT(rule(tipped, "foot_tilt_time").value, 0.0);
  EXPECT_FALSE(rule(tipped, "foot_tilt_time").passed || tipped.passed);
}

}  // namespace
