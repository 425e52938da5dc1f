#pragma once
// friction_ablation: the paper's Sec. V-A claim that joint friction compensation (eqs. 5, 7) is
// essential, tested by running base scenarios (push_x, stand, seesaw_y, ...) under friction-compensation
// variants and comparing the joint torque tracking (τ_opt vs the torque the plant delivers after
// its friction) and the ZMP tracking (measured vs optimized). docs/scenarios.md,
// "Friction-compensation ablation". Not real-time code.

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "plant_config.hpp"
#include "run.hpp"
#include "scenario.hpp"

namespace hqp::sim {

// One way of configuring the controller's friction compensation: the scenario parameters
// friction_compensation (k_f), friction_model and friction_model_scale it sets.
struct FrictionVariant {
  const char* name;
  double k_f;          // < 0: the controller YAML's per joint
  const char* model;   // config | plant
  double scale;        // factor on F_c, F_v
  double kinematic;    // factor on k_q̇ (eq. 8)
  const char* meaning;
};

// on: k_f = 1 with the plant's true F_c, F_v; off: k_f = 0; low / high: k_f = 1 with F_c, F_v
// 30 % below / above the plant's; config: the controller YAML as shipped; on_kdq0 / off_kdq0: on
// and off without the kinematic compensation of eq. 8 (its velocity feedback also fights friction).
const std::vector<FrictionVariant>& frictionVariants();
bool isFrictionVariant(const std::string& name);

// The controller overrides a scenario's friction parameters ask for; `plant` supplies F_c, F_v
// with friction_model = plant. Throws std::runtime_error when plant lacks a joint.
ControllerOverrides controllerOverrides(const ScenarioParams& p, const PlantConfig& plant);

// One run of the ablation: preset `base` (its name kept, so scene and plots are the base's) with
// the ablation's controller, noise, seed and substeps, and the variant's friction parameters.
ScenarioParams ablationRunParams(const ScenarioParams& ablation, const std::string& base,
                                 const FrictionVariant& variant);

struct AblationRun {
  std::string scenario, variant;
  ScenarioParams params;
  RunSummary run;
};

struct AblationResult {
  std::vector<AblationRun> runs;  // scenario-major, in the order of the parameter lists
  bool passed = false;            // every run passed its scenario's criterion
  double wall_time = 0;           // s
};

// Runs every base scenario under every variant. `run_one` runs one scenario (a fresh simulation
// and driver built from its parameters) and returns its summary; `variant` names its output.
using AblationRunner = std::function<RunSummary(const ScenarioParams& p, const std::string& variant)>;
AblationResult runFrictionAblation(const ScenarioParams& ablation, const AblationRunner& run_one);

// The record (JSON, like report.hpp's), its console text and its markdown table.
nlohmann::ordered_json ablationRecord(const ScenarioParams& ablation, const AblationResult& r);
void printAblation(std::FILE* out, const nlohmann::ordered_json& record);
std::string ablationMarkdown(const nlohmann::ordered_json& record);

}  // namespace hqp::sim
