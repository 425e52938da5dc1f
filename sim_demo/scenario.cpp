#include "scenario.hpp"

#include "friction_ablation.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace hqp::sim {

namespace {

[[noreturn]] void badValue(const std::string& key, const std::string& value, const std::string& expected) {
  throw std::invalid_argument("parameter '" + key + "': bad value '" + value + "' (expected " + expected + ")");
}

double parseDouble(const std::string& key, const std::string& v, double lo, double hi) {
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || errno != 0 || !std::isfinite(x)) badValue(key, v, "a number");
  if (x < lo || x > hi) {
    std::ostringstream s;
    s << "a number in [" << lo << ", " << hi << "]";
    badValue(key, v, s.str());
  }
  return x;
}

long parseInt(const std::string& key, const std::string& v, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno != 0 || x < lo || x > hi) {
    badValue(key, v, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return x;
}

bool parseBool(const std::string& key, const std::string& v) {
  if (v == "true" || v == "1" || v == "yes" || v == "on") return true;
  if (v == "false" || v == "0" || v == "no" || v == "off") return false;
  badValue(key, v, "true or false");
}

std::vector<std::string> split(const std::string& v, char sep) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(v);
  while (std::getline(in, item, sep)) out.push_back(item);
  if (!v.empty() && v.back() == sep) out.emplace_back();
  return out;
}

// "none" or "T:IX:IY[:IZ],..." (s, N·s, world).
std::vector<Push> parsePushes(const std::string& key, const std::string& v) {
  std::vector<Push> pushes;
  if (v == "none" || v.empty()) return pushes;
  const char* expected = "none or TIME:IX:IY[:IZ] items separated by commas, e.g. 2:8:0,5:10:0";
  for (const std::string& item : split(v, ',')) {
    const std::vector<std::string> f = split(item, ':');
    if (f.size() != 3 && f.size() != 4) badValue(key, v, expected);
    Push p;
    p.time = parseDouble(key, f[0], 0.0, 3600.0);
    for (std::size_t i = 1; i < f.size(); ++i) p.impulse[static_cast<int>(i) - 1] = parseDouble(key, f[i], -500.0, 500.0);
    pushes.push_back(p);
  }
  return pushes;
}

std::string formatDouble(double x) {
  char b[64];
  std::snprintf(b, sizeof(b), "%.10g", x);
  return b;
}

// "none" or "AMP:FREQ:START:DURATION[:OFFSET[:PHASE]]" (m or rad, Hz, s, s, m or rad, rad).
void parseMotion(SupportMotion& m, const std::string& key, const std::string& v, double ramp) {
  const std::string axis = m.axis;
  m = SupportMotion{};
  m.axis = axis;
  m.ramp = ramp;
  if (v == "none" || v.empty()) return;
  const std::vector<std::string> f = split(v, ':');
  if (f.size() < 4 || f.size() > 6) badValue(key, v, "none or AMP:FREQ:START:DURATION[:OFFSET[:PHASE]], e.g. 0.1:1.5:1.5:4");
  m.amplitude = parseDouble(key, f[0], -1.0, 1.0);
  m.frequency = parseDouble(key, f[1], 0.0, 20.0);
  m.start = parseDouble(key, f[2], 0.0, 3600.0);
  m.duration = parseDouble(key, f[3], 0.0, 3600.0);
  if (f.size() > 4) m.offset = parseDouble(key, f[4], -1.0, 1.0);
  if (f.size() > 5) m.phase = parseDouble(key, f[5], -10.0, 10.0);
}

std::string formatMotion(const SupportMotion& m) {
  if (!m.active()) return "none";
  std::string s = formatDouble(m.amplitude) + ":" + formatDouble(m.frequency) + ":" + formatDouble(m.start) + ":" +
                  formatDouble(m.duration);
  if (m.offset != 0.0 || m.phase != 0.0) s += ":" + formatDouble(m.offset);
  if (m.phase != 0.0) s += ":" + formatDouble(m.phase);
  return s;
}

SupportMotion& motionOf(ScenarioParams& p, const std::string& axis) {
  for (SupportMotion& m : p.supports) {
    if (m.axis == axis) return m;
  }
  p.supports.push_back(SupportMotion{});
  p.supports.back().axis = axis;
  p.supports.back().ramp = p.support_ramp;
  return p.supports.back();
}

const SupportMotion* findMotion(const ScenarioParams& p, const std::string& axis) {
  for (const SupportMotion& m : p.supports) {
    if (m.axis == axis) return &m;
  }
  return nullptr;
}

std::string formatPushes(const std::vector<Push>& pushes) {
  if (pushes.empty()) return "none";
  std::string s;
  for (const Push& p : pushes) {
    if (!s.empty()) s += ",";
    s += formatDouble(p.time) + ":" + formatDouble(p.impulse.x()) + ":" + formatDouble(p.impulse.y());
    if (p.impulse.z() != 0.0) s += ":" + formatDouble(p.impulse.z());
  }
  return s;
}

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const std::string& i : items) s += (s.empty() ? "" : ",") + i;
  return s;
}

// "none" or "NAME:VALUE,..." (link or joint names with a factor or error).
std::vector<std::pair<std::string, double>> parseNamedList(const std::string& key, const std::string& v, double lo,
                                                           double hi) {
  std::vector<std::pair<std::string, double>> out;
  if (v == "none" || v.empty()) return out;
  for (const std::string& item : split(v, ',')) {
    const std::vector<std::string> f = split(item, ':');
    if (f.size() != 2 || f[0].empty()) badValue(key, v, "none or NAME:VALUE items separated by commas, e.g. torso:1.1");
    out.emplace_back(f[0], parseDouble(key, f[1], lo, hi));
  }
  return out;
}

std::string formatNamedList(const std::vector<std::pair<std::string, double>>& list) {
  if (list.empty()) return "none";
  std::string s;
  for (const auto& [name, x] : list) s += (s.empty() ? "" : ",") + name + ":" + formatDouble(x);
  return s;
}

// "0" or "FX:FY:FZ:MX:MY:MZ" (N, N·m, sensor frame).
Vector6 parseWrench(const std::string& key, const std::string& v) {
  if (v == "0" || v == "none") return Vector6::Zero();
  const std::vector<std::string> f = split(v, ':');
  if (f.size() != 6) badValue(key, v, "0 or FX:FY:FZ:MX:MY:MZ (N, N·m)");
  Vector6 w;
  for (int i = 0; i < 6; ++i) w[i] = parseDouble(key, f[static_cast<std::size_t>(i)], -1000.0, 1000.0);
  return w;
}

std::string formatWrench(const Vector6& w) {
  if (w.isZero()) return "0";
  std::string s;
  for (int i = 0; i < 6; ++i) s += (i ? ":" : "") + formatDouble(w[i]);
  return s;
}

struct Parameter {
  std::string key;
  const char* help;
  std::function<void(ScenarioParams&, const std::string& key, const std::string& value)> set;
  std::function<std::string(const ScenarioParams&)> get;
};

// Every parameter a scenario has (docs/scenarios.md lists them with the presets' values).
const std::vector<Parameter>& parameters() {
  using P = ScenarioParams;
  using S = const std::string&;
  static const std::vector<Parameter> table = {
      {"duration", "simulated time, s",
       [](P& p, S k, S v) { p.run.duration = parseDouble(k, v, 0.001, 3600.0); },
       [](const P& p) { return formatDouble(p.run.duration); }},
      {"pushes", "impulses on the torso: none or TIME:IX:IY[:IZ],... (s, N·s, world)",
       [](P& p, S k, S v) { p.run.pushes = parsePushes(k, v); },
       [](const P& p) { return formatPushes(p.run.pushes); }},
      {"push_method", "ball (the scene's 5 kg ball thrown with that momentum) or force (10 ms force at the torso CoM)",
       [](P& p, S k, S v) {
         if (v != "ball" && v != "force") badValue(k, v, "ball or force");
         p.ball = v == "ball";
       },
       [](const P& p) { return std::string(p.ball ? "ball" : "force"); }},
      {"push_duration", "force pushes: duration of the constant force, s",
       [](P& p, S k, S v) { p.push_duration = parseDouble(k, v, 0.001, 1.0); },
       [](const P& p) { return formatDouble(p.push_duration); }},
      {"controller", "hqp (strict hierarchy, the paper's) or wqp (weighted)",
       [](P& p, S k, S v) {
         if (v != "hqp" && v != "wqp") badValue(k, v, "hqp or wqp");
         p.controller = v;
       },
       [](const P& p) { return p.controller; }},
      {"noise", "sensor noise of plant.yaml on or off",
       [](P& p, S k, S v) { p.noise = parseBool(k, v); },
       [](const P& p) { return std::string(p.noise ? "true" : "false"); }},
      {"seed", "noise seed",
       [](P& p, S k, S v) { p.seed = static_cast<unsigned>(parseInt(k, v, 0, 4294967295L)); },
       [](const P& p) { return std::to_string(p.seed); }},
      {"substeps", "physics steps per 1 ms control tick",
       [](P& p, S k, S v) { p.substeps = static_cast<int>(parseInt(k, v, 1, 20)); },
       [](const P& p) { return std::to_string(p.substeps); }},
      {"fall_height", "fall when the torso frame is below this height, m",
       [](P& p, S k, S v) { p.run.fall_height = parseDouble(k, v, 0.0, 2.0); },
       [](const P& p) { return formatDouble(p.run.fall_height); }},
      {"fall_tilt", "fall when torso pitch or roll exceeds this, rad",
       [](P& p, S k, S v) { p.run.fall_tilt = parseDouble(k, v, 0.01, 3.2); },
       [](const P& p) { return formatDouble(p.run.fall_tilt); }},
      {"zmp_tolerance", "a measured ZMP further than this outside its sole fails the run, m",
       [](P& p, S k, S v) { p.run.zmp_tolerance = parseDouble(k, v, 0.0, 0.1); },
       [](const P& p) { return formatDouble(p.run.zmp_tolerance); }},
      {"video_width", "video width, pixels",
       [](P& p, S k, S v) { p.run.video_width = static_cast<int>(parseInt(k, v, 64, 1920)); },
       [](const P& p) { return std::to_string(p.run.video_width); }},
      {"video_height", "video height, pixels",
       [](P& p, S k, S v) { p.run.video_height = static_cast<int>(parseInt(k, v, 64, 1080)); },
       [](const P& p) { return std::to_string(p.run.video_height); }},
      {"video_fps", "video frame rate",
       [](P& p, S k, S v) { p.run.video_fps = static_cast<int>(parseInt(k, v, 1, 120)); },
       [](const P& p) { return std::to_string(p.run.video_fps); }},
      {"sweep_directions", "push_sweep: directions among +x,-x,+y,-y and the diagonals +x+y,+x-y,-x+y,-x-y; skate_sweep: axes among x,y,z,roll,pitch,yaw",
       [](P& p, S k, S v) {
         const char* expected = "a list of +x, -x, +y, -y, +x+y, +x-y, -x+y, -x-y (push_sweep) or x, y, z, roll, pitch, yaw (skate_sweep)";
         std::vector<std::string> d = split(v, ',');
         if (d.empty()) badValue(k, v, expected);
         for (const std::string& s : d) {
           const bool push = s == "+x" || s == "-x" || s == "+y" || s == "-y" || s == "+x+y" || s == "+x-y" ||
                             s == "-x+y" || s == "-x-y";
           const bool skate = s == "x" || s == "y" || s == "z" || s == "roll" || s == "pitch" || s == "yaw";
           if (!(push || skate)) badValue(k, v, expected);
         }
         p.sweep_params.directions = d;
       },
       [](const P& p) { return join(p.sweep_params.directions); }},
      {"sweep_min", "sweeps: lower bracket end (push: N·s; skate: fraction of the paper's peak velocity)",
       [](P& p, S k, S v) { p.sweep_params.min_impulse = parseDouble(k, v, 0.0, 500.0); },
       [](const P& p) { return formatDouble(p.sweep_params.min_impulse); }},
      {"sweep_max", "sweeps: upper bracket end (same units)",
       [](P& p, S k, S v) { p.sweep_params.max_impulse = parseDouble(k, v, 0.1, 500.0); },
       [](const P& p) { return formatDouble(p.sweep_params.max_impulse); }},
      {"sweep_resolution", "sweeps: stop when the bracket is this narrow (same units)",
       [](P& p, S k, S v) { p.sweep_params.resolution = parseDouble(k, v, 0.01, 100.0); },
       [](const P& p) { return formatDouble(p.sweep_params.resolution); }},
      {"sweep_push_time", "push_sweep: time of the push in each trial, s",
       [](P& p, S k, S v) { p.sweep_params.push_time = parseDouble(k, v, 0.0, 60.0); },
       [](const P& p) { return formatDouble(p.sweep_params.push_time); }},
      {"sweep_observe", "push_sweep: simulated time after the push, s",
       [](P& p, S k, S v) { p.sweep_params.observe = parseDouble(k, v, 0.1, 60.0); },
       [](const P& p) { return formatDouble(p.sweep_params.observe); }},
      {"sweep_required", "sweeps: pass when every direction survives this (push: N·s; skate: fraction, 1 = paper)",
       [](P& p, S k, S v) { p.sweep_params.required = parseDouble(k, v, 0.0, 500.0); },
       [](const P& p) { return formatDouble(p.sweep_params.required); }},
      {"sweep_frequency", "skate_sweep: board frequency, Hz (0: each skate_* preset's; the amplitude follows the peak velocity)",
       [](P& p, S k, S v) { p.sweep_params.frequency = parseDouble(k, v, 0.0, 20.0); },
       [](const P& p) { return formatDouble(p.sweep_params.frequency); }},
      {"friction_compensation", "controller's k_f (eq. 5) for every joint, or config (controller YAML's)",
       [](P& p, S k, S v) { p.friction_compensation = v == "config" ? -1.0 : parseDouble(k, v, 0.0, 2.0); },
       [](const P& p) { return p.friction_compensation < 0 ? std::string("config") : formatDouble(p.friction_compensation); }},
      {"friction_model", "controller's F_c, F_v (eq. 7): config (controller YAML's) or plant (plant.yaml's, the truth)",
       [](P& p, S k, S v) {
         if (v != "config" && v != "plant") badValue(k, v, "config or plant");
         p.friction_model = v;
       },
       [](const P& p) { return p.friction_model; }},
      {"friction_model_scale", "factor on the controller's F_c and F_v",
       [](P& p, S k, S v) { p.friction_model_scale = parseDouble(k, v, 0.0, 10.0); },
       [](const P& p) { return formatDouble(p.friction_model_scale); }},
      {"kinematic_compensation", "factor on the controller's k_q̇ (eq. 8; 0: no kinematic compensation)",
       [](P& p, S k, S v) { p.kinematic_compensation = parseDouble(k, v, 0.0, 10.0); },
       [](const P& p) { return formatDouble(p.kinematic_compensation); }},
      {"estimator", "controller's state estimator: config (controller YAML's), stance or kinematic_inertial",
       [](P& p, S k, S v) {
         if (v != "config" && v != "stance" && v != "kinematic_inertial")
           badValue(k, v, "config, stance or kinematic_inertial");
         p.estimator = v;
       },
       [](const P& p) { return p.estimator; }},
      {"ablation_scenarios", "friction_ablation: base scenarios (single-run presets)",
       [](P& p, S k, S v) {
         std::vector<std::string> names = split(v, ',');
         if (names.empty()) badValue(k, v, "a list of scenario names");
         for (const std::string& n : names) {
           ScenarioParams base;
           try {
             base = presetScenario(n);
           } catch (const std::invalid_argument&) {
             badValue(k, v, "a list of known scenario names");
           }
           if (base.sweep || base.ablation) badValue(k, v, "single-run scenarios");
         }
         p.ablation_params.scenarios = names;
       },
       [](const P& p) { return join(p.ablation_params.scenarios); }},
      {"ablation_variants", "friction_ablation: variants among on, off, low, high, config, on_kdq0, off_kdq0",
       [](P& p, S k, S v) {
         std::vector<std::string> names = split(v, ',');
         if (names.empty()) badValue(k, v, "a list of on, off, low, high, config, on_kdq0, off_kdq0");
         for (const std::string& n : names) {
           if (!isFrictionVariant(n)) badValue(k, v, "a list of on, off, low, high, config, on_kdq0, off_kdq0");
         }
         p.ablation_params.variants = names;
       },
       [](const P& p) { return join(p.ablation_params.variants); }},
      {"scene", "scene file next to the build's scene.xml (scene_seesaw_x.xml, scene_seesaw_y.xml, scene_skateboards.xml)",
       [](P& p, S k, S v) {
         if (v.empty() || v.find('/') != std::string::npos) badValue(k, v, "a file name such as scene_skateboards.xml");
         p.scene = v;
       },
       [](const P& p) { return p.scene; }},
      {"motion_ramp", "moving supports: raised-cosine ramp in and out of every motion, s",
       [](P& p, S k, S v) {
         p.support_ramp = parseDouble(k, v, 0.0, 60.0);
         for (SupportMotion& m : p.supports) m.ramp = p.support_ramp;
       },
       [](const P& p) { return formatDouble(p.support_ramp); }},
      {"robustness_matrix", "robustness: the matrix YAML file (default: robots/walker3/robustness.yaml)",
       [](P& p, S, S v) { p.robustness_matrix = v; },
       [](const P& p) { return p.robustness_matrix.empty() ? std::string("default") : p.robustness_matrix; }},
      // Plant perturbations (plant only; docs/scenarios.md, "Plant perturbations").
      {"payload", "plant: none or LINK:MASS:X:Y:Z, a point mass (kg) at (m) in the link's frame",
       [](P& p, S k, S v) {
         PlantPerturbation& pp = p.perturbation;
         if (v == "none" || v.empty()) {
           pp.payload_link.clear();
           pp.payload_mass = 0.0;
           pp.payload_position.setZero();
           return;
         }
         const std::vector<std::string> f = split(v, ':');
         if (f.size() != 5 || f[0].empty()) badValue(k, v, "none or LINK:MASS:X:Y:Z, e.g. torso:5:0:0:0.3");
         pp.payload_link = f[0];
         pp.payload_mass = parseDouble(k, f[1], 1e-6, 1000.0);
         for (int i = 0; i < 3; ++i) pp.payload_position[i] = parseDouble(k, f[static_cast<std::size_t>(2 + i)], -2.0, 2.0);
       },
       [](const P& p) {
         const PlantPerturbation& pp = p.perturbation;
         if (pp.payload_link.empty()) return std::string("none");
         return pp.payload_link + ":" + formatDouble(pp.payload_mass) + ":" + formatDouble(pp.payload_position.x()) + ":" +
                formatDouble(pp.payload_position.y()) + ":" + formatDouble(pp.payload_position.z());
       }},
      {"mass_scale", "plant: factor on the mass and inertia of every robot link",
       [](P& p, S k, S v) { p.perturbation.mass_scale = parseDouble(k, v, 0.1, 10.0); },
       [](const P& p) { return formatDouble(p.perturbation.mass_scale); }},
      {"link_mass_scale", "plant: none or LINK:FACTOR,... on the mass and inertia of single links (e.g. torso:1.1)",
       [](P& p, S k, S v) { p.perturbation.link_mass_scale = parseNamedList(k, v, 0.1, 10.0); },
       [](const P& p) { return formatNamedList(p.perturbation.link_mass_scale); }},
      {"sensor_latency", "plant: encoder, IMU and F/T latency at once, ticks (reads the encoder value)",
       [](P& p, S k, S v) {
         const int n = static_cast<int>(parseInt(k, v, 0, 100));
         p.perturbation.encoder_latency = p.perturbation.imu_latency = p.perturbation.ft_latency = n;
       },
       [](const P& p) { return std::to_string(p.perturbation.encoder_latency); }},
      {"encoder_latency", "plant: joint encoder latency, ticks",
       [](P& p, S k, S v) { p.perturbation.encoder_latency = static_cast<int>(parseInt(k, v, 0, 100)); },
       [](const P& p) { return std::to_string(p.perturbation.encoder_latency); }},
      {"imu_latency", "plant: IMU latency, ticks",
       [](P& p, S k, S v) { p.perturbation.imu_latency = static_cast<int>(parseInt(k, v, 0, 100)); },
       [](const P& p) { return std::to_string(p.perturbation.imu_latency); }},
      {"ft_latency", "plant: F/T sensor latency, ticks",
       [](P& p, S k, S v) { p.perturbation.ft_latency = static_cast<int>(parseInt(k, v, 0, 100)); },
       [](const P& p) { return std::to_string(p.perturbation.ft_latency); }},
      {"actuator_latency", "plant: motors apply the current commanded this many ticks ago",
       [](P& p, S k, S v) { p.perturbation.actuator_latency = static_cast<int>(parseInt(k, v, 0, 100)); },
       [](const P& p) { return std::to_string(p.perturbation.actuator_latency); }},
      {"ft_offset_left", "plant: 0 or FX:FY:FZ:MX:MY:MZ added to the left F/T reading (N, N·m, sensor frame)",
       [](P& p, S k, S v) { p.perturbation.ft_offset[0] = parseWrench(k, v); },
       [](const P& p) { return formatWrench(p.perturbation.ft_offset[0]); }},
      {"ft_offset_right", "plant: 0 or FX:FY:FZ:MX:MY:MZ added to the right F/T reading",
       [](P& p, S k, S v) { p.perturbation.ft_offset[1] = parseWrench(k, v); },
       [](const P& p) { return formatWrench(p.perturbation.ft_offset[1]); }},
      {"torque_constant_error", "plant: relative error of every motor's torque constant (0.1: 10 % stronger than modelled)",
       [](P& p, S k, S v) { p.perturbation.torque_constant_error = parseDouble(k, v, -0.9, 10.0); },
       [](const P& p) { return formatDouble(p.perturbation.torque_constant_error); }},
      {"torque_constant_error_joint", "plant: none or JOINT:ERROR,... per joint, on top (e.g. l_knee:-0.2)",
       [](P& p, S k, S v) { p.perturbation.torque_constant_error_joint = parseNamedList(k, v, -0.9, 10.0); },
       [](const P& p) { return formatNamedList(p.perturbation.torque_constant_error_joint); }},
      {"joint_friction_scale", "plant: factor on the joints' Coulomb and viscous friction (the controller's model keeps its own)",
       [](P& p, S k, S v) { p.perturbation.joint_friction_scale = parseDouble(k, v, 0.0, 10.0); },
       [](const P& p) { return formatDouble(p.perturbation.joint_friction_scale); }},
      {"ground_friction", "plant: sliding friction coefficient of every contact, or scene (the scene's, 1)",
       [](P& p, S k, S v) { p.perturbation.ground_friction = v == "scene" ? -1.0 : parseDouble(k, v, 0.0, 5.0); },
       [](const P& p) {
         return p.perturbation.ground_friction < 0 ? std::string("scene") : formatDouble(p.perturbation.ground_friction);
       }},
      {"contact", "plant: contact softness preset, default (the scene's), soft or hard",
       [](P& p, S k, S v) {
         if (v != "default" && v != "soft" && v != "hard") badValue(k, v, "default, soft or hard");
         p.perturbation.contact = v;
       },
       [](const P& p) { return p.perturbation.contact; }},
      // Pass rules (docs/scenarios.md, "Pass rules").
      {"rule_foot_tilt_angle", "pass rule: a loaded sole tilted more than this from its support counts as tilted, deg",
       [](P& p, S k, S v) { p.run.rules.foot_tilt_angle = parseDouble(k, v, 0.0, 90.0) * M_PI / 180.0; },
       [](const P& p) { return formatDouble(p.run.rules.foot_tilt_angle * 180.0 / M_PI); }},
      {"rule_foot_tilt_time", "pass rule: tilted time per foot that fails the run, s",
       [](P& p, S k, S v) { p.run.rules.foot_tilt_time = parseDouble(k, v, 0.0, 3600.0); },
       [](const P& p) { return formatDouble(p.run.rules.foot_tilt_time); }},
      {"rule_sole_slide", "pass rule: a loaded sole moving further than this on its support fails the run, m",
       [](P& p, S k, S v) { p.run.rules.sole_slide = parseDouble(k, v, 0.0, 10.0); },
       [](const P& p) { return formatDouble(p.run.rules.sole_slide); }},
      {"rule_feet_touch_time", "pass rule: time the two soles may touch each other, s",
       [](P& p, S k, S v) { p.run.rules.feet_touch_time = parseDouble(k, v, 0.0, 3600.0); },
       [](const P& p) { return formatDouble(p.run.rules.feet_touch_time); }},
      {"rule_non_optimal_ticks", "pass rule: ticks with a hierarchy level not Optimal that the run may have",
       [](P& p, S k, S v) { p.run.rules.non_optimal_ticks = parseInt(k, v, 0, 100000000); },
       [](const P& p) { return std::to_string(p.run.rules.non_optimal_ticks); }},
      {"rule_com_return",
       "pass rule: on still ground, the CoM before each later push and at the end within this of where it "
       "was before the first push, m (inf: off)",
       [](P& p, S k, S v) {
         p.run.rules.com_return = v == "inf" ? std::numeric_limits<double>::infinity() : parseDouble(k, v, 0.0, 1.0);
       },
       [](const P& p) { return formatDouble(p.run.rules.com_return); }},
      {"rule_safe_mode_ticks", "pass rule: ticks in the controller's safe mode that the run may have",
       [](P& p, S k, S v) { p.run.rules.safe_mode_ticks = parseInt(k, v, 0, 100000000); },
       [](const P& p) { return std::to_string(p.run.rules.safe_mode_ticks); }},
  };
  static const std::vector<Parameter> with_motions = [] {
    std::vector<Parameter> t = table;
    // One key per support servo: motion_seesaw, motion_r_board_x, ... (the scene must have it).
    for (const std::string& axis : supportAxes()) {
      t.push_back({"motion_" + axis,
                   "servo target: none or AMP:FREQ:START:DURATION[:OFFSET[:PHASE]] (m or rad, Hz, s, s, m or rad, rad)",
                   [axis](P& p, S k, S v) { parseMotion(motionOf(p, axis), k, v, p.support_ramp); },
                   [axis](const P& p) {
                     const SupportMotion* m = findMotion(p, axis);
                     return m ? formatMotion(*m) : std::string("none");
                   }});
    }
    return t;
  }();
  return with_motions;
}

std::vector<Push> series(double first, double spacing, const std::vector<double>& magnitudes,
                         const Eigen::Vector3d& direction) {
  std::vector<Push> pushes;
  for (std::size_t i = 0; i < magnitudes.size(); ++i) {
    Push p;
    p.time = first + spacing * static_cast<double>(i);
    p.impulse = magnitudes[i] * direction;
    pushes.push_back(p);
  }
  return pushes;
}

}  // namespace

std::vector<std::string> scenarioNames() {
  return {"stand",      "push_x",     "push_y",      "push_sweep", "friction_ablation", "seesaw_x",    "seesaw_y",
          "skate_x",    "skate_y",    "skate_z",     "skate_roll", "skate_pitch", "skate_yaw",
          "skate_mixed", "skate_sweep", "robustness"};
}

const std::vector<std::string>& supportAxes() {
  static const std::vector<std::string> axes = {
      "seesaw",    "r_board_x", "r_board_y", "r_board_z", "r_board_roll", "r_board_pitch", "r_board_yaw",
      "l_board_x", "l_board_y", "l_board_z", "l_board_roll", "l_board_pitch", "l_board_yaw"};
  return axes;
}

double paperSkatePeak(const std::string& axis) {
  // Section VI-C: 0.94, 0.89, 0.47 m/s along X, Y, Z; 1.8, 1.4, 0.5 rad/s about X, Y, Z.
  if (axis == "x") return 0.94;
  if (axis == "y") return 0.89;
  if (axis == "z") return 0.47;
  if (axis == "roll") return 1.8;
  if (axis == "pitch") return 1.4;
  if (axis == "yaw") return 0.5;
  throw std::invalid_argument("skate axis '" + axis + "' (expected x, y, z, roll, pitch or yaw)");
}

std::string scenePath(const ScenarioParams& p, const std::string& default_scene) {
  if (p.scene.empty() || p.scene == "scene.xml") return default_scene;
  return (std::filesystem::path(default_scene).parent_path() / p.scene).string();
}

ScenarioParams presetScenario(const std::string& name) {
  ScenarioParams p;
  p.name = name;
  // The first push waits 2 s: the controller settles its references during the first second.
  constexpr double kFirst = 2.0, kSpacing = 3.0, kAfter = 3.0;
  if (name == "stand") {
    p.description = "10 s of quiet standing";
    p.run.duration = 10.0;
  } else if (name == "push_x") {
    p.description = "eight impulses along +X at the torso, 3 s apart (Table II: 8, 10, 11, 12 x5 N·s)";
    p.run.pushes = series(kFirst, kSpacing, {8, 10, 11, 12, 12, 12, 12, 12}, Eigen::Vector3d::UnitX());
    p.run.duration = p.run.pushes.back().time + kAfter;
  } else if (name == "push_y") {
    p.description = "seven impulses along +Y at the torso, 3 s apart (8, 10, 11, 12 x4 N·s)";
    p.run.pushes = series(kFirst, kSpacing, {8, 10, 11, 12, 12, 12, 12}, Eigen::Vector3d::UnitY());
    p.run.duration = p.run.pushes.back().time + kAfter;
  } else if (name == "seesaw_x" || name == "seesaw_y") {
    // Section VI-B: a hinged board driven by its servo, +-6 deg; the frequency gives the paper's
    // peak foot angular velocity with 2 % to spare (0.6 rad/s about X, 1.0 rad/s about Y).
    const bool x = name == "seesaw_x";
    p.description = std::string("seesaw about ") + (x ? "X" : "Y") + ": +-6 deg sinusoid, peak " +
                    (x ? "0.61" : "1.02") + " rad/s, from 1.5 s for 6 s";
    p.scene = x ? "scene_seesaw_x.xml" : "scene_seesaw_y.xml";
    SupportMotion& m = motionOf(p, "seesaw");
    m.amplitude = 6.0 * M_PI / 180.0;
    m.frequency = (x ? 0.6 : 1.0) * 1.02 / (2.0 * M_PI * m.amplitude);
    m.start = 1.5;
    m.duration = 6.0;
    p.run.duration = m.start + m.duration + 1.5;
  } else if (name.rfind("skate_", 0) == 0 && name != "skate_mixed" && name != "skate_sweep") {
    // Section VI-C: the right board moves along one axis, the left one is locked. Amplitude and
    // frequency give the paper's peak foot velocity with 2 % to spare (the metric is the
    // measured foot velocity). Y is offset outwards, so that a hand-sized motion fits: the soles
    // are only 8 cm apart, and a 4.5 cm amplitude needed 3.2 Hz (18 m/s² at the board).
    const std::string axis = name.substr(6);
    p.scene = "scene_skateboards.xml";
    SupportMotion& m = motionOf(p, "r_board_" + axis);
    const double peak = 1.02 * paperSkatePeak(axis);
    if (axis == "x") m.amplitude = 0.10;
    else if (axis == "y") { m.amplitude = 0.083; m.offset = -0.05; }  // 1.7 Hz, 9.5 m/s²
    else if (axis == "z") { m.amplitude = 0.04; m.offset = 0.01; }
    else m.amplitude = 0.15;  // rad, the three rotations
    m.frequency = peak / (2.0 * M_PI * m.amplitude);
    m.start = 1.5;
    m.duration = 4.0;
    char d[200];
    std::snprintf(d, sizeof(d), "right skateboard along %s: amplitude %g %s at %.2f Hz (peak %.2f %s, %.1f %s), left locked",
                  axis.c_str(), m.amplitude, axis.size() == 1 ? "m" : "rad", m.frequency, peak,
                  axis.size() == 1 ? "m/s" : "rad/s", m.peakAcceleration(), axis.size() == 1 ? "m/s²" : "rad/s²");
    p.description = d;
    p.run.duration = m.start + m.duration + 1.5;
  } else if (name == "skate_mixed") {
    // Both boards inclined differently and translating back and forth out of phase, with 8 N·s
    // pushes along +Y and -Y while they move.
    // 0.1 m at 0.8 Hz: 0.50 m/s peak per board, 1 m/s between them (0.15 m falls after the
    // second push; docs/scenarios.md).
    p.description = "both skateboards inclined (left pitch +3 deg, right roll -3 deg), X out of phase "
                    "(0.1 m, 0.8 Hz), 8 N·s pushes along +Y at 4 s and -Y at 7 s";
    p.scene = "scene_skateboards.xml";
    const double incl = 3.0 * M_PI / 180.0;
    for (const char* side : {"l", "r"}) {
      SupportMotion& m = motionOf(p, std::string(side) + "_board_x");
      m.amplitude = 0.1;
      m.frequency = 0.8;
      m.start = 1.5;
      m.duration = 8.0;
      m.phase = side[0] == 'l' ? 0.0 : M_PI;
      SupportMotion& t = motionOf(p, std::string(side) + "_board_" + (side[0] == 'l' ? "pitch" : "roll"));
      t.offset = side[0] == 'l' ? incl : -incl;
      t.frequency = 0.0;
      t.start = 1.0;
      t.duration = 9.0;
      t.ramp = 1.0;
    }
    p.run.pushes = series(4.0, 3.0, {8}, Eigen::Vector3d::UnitY());
    p.run.pushes.push_back(p.run.pushes.back());
    p.run.pushes.back().time = 7.0;
    p.run.pushes.back().impulse = Eigen::Vector3d(0.0, -8.0, 0.0);
    p.run.duration = 11.0;
  } else if (name == "skate_sweep") {
    p.description = "largest right-board velocity survived along x, y, z, roll, pitch, yaw (bisection on the skate_* amplitude)";
    p.sweep = true;
    p.scene = "scene_skateboards.xml";
    p.sweep_params.skate = true;
    p.sweep_params.directions = {"x", "y", "z", "roll", "pitch", "yaw"};
    p.sweep_params.min_impulse = 0.1;
    p.sweep_params.max_impulse = 2.5;
    p.sweep_params.resolution = 0.05;
    p.sweep_params.required = 1.0;
    p.run.duration = 7.0;
  } else if (name == "push_sweep") {
    p.description = "largest single impulse survived along +X, -X, +Y, -Y (bisection)";
    p.sweep = true;
    p.run.duration = p.sweep_params.push_time + p.sweep_params.observe;
  } else if (name == "robustness") {
    p.description = "experiments x plant perturbations x controllers x noise seeds, pass rates and margins (--jobs N)";
    p.robustness = true;
  } else if (name == "friction_ablation") {
    p.description = "base scenarios x joint friction compensation on / off / model 30 % low / high (Sec. V-A)";
    p.ablation = true;
  } else {
    std::string known;
    for (const std::string& n : scenarioNames()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown scenario '" + name + "' (known: " + known + ")");
  }
  return p;
}

void setParameter(ScenarioParams& p, const std::string& key, const std::string& value) {
  for (const Parameter& par : parameters()) {
    if (key == par.key) {
      par.set(p, key, value);
      return;
    }
  }
  std::string keys;
  for (const Parameter& par : parameters()) keys += (keys.empty() ? "" : ", ") + std::string(par.key);
  throw std::invalid_argument("unknown parameter '" + key + "' (known: " + keys + ")");
}

void applyAssignment(ScenarioParams& p, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw std::invalid_argument("--set '" + assignment + "': expected key=value");
  }
  setParameter(p, assignment.substr(0, eq), assignment.substr(eq + 1));
}

void applyParameterFile(ScenarioParams& p, const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(yaml_path + ": " + e.what());
  }
  if (!root.IsMap()) throw std::invalid_argument(yaml_path + ": expected a map of parameter: value");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    std::string text;
    // A sequence is a list value: items joined by ',', an item that is itself a sequence
    // (a push [t, ix, iy]) by ':'.
    if (v.IsSequence()) {
      for (const auto& item : v) {
        std::string t;
        if (item.IsSequence()) {
          for (const auto& x : item) t += (t.empty() ? "" : ":") + x.as<std::string>();
        } else if (item.IsScalar()) {
          t = item.as<std::string>();
        } else {
          throw std::invalid_argument(yaml_path + ": parameter '" + key + "': unsupported value");
        }
        text += (text.empty() ? "" : ",") + t;
      }
      if (text.empty()) text = "none";
    } else if (v.IsScalar()) {
      text = v.as<std::string>();
    } else {
      throw std::invalid_argument(yaml_path + ": parameter '" + key + "': expected a value or a list");
    }
    try {
      setParameter(p, key, text);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(yaml_path + ": " + e.what());
    }
  }
}

RunOptions runOptions(const ScenarioParams& p) {
  RunOptions o = p.run;
  o.scenario = p.name;
  for (Push& push : o.pushes) {
    push.ball = p.ball;
    push.duration = p.push_duration;
  }
  o.supports.clear();
  for (const SupportMotion& m : p.supports) {
    if (!m.active()) continue;
    o.supports.push_back(m);
  }
  return o;
}

std::vector<std::pair<std::string, std::string>> parameterValues(const ScenarioParams& p) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Parameter& par : parameters()) out.emplace_back(par.key, par.get(p));
  return out;
}

std::vector<std::pair<std::string, std::string>> parameterHelp() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Parameter& par : parameters()) out.emplace_back(par.key, par.help);
  return out;
}

}  // namespace hqp::sim
