#pragma once
// Named scenarios of the MuJoCo demo (docs/scenarios.md): presets of the paper's Section VI-A
// (quiet standing, the Table II push series, a push sweep) whose every parameter can be
// overridden from a YAML file or `--set key=value`. Not real-time code.

#include <string>
#include <utility>
#include <vector>

#include "plant_perturbation.hpp"
#include "run.hpp"
#include "support_motion.hpp"

namespace hqp::sim {

// Bisection for the largest impulse survived along each direction (push_sweep), or for the
// largest board velocity along each axis (skate_sweep: values are fractions of the paper's peak).
struct SweepParams {
  bool skate = false;          // skate_sweep: directions are x, y, z, roll, pitch, yaw
  std::vector<std::string> directions = {"+x", "-x", "+y", "-y"};
  double min_impulse = 4.0;    // N·s, first bracket end (expected to pass)
  double max_impulse = 40.0;   // N·s, other end (expected to fail)
  double resolution = 0.25;    // N·s, stop when the bracket is this narrow
  double push_time = 2.0;      // s after the start of each trial
  double observe = 3.0;        // s simulated after the push
  double required = 12.0;      // N·s, the sweep passes when every direction survives this (paper: 12)
  double frequency = 0.0;      // Hz, skate_sweep: the board's frequency (0: the skate_* preset's)
};

// friction_ablation: every base scenario under every friction-compensation variant
// (friction_ablation.hpp lists the variants).
struct AblationParams {
  // push_x: friction under pushes; stand: where compensation matters most; seesaw_y: a moving support.
  std::vector<std::string> scenarios = {"push_x", "stand", "seesaw_y"};
  std::vector<std::string> variants = {"on", "off", "low", "high", "config", "on_kdq0", "off_kdq0"};
};

struct ScenarioParams {
  std::string name;
  std::string description;
  RunOptions run;                 // duration, pushes, fall/ZMP criteria, video size
  bool ball = false;               // pushes throw the scene's 5 kg ball instead of a force on the torso
  double push_duration = 0.01;    // s, force pushes only
  std::string controller = "hqp"; // hqp | wqp
  bool noise = false;             // plant.yaml sensor noise
  unsigned seed = 1;
  int substeps = 1;               // physics steps per 1 ms tick
  bool sweep = false;             // push_sweep: bisection instead of one run
  SweepParams sweep_params;
  // The controller's joint friction compensation (eqs. 5, 7), overriding its YAML.
  double friction_compensation = -1.0;    // k_f of every joint; < 0: the YAML's per joint
  std::string friction_model = "config";  // F_c, F_v: config (the YAML's) or plant (plant.yaml's, the truth)
  double friction_model_scale = 1.0;      // factor on those F_c and F_v
  double kinematic_compensation = 1.0;    // factor on the YAML's k_q̇ (eq. 8)
  std::string estimator = "config";       // config (controller YAML's), stance or kinematic_inertial
  PlantPerturbation perturbation;         // the plant's differences from the controller's model
  bool ablation = false;                  // friction_ablation: runs instead of one run
  bool robustness = false;                // robustness: the matrix of robustness_matrix (sim_demo processes)
  std::string robustness_matrix;          // its YAML file; empty: robots/walker3/robustness.yaml
  AblationParams ablation_params;
  // Moving supports: the scene file (in the directory of the default scene.xml) and
  // one motion per servo axis of kSupportAxes (amplitude 0 and offset 0: not driven).
  std::string scene = "scene.xml";
  std::vector<SupportMotion> supports;
  double support_ramp = 0.5;      // s, ramp of motions set from text (motion_ramp also sets every existing one)
};

// The servo axes a scene may have (seesaw scenes: seesaw; skateboards: the rest).
const std::vector<std::string>& supportAxes();
// The paper's peak right-foot velocity for skate axis x, y, z (m/s), roll, pitch, yaw (rad/s).
double paperSkatePeak(const std::string& axis);
// The scene file of a scenario: p.scene next to `default_scene` (the build's scene.xml).
std::string scenePath(const ScenarioParams& p, const std::string& default_scene);

// The presets, in the order `--list` shows them.
std::vector<std::string> scenarioNames();
// Throws std::invalid_argument naming the unknown scenario and the known ones.
ScenarioParams presetScenario(const std::string& name);
// One parameter from text (`--set key=value`); throws std::invalid_argument naming the key
// (unknown key: lists the valid ones) and the bad value.
void setParameter(ScenarioParams& p, const std::string& key, const std::string& value);
// `--set key=value` split and applied.
void applyAssignment(ScenarioParams& p, const std::string& assignment);
// A YAML map of the same keys (sequences for list values); errors name the file and key.
void applyParameterFile(ScenarioParams& p, const std::string& yaml_path);
// The run's options: `run` with the push method applied to every push.
RunOptions runOptions(const ScenarioParams& p);
// (key, current value as `--set` would accept it) for every parameter: the run's record.
std::vector<std::pair<std::string, std::string>> parameterValues(const ScenarioParams& p);
// (key, meaning) for the help text.
std::vector<std::pair<std::string, std::string>> parameterHelp();

}  // namespace hqp::sim
