// The two measurements of the friction-compensation ablation (docs/scenarios.md,
// "Friction-compensation ablation"), checked against independent computations:
//  - Simulation::deliveredTorque() (actuator torque minus the joint friction MuJoCo applied) equals
//    M q̈ + C q̇ + G on every joint of a robot in free fall, with q̈ from the velocity change of the
//    step, M and the bias from a separate mjData at the step's start state;
//  - the friction parameters of a scenario reach the controller: its joint-level torque equals
//    eq. 5 with τ_f from eq. 7 and τ_q̇ from eq. 8 recomputed here (q̇_des integrated here from the
//    controller's q̈*), so k_f = 0 removes τ_f and the model scale scales it.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "friction_ablation.hpp"
#include "run.hpp"
#include "scenario.hpp"
#include "simulation.hpp"
#include "support/urdf_to_mujoco.hpp"

namespace {

using hqp::sim::kJoints;
using hqp::sim::Robot;
using hqp::sim::Simulation;
using hqp::sim::VectorJ;

hqp::sim::SimulationOptions defaultOptions() {
  hqp::sim::SimulationOptions o;
  o.scene = HQP_SIM_SCENE;
  o.plant = HQP_SIM_PLANT;
  return o;
}

std::string jointName(int i) { return Robot::bodies[i + 1].joint; }

// ---------------------------------------------------------------------------------------------
// Free fall (no contact), torques of 0.5..2 F_c in a 4 Hz pattern: joints stick, slide and reverse.
// The joint rows of MuJoCo's equation of motion then hold only the actuator, the joint friction
// and the rigid-body terms, so the delivered torque must equal M q̈ + bias there. Leaving out the
// frictionloss force (up to F_c = 5.5 N·m) or taking the damping at the start velocity (h D q̈, up
// to 0.04 N·m here) breaks the identity by far more than the tolerance (both checked by mutation).
TEST(SimDeliveredTorque, EqualsTheRigidBodyTorqueInFreeFall) {
  Simulation sim(defaultOptions());
  const mjModel* m = sim.model();
  mjData* d = sim.data();
  d->qpos[sim.baseQposAdr() + 2] += 1.0;  // 1 m up: ~0.2 m of fall in 0.2 s, no contact
  mj_forward(m, d);
  hqp::test::MjDataPtr ref(mj_makeData(m));
  const double h = m->opt.timestep;
  ASSERT_EQ(sim.controlDt(), h);
  std::vector<mjtNum> M(static_cast<std::size_t>(m->nv * m->nv));
  int stuck = 0, sliding = 0;
  double max_friction = 0.0;
  for (int k = 0; k < 200; ++k) {
    hqp::sim::Command cmd;
    for (int i = 0; i < kJoints; ++i) {
      const double fc = m->dof_frictionloss[sim.jointDofAdr(i)];
      const double amp = (0.5 + 1.5 * i / (kJoints - 1.0)) * fc;
      cmd.current[i] = amp * std::sin(2 * M_PI * 4.0 * k * h + i) / sim.torqueConstant()[i];
    }
    sim.applyCommand(cmd);
    // Start state of the step, copied before it.
    mj_resetData(m, ref.get());
    for (int q = 0; q < m->nq; ++q) ref->qpos[q] = d->qpos[q];
    for (int v = 0; v < m->nv; ++v) ref->qvel[v] = d->qvel[v];
    const std::vector<mjtNum> v0(d->qvel, d->qvel + m->nv);
    sim.step();
    mj_forward(m, ref.get());
    mj_fullM(m, M.data(), ref->qM);
    for (int c = 0; c < d->ncon; ++c) {  // only the parked ball may touch the floor
      const int b1 = m->body_rootid[m->geom_bodyid[d->contact[c].geom1]];
      const int b2 = m->body_rootid[m->geom_bodyid[d->contact[c].geom2]];
      ASSERT_TRUE(b1 != m->body_rootid[mj_name2id(m, mjOBJ_BODY, Robot::bodies[0].name)] &&
                  b2 != m->body_rootid[mj_name2id(m, mjOBJ_BODY, Robot::bodies[0].name)])
          << "the falling robot touched something at tick " << k;
    }
    const VectorJ delivered = sim.deliveredTorque();
    for (int i = 0; i < kJoints; ++i) {
      const int dof = sim.jointDofAdr(i);
      double rigid = ref->qfrc_bias[dof];
      for (int v = 0; v < m->nv; ++v) rigid += M[static_cast<std::size_t>(dof * m->nv + v)] * (d->qvel[v] - v0[v]) / h;
      EXPECT_NEAR(delivered[i], rigid, 1e-7) << jointName(i) << " at tick " << k;
      // Friction the joint took: actuator minus delivered minus the damping at the start velocity.
      const double friction = d->actuator_force[sim.actuator(i)] - sim.jointDamping(i) * v0[dof] - delivered[i];
      max_friction = std::max(max_friction, std::abs(friction));
      if (std::abs(d->qvel[dof]) < 1e-4) ++stuck;
      else ++sliding;
    }
  }
  // The pattern exercised both regimes and a friction force comparable to F_c.
  EXPECT_GT(stuck, 100);
  EXPECT_GT(sliding, 100);
  EXPECT_GT(max_friction, 1.5);
}

// ---------------------------------------------------------------------------------------------
// eq. 7, written here from the paper (linear band ±q̇*, viscous term from the band edge).
double frictionEq7(double fc, double fv, double dq_star, double dq) {
  if (dq >= dq_star) return fc + fv * (dq - dq_star);
  if (dq <= -dq_star) return -fc + fv * (dq + dq_star);
  return fc * dq / dq_star;
}

struct JointYaml {
  double k_dq, dq_star, coulomb, viscous, k_f, leak;  // leak: the joint's own leak_time, else the global one
};

struct Case {
  const char* sets[3];
  double k_f;  // expected k_f of every joint (< 0: the YAML's)
  bool plant;  // expected F_c, F_v: the plant's (else the YAML's)
  double scale;
  double kinematic = 1.0;  // expected factor on the YAML's k_q̇
};

// A 6 N·s push along X at 0.1 s moves every leg joint through all three branches of eq. 7.
// Returns the largest |cmd.torque − expected| over 400 ticks, and the largest |τ_f| term.
void checkJointLevel(const Case& c, double& max_error, double& max_tau_f, std::array<int, 3>& branches) {
  const std::string config_path =
      (std::filesystem::path(HQP_SIM_URDF).parent_path() / "controller.yaml").string();
  const YAML::Node y = YAML::LoadFile(config_path)["joint_control"];
  const double leak = y["leak_time"].as<double>();
  std::vector<JointYaml> joints;
  for (int i = 0; i < kJoints; ++i) {
    const YAML::Node j = y["joints"][jointName(i)];
    joints.push_back({j["k_dq"].as<double>(), j["dq_star"].as<double>(), j["coulomb"].as<double>(),
                      j["viscous"].as<double>(), j["k_f"].as<double>(),
                      j["leak_time"] ? j["leak_time"].as<double>() : leak});
  }
  const YAML::Node plant = YAML::LoadFile(HQP_SIM_PLANT)["joints"];

  hqp::sim::ScenarioParams p = hqp::sim::presetScenario("stand");
  for (const char* s : c.sets) {
    if (s) hqp::sim::applyAssignment(p, s);
  }
  Simulation sim(defaultOptions());
  auto driver = hqp::sim::makeBalanceController(config_path, false, hqp::sim::controllerOverrides(p, sim.plant()));
  ASSERT_TRUE(driver);
  sim.reset();
  driver->reset();
  const double dt = 0.001;
  VectorJ dq_des = VectorJ::Zero();
  hqp::sim::Sensors s;
  hqp::sim::Command cmd;
  hqp::sim::JointTargets t;
  max_error = max_tau_f = 0.0;
  branches = {0, 0, 0};
  for (int k = 0; k < 400; ++k) {
    sim.readSensors(s);
    driver->tick(s, cmd);
    ASSERT_TRUE(driver->jointTargets(t)) << "safe mode at tick " << k;
    if (k == 0) dq_des = s.dq;
    for (int i = 0; i < kJoints; ++i) {
      const JointYaml& j = joints[static_cast<std::size_t>(i)];
      dq_des[i] += t.ddq_opt[i] * dt;
      dq_des[i] += (1.0 - std::exp(-dt / j.leak)) * (s.dq[i] - dq_des[i]);
      double fc = j.coulomb, fv = j.viscous;
      if (c.plant) {
        const YAML::Node pj = plant[jointName(i).substr(2)];
        fc = pj["coulomb"].as<double>();
        fv = pj["viscous"].as<double>();
      }
      const double k_f = c.k_f < 0 ? j.k_f : c.k_f;
      const double tau_f = k_f * frictionEq7(c.scale * fc, c.scale * fv, j.dq_star, dq_des[i]);
      const double tau_dq = c.kinematic * j.k_dq * (dq_des[i] - s.dq[i]);
      max_error = std::max(max_error, std::abs(cmd.torque[i] - (t.tau_opt[i] + tau_f + tau_dq)));  // eq. 5
      max_tau_f = std::max(max_tau_f, std::abs(tau_f));
      ++branches[dq_des[i] >= j.dq_star ? 0 : dq_des[i] <= -j.dq_star ? 2 : 1];
    }
    sim.applyCommand(cmd);
    sim.setTorsoForce(k >= 100 && k < 110 ? Eigen::Vector3d(600.0, 0.0, 0.0) : Eigen::Vector3d::Zero());
    sim.step();
  }
}

TEST(SimFrictionCompensation, ScenarioParametersReachTheJointLevel) {
  if (!hqp::sim::balanceControllerAvailable()) GTEST_SKIP() << "built without the balance controller";
  const std::vector<Case> cases = {
      {{"friction_compensation=0", nullptr, nullptr}, 0.0, false, 1.0},
      {{"friction_compensation=1", "friction_model=plant", nullptr}, 1.0, true, 1.0},
      {{"friction_compensation=1", "friction_model=plant", "friction_model_scale=0.7"}, 1.0, true, 0.7},
      {{nullptr, nullptr, nullptr}, -1.0, false, 1.0},  // the YAML as shipped (k_f 0.8)
      {{"friction_compensation=0", "kinematic_compensation=0", nullptr}, 0.0, false, 1.0, 0.0},
  };
  double tau_f_on = 0.0;
  for (const Case& c : cases) {
    double err = 0, tau_f = 0;
    std::array<int, 3> branches{};
    std::string what;
    for (const char* s : c.sets) what += s ? std::string(s) + " " : "";
    SCOPED_TRACE(what.empty() ? "defaults" : what);
    checkJointLevel(c, err, tau_f, branches);
    EXPECT_LT(err, 1e-9);
    for (int b = 0; b < 3; ++b) EXPECT_GT(branches[b], 20) << "branch " << b << " of eq. 7 barely reached";
    if (c.k_f == 0.0) EXPECT_EQ(tau_f, 0.0);  // (the expectation had none: err is the check)
    else tau_f_on = std::max(tau_f_on, tau_f);
  }
  // The compensation the k_f = 0 case must not contain is large: that case can fail.
  EXPECT_GT(tau_f_on, 2.0);
}

// The run's torque-tracking summary is the RMS of the CSV's tau_err_<joint> columns (recomputed
// here from the file, over all ticks and joints) and their largest magnitude.
TEST(SimFrictionCompensation, TorqueTrackingSummaryMatchesTheCsv) {
  if (!hqp::sim::balanceControllerAvailable()) GTEST_SKIP() << "built without the balance controller";
  const std::string config_path =
      (std::filesystem::path(HQP_SIM_URDF).parent_path() / "controller.yaml").string();
  Simulation sim(defaultOptions());
  auto driver = hqp::sim::makeBalanceController(config_path, false);
  ASSERT_TRUE(driver);
  hqp::sim::ScenarioParams p = hqp::sim::presetScenario("stand");
  hqp::sim::applyAssignment(p, "duration=0.5");
  hqp::sim::RunOptions o = hqp::sim::runOptions(p);
  o.out_dir = (std::filesystem::temp_directory_path() / "hqp_test_friction_ablation").string();
  const hqp::sim::RunSummary r = hqp::sim::runScenario(sim, *driver, o);
  std::ifstream csv(r.csv_path);
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  std::vector<int> cols;
  {
    std::stringstream h(line);
    std::string name;
    for (int c = 0; std::getline(h, name, ','); ++c) {
      if (name.rfind("tau_err_", 0) == 0) cols.push_back(c);
    }
  }
  ASSERT_EQ(cols.size(), static_cast<std::size_t>(kJoints));
  double sum = 0.0, max = 0.0;
  long n = 0;
  while (std::getline(csv, line)) {
    std::stringstream row(line);
    std::string field;
    std::size_t k = 0;
    for (int c = 0; std::getline(row, field, ','); ++c) {
      if (k < cols.size() && c == cols[k]) {
        const double e = std::stod(field);
        sum += e * e;
        max = std::max(max, std::abs(e));
        ++n;
        ++k;
      }
    }
  }
  ASSERT_EQ(n, 500L * kJoints);
  EXPECT_NEAR(r.torque_tracking_rms, std::sqrt(sum / n), 1e-4);  // the CSV has 4 decimals
  EXPECT_NEAR(r.torque_tracking_max, max, 1e-4);
  EXPECT_GT(r.torque_tracking_rms, 0.0);
  std::filesystem::remove_all(o.out_dir);
}

TEST(SimFrictionCompensation, ParametersAndVariants) {
  hqp::sim::ScenarioParams p = hqp::sim::presetScenario("push_x");
  EXPECT_LT(p.friction_compensation, 0.0);
  hqp::sim::applyAssignment(p, "friction_compensation=0.25");
  EXPECT_EQ(p.friction_compensation, 0.25);
  hqp::sim::applyAssignment(p, "friction_compensation=config");
  EXPECT_LT(p.friction_compensation, 0.0);
  EXPECT_THROW(hqp::sim::applyAssignment(p, "friction_compensation=-1"), std::invalid_argument);
  EXPECT_THROW(hqp::sim::applyAssignment(p, "friction_model=ideal"), std::invalid_argument);
  EXPECT_THROW(hqp::sim::applyAssignment(p, "ablation_scenarios=push_x,push_sweep"), std::invalid_argument);
  EXPECT_THROW(hqp::sim::applyAssignment(p, "ablation_variants=on,half"), std::invalid_argument);

  hqp::sim::ScenarioParams a = hqp::sim::presetScenario("friction_ablation");
  EXPECT_TRUE(a.ablation);
  hqp::sim::applyAssignment(a, "ablation_scenarios=stand");
  hqp::sim::applyAssignment(a, "ablation_variants=off,high,off_kdq0");
  hqp::sim::applyAssignment(a, "controller=wqp");
  std::vector<std::string> seen;
  const auto result = hqp::sim::runFrictionAblation(a, [&](const hqp::sim::ScenarioParams& v, const std::string& name) {
    seen.push_back(v.name + "/" + name);
    EXPECT_EQ(v.controller, "wqp");
    EXPECT_EQ(v.friction_model, "plant");
    EXPECT_EQ(v.friction_compensation, name == "high" ? 1.0 : 0.0);
    EXPECT_DOUBLE_EQ(v.friction_model_scale, name == "high" ? 1.3 : 1.0);
    EXPECT_DOUBLE_EQ(v.kinematic_compensation, name == "off_kdq0" ? 0.0 : 1.0);
    hqp::sim::RunSummary r;
    r.passed = name == "off";
    return r;
  });
  EXPECT_EQ(seen, (std::vector<std::string>{"stand/off", "stand/high", "stand/off_kdq0"}));
  EXPECT_FALSE(result.passed);  // one run failed
}

}  // namespace
