// The controller's state estimate against MuJoCo's true state (docs/controller.md, "State
// estimator"), on the paper's scenarios with the plant's sensor noise, IMU biases and heading
// drift on (seed 1). The errors come from runScenario, which compares the estimate of every tick
// with the MuJoCo state the sensors were read from. Thresholds and why:
// - standing and pushes: base and CoM velocity RMS ≤ 15 mm/s, half the per-tick kinematic velocity
//   noise (0.02 rad/s encoder rate noise over ~1 m of leg): the filter must average it;
// - seesaw_y: ≤ 50 mm/s, 5 % of the seesaw's 1 rad/s times the 1 m base height;
// - skate_x: ≤ 50 mm/s, 5 % of the board's 0.96 m/s peak, and below a quarter of the stance-foot
//   estimator's error on the same run (it assumes the board foot stands still: −v/2);
//   the support velocity of the loaded feet ≤ 60 mm/s;
// - orientation (the IMU's own): max ≤ the plant's 1 mrad/s heading drift times the run's length
//   plus 0.5° (the 2 mrad white noise, 5 σ, and the torso's lean about the drifted axis).
// Every run must also pass (no fall, no safe mode, ZMPs inside).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "friction_ablation.hpp"
#include "run.hpp"
#include "scenario.hpp"
#include "simulation.hpp"

namespace {

hqp::sim::RunSummary runPreset(const std::string& name, const std::string& estimator) {
  hqp::sim::ScenarioParams p = hqp::sim::presetScenario(name);
  hqp::sim::applyAssignment(p, "noise=true");
  hqp::sim::applyAssignment(p, "seed=1");
  hqp::sim::applyAssignment(p, "estimator=" + estimator);
  hqp::sim::SimulationOptions so;
  so.scene = hqp::sim::scenePath(p, HQP_SIM_SCENE);
  so.plant = HQP_SIM_PLANT;
  so.noise = p.noise;
  so.seed = p.seed;
  hqp::sim::Simulation sim(so);
  const std::string config = (std::filesystem::path(HQP_SIM_URDF).parent_path() / "controller.yaml").string();
  auto driver = hqp::sim::makeBalanceController(config, false, hqp::sim::controllerOverrides(p, sim.plant()));
  hqp::sim::RunOptions o = hqp::sim::runOptions(p);
  o.out_dir.clear();
  o.video = false;
  return hqp::sim::runScenario(sim, *driver, o);
}

void expectAccurate(const hqp::sim::RunSummary& r, double velocity_rms, const char* what) {
  SCOPED_TRACE(what);
  // Balance kept (no fall, ZMP inside, no safe mode); the stricter contact rules (sole slide,
  // tilt) are the scenario matrix's business, not the estimator's.
  EXPECT_FALSE(r.fell) << r.fall_reason;
  EXPECT_TRUE(r.zmp_inside);
  EXPECT_EQ(r.safe_mode_ticks, 0);
  ASSERT_TRUE(r.estimator.available);
  EXPECT_GT(r.estimator.base_velocity.n, 1000);
  EXPECT_LE(r.estimator.base_velocity.rms, velocity_rms);
  EXPECT_LE(r.estimator.com_velocity.rms, velocity_rms);
  EXPECT_LE(r.estimator.orientation.max, 1e-3 * r.duration + 0.5 * M_PI / 180.0);
  EXPECT_LE(r.estimator.base_position.rms, 0.08);  // m: drift of a position nothing observes absolutely
}

TEST(EstimatorAccuracy, StandWithNoise) {
  expectAccurate(runPreset("stand", "kinematic_inertial"), 0.015, "stand");
}

TEST(EstimatorAccuracy, PushXWithNoise) {
  expectAccurate(runPreset("push_x", "kinematic_inertial"), 0.015, "push_x");
}

TEST(EstimatorAccuracy, SeesawYWithNoise) {
  expectAccurate(runPreset("seesaw_y", "kinematic_inertial"), 0.05, "seesaw_y");
}

TEST(EstimatorAccuracy, SkateXWithNoiseBeatsTheStanceFootAssumption) {
  const hqp::sim::RunSummary fused = runPreset("skate_x", "kinematic_inertial");
  expectAccurate(fused, 0.05, "skate_x, kinematic_inertial");
  EXPECT_LE(fused.estimator.support_velocity.rms, 0.06);
  const hqp::sim::RunSummary stance = runPreset("skate_x", "stance");
  ASSERT_TRUE(stance.estimator.available);
  // The stance-foot estimator's phantom −v/2 on the board foot's side.
  EXPECT_GT(stance.estimator.base_velocity.rms, 0.15);
  EXPECT_LT(fused.estimator.base_velocity.rms, 0.25 * stance.estimator.base_velocity.rms);
}

}  // namespace
