#include "friction_ablation.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "report.hpp"

namespace hqp::sim {

namespace {

std::string fmt(const char* f, double x) {
  char b[64];
  std::snprintf(b, sizeof(b), f, x);
  return b;
}

std::string fmtOr(const nlohmann::ordered_json& j, const char* f) { return j.is_number() ? fmt(f, j.get<double>()) : "–"; }

const FrictionVariant& variantNamed(const std::string& name) {
  for (const FrictionVariant& v : frictionVariants()) {
    if (name == v.name) return v;
  }
  throw std::invalid_argument("unknown friction variant '" + name + "' (known: on, off, low, high, config, on_kdq0, off_kdq0)");
}

// What the controller's friction compensation was in a run, for the table.
std::string modelText(const nlohmann::ordered_json& params) {
  const std::string model = params["friction_model"].get<std::string>();
  const std::string scale = params["friction_model_scale"].get<std::string>();
  return (model == "plant" ? std::string("plant") : std::string("YAML")) + (scale == "1" ? "" : " × " + scale);
}

}  // namespace

const std::vector<FrictionVariant>& frictionVariants() {
  static const std::vector<FrictionVariant> v = {
      {"on", 1.0, "plant", 1.0, 1.0, "k_f = 1, F_c and F_v equal to the plant's"},
      {"off", 0.0, "plant", 1.0, 1.0, "k_f = 0: no friction compensation"},
      {"low", 1.0, "plant", 0.7, 1.0, "k_f = 1, F_c and F_v 30 % below the plant's"},
      {"high", 1.0, "plant", 1.3, 1.0, "k_f = 1, F_c and F_v 30 % above the plant's"},
      {"config", -1.0, "config", 1.0, 1.0, "controller.yaml as shipped (k_f = 0.8, its own F_c, F_v)"},
      {"on_kdq0", 1.0, "plant", 1.0, 0.0, "as on, without the kinematic compensation (k_q̇ = 0, eq. 8)"},
      {"off_kdq0", 0.0, "plant", 1.0, 0.0, "as off, without the kinematic compensation (k_q̇ = 0, eq. 8)"},
  };
  return v;
}

bool isFrictionVariant(const std::string& name) {
  for (const FrictionVariant& v : frictionVariants()) {
    if (name == v.name) return true;
  }
  return false;
}

ControllerOverrides controllerOverrides(const ScenarioParams& p, const PlantConfig& plant) {
  ControllerOverrides o;
  o.k_f = p.friction_compensation;
  o.plant_friction = p.friction_model == "plant";
  o.friction_model_scale = p.friction_model_scale;
  o.kinematic_compensation = p.kinematic_compensation;
  o.estimator = p.estimator;
  if (o.plant_friction) {
    for (int i = 0; i < kJoints; ++i) {
      const JointPlant& j = plant.joint(Robot::bodies[i + 1].joint);
      o.coulomb[i] = j.coulomb;
      o.viscous[i] = j.viscous;
    }
  }
  return o;
}

ScenarioParams ablationRunParams(const ScenarioParams& ablation, const std::string& base,
                                 const FrictionVariant& variant) {
  ScenarioParams p = presetScenario(base);
  p.controller = ablation.controller;
  p.noise = ablation.noise;
  p.seed = ablation.seed;
  p.substeps = ablation.substeps;
  p.perturbation = ablation.perturbation;
  p.run.rules = ablation.run.rules;
  p.friction_compensation = variant.k_f;
  p.friction_model = variant.model;
  p.friction_model_scale = variant.scale;
  p.kinematic_compensation = variant.kinematic;
  return p;
}

AblationResult runFrictionAblation(const ScenarioParams& ablation, const AblationRunner& run_one) {
  const auto wall0 = std::chrono::steady_clock::now();
  AblationResult result;
  result.passed = true;
  for (const std::string& base : ablation.ablation_params.scenarios) {
    for (const std::string& name : ablation.ablation_params.variants) {
      AblationRun r;
      r.scenario = base;
      r.variant = name;
      r.params = ablationRunParams(ablation, base, variantNamed(name));
      r.run = run_one(r.params, name);
      result.passed = result.passed && r.run.passed;
      result.runs.push_back(std::move(r));
    }
  }
  result.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

nlohmann::ordered_json ablationRecord(const ScenarioParams& ablation, const AblationResult& r) {
  nlohmann::ordered_json j = {{"scenario", ablation.name},
                              {"description", ablation.description},
                              {"controller", ablation.controller},
                              {"passed", r.passed},
                              {"ablation", true}};
  nlohmann::ordered_json variants = nlohmann::ordered_json::array();
  for (const std::string& name : ablation.ablation_params.variants) {
    const FrictionVariant& v = variantNamed(name);
    variants.push_back({{"name", v.name},
                        {"k_f", v.k_f < 0 ? nlohmann::ordered_json("config") : nlohmann::ordered_json(v.k_f)},
                        {"friction_model", v.model},
                        {"friction_model_scale", v.scale},
                        {"kinematic_compensation", v.kinematic},
                        {"meaning", v.meaning}});
  }
  j["variants"] = variants;
  nlohmann::ordered_json runs = nlohmann::ordered_json::array();
  for (const AblationRun& a : r.runs) {
    nlohmann::ordered_json rec = runRecord(a.params, a.run);
    rec["variant"] = a.variant;
    runs.push_back(rec);
  }
  j["runs"] = runs;
  j["wall_time_s"] = r.wall_time;
  nlohmann::ordered_json params = nlohmann::ordered_json::object();
  for (const auto& [k, v] : parameterValues(ablation)) params[k] = v;
  j["parameters"] = params;
  j["files"] = {{"plots", nlohmann::ordered_json::array()}};
  return j;
}

void printAblation(std::FILE* out, const nlohmann::ordered_json& j) {
  std::fprintf(out, "\n== %s (%s): %s ==\n", j["scenario"].get<std::string>().c_str(),
               j["controller"].get<std::string>().c_str(), j["passed"].get<bool>() ? "PASS" : "FAIL");
  std::fprintf(out, "  %-10s %-7s %-10s %-28s %-22s %s\n", "scenario", "variant", "result", "torque RMS (links) / max",
               "ZMP tracking RMS L/R", "max torso pitch");
  for (const auto& r : j["runs"]) {
    const std::string result =
        r["fell"].get<bool>() ? fmt("FELL %.2f s", r["fall_time"].get<double>()) : (r["passed"].get<bool>() ? "pass" : "FAIL");
    const std::string tau = fmtOr(r["torque_tracking_rms_Nm"], "%.2f") + " (" + fmtOr(r["torque_tracking_link_rms_Nm"], "%.2f") +
                            ") / " + fmtOr(r["torque_tracking_max_Nm"], "%.1f") + " N·m";
    const std::string zmp = fmtOr(r["feet"][0]["zmp_tracking_rms_mm"], "%.1f") + " / " +
                            fmtOr(r["feet"][1]["zmp_tracking_rms_mm"], "%.1f") + " mm";
    std::fprintf(out, "  %-10s %-7s %-10s %-28s %-22s %.1f deg\n", r["scenario"].get<std::string>().c_str(),
                 r["variant"].get<std::string>().c_str(), result.c_str(), tau.c_str(), zmp.c_str(),
                 r["max_torso_pitch_deg"].get<double>());
  }
  std::fprintf(out, "  wall time: %.1f s\n", j["wall_time_s"].get<double>());
  for (const auto& f : j["files"]["plots"]) std::fprintf(out, "  plot: %s\n", f.get<std::string>().c_str());
}

std::string ablationMarkdown(const nlohmann::ordered_json& j) {
  std::ostringstream s;
  s << "**" << j["scenario"].get<std::string>() << "** (" << j["controller"].get<std::string>() << "): "
    << (j["passed"].get<bool>() ? "PASS" : "FAIL") << " — every run must pass its scenario's criterion. "
    << "Torque tracking: τ_opt (eq. 6) minus the joint torque the plant delivered after its friction, "
       "RMS over ticks and joints, the same at the links (rotor inertia J_m N² q̈ also taken off), and the "
       "largest |error|; ZMP tracking: measured (F/T) minus optimized ZMP, RMS per foot.\n\n"
    << "| scenario | variant | k_f | controller F_c, F_v | k_q̇ | result | torque tracking RMS (N·m) | at the links RMS (N·m) | "
       "max (N·m) | knees RMS L / R (N·m) | ZMP tracking RMS L / R (mm) | max torso pitch (°) | min ZMP margin (mm) |\n"
    << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : j["runs"]) {
    const auto& par = r["parameters"];
    std::string result = r["passed"].get<bool>() ? "PASS" : "FAIL";
    if (r["fell"].get<bool>()) result += fmt(" (fell at %.2f s)", r["fall_time"].get<double>());
    const auto& joint = r["torque_tracking_rms_joint_Nm"];
    s << "| " << r["scenario"].get<std::string>() << " | " << r["variant"].get<std::string>() << " | "
      << (par["friction_compensation"] == "config" ? std::string("YAML (0.8)") : par["friction_compensation"].get<std::string>())
      << " | " << modelText(par) << " | " << (par["kinematic_compensation"] == "1" ? std::string("YAML") : "YAML × " + par["kinematic_compensation"].get<std::string>())
      << " | " << result << " | " << fmtOr(r["torque_tracking_rms_Nm"], "%.2f") << " | "
      << fmtOr(r["torque_tracking_link_rms_Nm"], "%.2f") << " | "
      << fmtOr(r["torque_tracking_max_Nm"], "%.1f") << " | "
      << (joint.contains("l_knee") ? fmtOr(joint["l_knee"], "%.2f") : "–") << " / "
      << (joint.contains("r_knee") ? fmtOr(joint["r_knee"], "%.2f") : "–") << " | "
      << fmtOr(r["feet"][0]["zmp_tracking_rms_mm"], "%.1f") << " / " << fmtOr(r["feet"][1]["zmp_tracking_rms_mm"], "%.1f")
      << " | " << fmt("%.1f", r["max_torso_pitch_deg"].get<double>()) << " | " << fmtOr(r["zmp_margin_mm"], "%.1f")
      << " |\n";
  }
  return s.str();
}

}  // namespace hqp::sim
