#pragma once
// loadControllerConfig<Robot>(path): reads a ControllerConfig from YAML with
// yaml-cpp, at start-up only (allocates and throws; never call it in the tick).
// Layout and the meaning of every key: robots/walker3/controller.yaml and
// docs/controller.md ("Configuration"). The reader is strict: every key must
// be present, no unknown key is accepted (a typo is an error, not a silent
// default), per-joint entries are keyed by URDF joint name and must cover every
// joint of Robot exactly once, and each value is range-checked. Any problem
// throws std::runtime_error("<file>: <what> '<key path>'...").

#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "tasks/controller_config.hpp"

namespace hqp::tasks {
namespace detail {

class ConfigReader {
 public:
  explicit ConfigReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(file_ + ": " + what);
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  // The map at path.key, with exactly the allowed keys (an empty list: any keys).
  YAML::Node map(const YAML::Node& parent, const std::string& path, const std::string& key,
                 std::initializer_list<const char*> allowed) const {
    const std::string full = join(path, key);
    const YAML::Node n = child(parent, path, key);
    if (!n.IsMap()) fail("'" + full + "' must be a map");
    onlyKeys(n, full, allowed);
    return n;
  }

  void onlyKeys(const YAML::Node& m, const std::string& path,
                std::initializer_list<const char*> allowed) const {
    for (const auto& kv : m) {
      const std::string k = kv.first.as<std::string>();
      bool ok = false;
      for (const char* a : allowed) ok = ok || k == a;
      if (!ok) fail("unknown key '" + join(path, k) + "'");
    }
  }

  YAML::Node child(const YAML::Node& parent, const std::string& path, const std::string& key) const {
    const YAML::Node n = parent[key];
    if (!n.IsDefined() || n.IsNull()) fail("missing key '" + join(path, key) + "'");
    return n;
  }

  std::string text(const YAML::Node& parent, const std::string& path, const std::string& key) const {
    const YAML::Node n = child(parent, path, key);
    if (!n.IsScalar()) fail("'" + join(path, key) + "' must be a string");
    return n.Scalar();
  }

  double number(const YAML::Node& n, const std::string& full) const {
    if (!n.IsScalar()) fail("'" + full + "' must be a number");
    double x = 0.0;
    try {
      x = n.as<double>();
    } catch (const YAML::Exception&) {
      fail("'" + full + "' must be a number, got '" + n.Scalar() + "'");
    }
    if (std::isnan(x)) fail("'" + full + "' is not a number (NaN)");
    return x;
  }

  // A finite number at path.key with lo ≤ x (strictly lo < x if strict).
  double atLeast(const YAML::Node& parent, const std::string& path, const std::string& key,
                 double lo, bool strict, bool allow_inf = false) const {
    const std::string full = join(path, key);
    const double x = number(child(parent, path, key), full);
    if (!allow_inf && !std::isfinite(x)) fail("'" + full + "' must be finite");
    if (strict ? !(x > lo) : !(x >= lo)) {
      fail("'" + full + "' = " + std::to_string(x) + " must be " + (strict ? "> " : ">= ") +
           std::to_string(lo));
    }
    return x;
  }

  // A whole number at path.key with lo ≤ n ≤ hi.
  int integer(const YAML::Node& parent, const std::string& path, const std::string& key, int lo, int hi) const {
    const std::string full = join(path, key);
    const double x = number(child(parent, path, key), full);
    if (!(x >= lo && x <= hi) || x != std::floor(x)) {
      fail("'" + full + "' = " + child(parent, path, key).Scalar() + " must be a whole number in [" +
           std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return static_cast<int>(x);
  }

  // A tolerance at path.key: finite, 0 < x < 1.
  double tolerance(const YAML::Node& parent, const std::string& path, const std::string& key) const {
    const double x = atLeast(parent, path, key, 0.0, true);
    if (!(x < 1.0)) fail("'" + join(path, key) + "' = " + std::to_string(x) + " must be < 1");
    return x;
  }

  bool boolean(const YAML::Node& parent, const std::string& path, const std::string& key) const {
    const std::string full = join(path, key);
    const YAML::Node n = child(parent, path, key);
    bool b = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, b)) fail("'" + full + "' must be true or false");
    return b;
  }

  double finite(const YAML::Node& parent, const std::string& path, const std::string& key) const {
    const std::string full = join(path, key);
    const double x = number(child(parent, path, key), full);
    if (!std::isfinite(x)) fail("'" + full + "' must be finite");
    return x;
  }

  PdGains gains(const YAML::Node& parent, const std::string& path, const std::string& key) const {
    const YAML::Node g = map(parent, path, key, {"kp", "kd"});
    const std::string p = join(path, key);
    return PdGains{atLeast(g, p, "kp", 0.0, false), atLeast(g, p, "kd", 0.0, false)};
  }

  // x_min < x_max, y_min < y_max (sole frame, m).
  void rectangle(const YAML::Node& parent, const std::string& path, const std::string& key,
                 double& x_min, double& x_max, double& y_min, double& y_max) const {
    const YAML::Node r = map(parent, path, key, {"x_min", "x_max", "y_min", "y_max"});
    const std::string p = join(path, key);
    x_min = finite(r, p, "x_min");
    x_max = finite(r, p, "x_max");
    y_min = finite(r, p, "y_min");
    y_max = finite(r, p, "y_max");
    if (!(x_min < x_max) || !(y_min < y_max)) fail("'" + p + "' needs x_min < x_max and y_min < y_max");
  }

  // Entries of a per-joint map in model joint order; every joint exactly once.
  template <class Robot>
  std::vector<YAML::Node> perJoint(const YAML::Node& parent, const std::string& path,
                                   const std::string& key) const {
    const std::string full = join(path, key);
    const YAML::Node m = child(parent, path, key);
    if (!m.IsMap()) fail("'" + full + "' must be a map keyed by joint name");
    std::vector<YAML::Node> out(static_cast<std::size_t>(Robot::nj));
    std::vector<bool> seen(static_cast<std::size_t>(Robot::nj), false);
    for (const auto& kv : m) {
      const std::string name = kv.first.as<std::string>();
      const int j = Robot::jointIndex(name);
      if (j < 0) fail("unknown joint '" + name + "' in '" + full + "' (robot " + Robot::name + ")");
      if (seen[static_cast<std::size_t>(j)]) fail("joint '" + name + "' twice in '" + full + "'");
      seen[static_cast<std::size_t>(j)] = true;
      out[static_cast<std::size_t>(j)] = kv.second;
    }
    for (int j = 0; j < Robot::nj; ++j) {
      if (!seen[static_cast<std::size_t>(j)]) fail("missing key '" + join(full, jointName<Robot>(j)) + "'");
    }
    return out;
  }

  template <class Robot>
  static const char* jointName(int j) {
    return Robot::bodies[static_cast<std::size_t>(j + (Robot::floating_base ? 1 : 0))].joint;
  }

 private:
  std::string file_;
};

}  // namespace detail

template <class Robot>
ControllerConfig<Robot::nj> loadControllerConfig(const std::string& path) {
  constexpr int nj = Robot::nj;
  const detail::ConfigReader r(path);
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    r.fail("cannot open the file");
  } catch (const YAML::Exception& e) {
    r.fail(std::string("YAML error: ") + e.what());
  }
  if (!root.IsMap()) r.fail("the top level must be a map");
  r.onlyKeys(root, "", {"controller", "balance", "planner", "estimator", "joint_control", "safe_mode", "qp"});

  ControllerConfig<nj> c;
  {
    const YAML::Node n = r.map(root, "", "controller", {"solver", "dt", "wqp_priority_ratio"});
    const std::string solver = r.text(n, "controller", "solver");
    if (solver == "hqp") {
      c.solver = ControllerConfig<nj>::Solver::Hqp;
    } else if (solver == "wqp") {
      c.solver = ControllerConfig<nj>::Solver::Wqp;
    } else {
      r.fail("'controller.solver' must be hqp or wqp, got '" + solver + "'");
    }
    c.dt = r.atLeast(n, "controller", "dt", 0.0, true);
    c.wqp_priority_ratio = r.atLeast(n, "controller", "wqp_priority_ratio", 1.0, false);
  }
  {
    const std::string p = "balance";
    const YAML::Node n = r.map(root, "", p,
                               {"foot_linear", "foot_angular", "com", "com_vertical", "torso", "mu",
                                "fz_min", "cop_region", "torque_limit", "torso_weight", "force_weight",
                                "torsion_radius", "com_integral", "com_schedule", "torso_error_limit",
                                "hip_strategy", "cop_moment_margin"});
    BalanceParameters<nj>& b = c.balance;
    b.foot_linear = r.gains(n, p, "foot_linear");
    b.foot_angular = r.gains(n, p, "foot_angular");
    b.com = r.gains(n, p, "com");
    b.com_vertical = r.gains(n, p, "com_vertical");
    if (n["com_integral"]) {  // optional, beyond the paper
      const YAML::Node g = r.map(n, p, "com_integral", {"ki", "limit", "reset_on_crossing"});
      b.com_ki = r.atLeast(g, p + ".com_integral", "ki", 0.0, false);
      b.com_integral_limit = r.atLeast(g, p + ".com_integral", "limit", 0.0, false);
      if (g["reset_on_crossing"]) b.com_integral_reset = r.boolean(g, p + ".com_integral", "reset_on_crossing");
    }
    if (n["com_schedule"]) {  // optional, beyond the paper
      const YAML::Node g = r.map(n, p, "com_schedule", {"dcm_low", "dcm_high", "kp", "kd"});
      const std::string q = p + ".com_schedule";
      b.com_dcm_low = r.atLeast(g, q, "dcm_low", 0.0, false);
      b.com_dcm_high = r.atLeast(g, q, "dcm_high", 0.0, false);
      b.com_high = PdGains{r.atLeast(g, q, "kp", 0.0, false), r.atLeast(g, q, "kd", 0.0, false)};
      if (!(b.com_dcm_high > b.com_dcm_low)) {
        r.fail("'" + q + ".dcm_high' must exceed dcm_low");
      }
    }
    if (n["hip_strategy"]) {  // optional, beyond the paper; max_tilt .inf = off
      const YAML::Node g = r.map(n, p, "hip_strategy", {"max_tilt", "stiffness", "damping"});
      const std::string q = p + ".hip_strategy";
      b.hip_max_tilt = r.atLeast(g, q, "max_tilt", 0.0, true, true);
      b.hip_stiffness = r.atLeast(g, q, "stiffness", 0.0, false);
      b.hip_damping = r.atLeast(g, q, "damping", 0.0, false);
    }
    b.torso = r.gains(n, p, "torso");
    if (n["torso_error_limit"]) b.torso_error_limit = r.atLeast(n, p, "torso_error_limit", 0.0, true, true);  // beyond the paper; .inf = off
    b.mu = r.atLeast(n, p, "mu", 0.0, true);
    b.fz_min = r.atLeast(n, p, "fz_min", 0.0, false);
    r.rectangle(n, p, "cop_region", b.sole_x_min, b.sole_x_max, b.sole_y_min, b.sole_y_max);
    if (n["cop_moment_margin"]) b.cop_moment_margin = r.atLeast(n, p, "cop_moment_margin", 0.0, false);  // beyond the paper
    b.torso_weight = r.atLeast(n, p, "torso_weight", 0.0, false);
    b.force_weight = r.atLeast(n, p, "force_weight", 0.0, false);
    b.torsion_radius = r.atLeast(n, p, "torsion_radius", 0.0, true);
    const std::vector<YAML::Node> lim = r.perJoint<Robot>(n, p, "torque_limit");
    for (int j = 0; j < nj; ++j) {
      const std::string key = r.join(p + ".torque_limit", detail::ConfigReader::jointName<Robot>(j));
      const double t = r.number(lim[static_cast<std::size_t>(j)], key);
      if (!(t > 0.0) || !std::isfinite(t)) r.fail("'" + key + "' must be finite and > 0");
      const double effort = Robot::bodies[static_cast<std::size_t>(j + (Robot::floating_base ? 1 : 0))].effort;
      if (t > effort) {
        r.fail("'" + key + "' = " + std::to_string(t) + " exceeds the URDF effort limit " +
               std::to_string(effort));
      }
      b.tau_max[j] = t;
    }
  }
  {
    const std::string p = "planner";
    const YAML::Node n = r.map(root, "", p, {"safe_margin", "com_height", "sole", "torso_yaw_offset",
                                            "follow_acceleration_cutoff", "follow_translation", "hold_tipping_axis",
                                            "com_reference_cutoff", "support_acceleration_from_estimator",
                                            "follow_acceleration_order", "follow_acceleration_deadband", "hold_one_sided"});
    PlannerParameters& pl = c.planner;
    pl.safe_margin = r.atLeast(n, p, "safe_margin", 0.0, false);
    pl.com_height = r.finite(n, p, "com_height");
    r.rectangle(n, p, "sole", pl.sole_x_min, pl.sole_x_max, pl.sole_y_min, pl.sole_y_max);
    if (!(2.0 * pl.safe_margin < pl.sole_x_max - pl.sole_x_min) ||
        !(2.0 * pl.safe_margin < pl.sole_y_max - pl.sole_y_min)) {
      r.fail("'planner.safe_margin' leaves no safe region inside 'planner.sole'");
    }
    pl.torso_yaw_offset = r.finite(n, p, "torso_yaw_offset");
    // Moving-support extensions: optional, off (the paper's rule) when absent.
    if (n["follow_acceleration_cutoff"])
      pl.follow_acceleration_cutoff = r.atLeast(n, p, "follow_acceleration_cutoff", 0.0, false);
    if (n["follow_translation"]) pl.follow_translation = r.boolean(n, p, "follow_translation");
    if (n["hold_tipping_axis"]) pl.hold_tipping_axis = r.boolean(n, p, "hold_tipping_axis");
    if (n["hold_one_sided"]) pl.hold_one_sided = r.boolean(n, p, "hold_one_sided");
    if (pl.hold_one_sided && !pl.hold_tipping_axis) r.fail("'planner.hold_one_sided' needs 'planner.hold_tipping_axis'");
    if (n["support_acceleration_from_estimator"])
      pl.support_acceleration_from_estimator = r.boolean(n, p, "support_acceleration_from_estimator");
    if (n["com_reference_cutoff"])
      pl.com_reference_cutoff = r.atLeast(n, p, "com_reference_cutoff", 0.0, false);
    if (n["follow_acceleration_order"]) {
      const double o = r.atLeast(n, p, "follow_acceleration_order", 1.0, false);
      if (!(o == 1.0 || o == 2.0)) r.fail("'planner.follow_acceleration_order' must be 1 or 2");
      pl.follow_acceleration_order = static_cast<int>(o);
    }
    if (n["follow_acceleration_deadband"]) {
      const std::string q = p + ".follow_acceleration_deadband";
      const YAML::Node d = r.map(n, p, "follow_acceleration_deadband", {"linear", "angular"});
      pl.follow_acceleration_deadband_linear = r.atLeast(d, q, "linear", 0.0, false);
      pl.follow_acceleration_deadband_angular = r.atLeast(d, q, "angular", 0.0, false);
    }
  }
  {
    const std::string p = "estimator";
    const YAML::Node n =
        r.map(root, "", p,
              {"method", "contact_threshold", "contact_on", "contact_full", "zero_velocity_gate", "stationary_velocity", "relative_velocity_gate", "gate_cutoff", "trust_delay", "motion_gate", "motion_cutoff",
               "moving_velocity", "support_acceleration_cutoff", "quaternion_tolerance", "noise"});
    EstimatorParameters& e = c.estimator;
    e.contact_threshold = r.atLeast(n, p, "contact_threshold", 0.0, true);
    // A foot the QP still loads with fz_min must register as a support (docs/controller.md).
    if (!(e.contact_threshold < c.balance.fz_min))
      r.fail("'estimator.contact_threshold' must be below 'balance.fz_min'");
    // Optional keys: absent = the stance-foot estimator without hysteresis.
    if (n["method"]) {
      const std::string m = r.text(n, p, "method");
      if (m == "stance") e.method = EstimatorParameters::Method::Stance;
      else if (m == "kinematic_inertial") e.method = EstimatorParameters::Method::KinematicInertial;
      else r.fail("'estimator.method' must be stance or kinematic_inertial, got '" + m + "'");
    }
    if (n["contact_on"]) {
      e.contact_on = r.atLeast(n, p, "contact_on", 0.0, false);
      if (!(e.contact_on < c.balance.fz_min)) r.fail("'estimator.contact_on' must be below 'balance.fz_min'");
    }
    if (n["contact_full"]) e.contact_full = r.atLeast(n, p, "contact_full", 0.0, false);
    if (n["zero_velocity_gate"]) e.zero_velocity_gate = r.atLeast(n, p, "zero_velocity_gate", 0.0, true);
    if (n["stationary_velocity"]) e.stationary_velocity = r.atLeast(n, p, "stationary_velocity", 0.0, true);
    if (n["relative_velocity_gate"])
      e.relative_velocity_gate = r.atLeast(n, p, "relative_velocity_gate", 0.0, true);
    if (n["gate_cutoff"]) e.gate_cutoff = r.atLeast(n, p, "gate_cutoff", 0.0, false);
    if (n["trust_delay"]) e.trust_delay = r.atLeast(n, p, "trust_delay", 0.0, false);
    if (n["motion_gate"]) e.motion_gate = r.atLeast(n, p, "motion_gate", 0.0, true);
    if (n["motion_cutoff"]) e.motion_cutoff = r.atLeast(n, p, "motion_cutoff", 0.0, false);
    if (n["moving_velocity"]) e.moving_velocity = r.atLeast(n, p, "moving_velocity", 0.0, true);
    if (n["support_acceleration_cutoff"])
      e.support_acceleration_cutoff = r.atLeast(n, p, "support_acceleration_cutoff", 0.0, false);
    if (n["quaternion_tolerance"]) e.quaternion_tolerance = r.atLeast(n, p, "quaternion_tolerance", 0.0, true);
    if (n["noise"]) {
      const std::string np = "estimator.noise";
      const YAML::Node nn = r.map(n, p, "noise",
                                  {"accel", "bias", "foot_stance", "foot_swing", "kinematic_position",
                                   "zero_velocity", "fallback_velocity"});
      KinematicInertialNoise& k = e.noise;
      k.accel = r.atLeast(nn, np, "accel", 0.0, true);
      k.bias = r.atLeast(nn, np, "bias", 0.0, false);
      k.foot_stance = r.atLeast(nn, np, "foot_stance", 0.0, false);
      k.foot_swing = r.atLeast(nn, np, "foot_swing", 0.0, true);
      k.kinematic_position = r.atLeast(nn, np, "kinematic_position", 0.0, true);
      k.zero_velocity = r.atLeast(nn, np, "zero_velocity", 0.0, true);
      k.fallback_velocity = r.atLeast(nn, np, "fallback_velocity", 0.0, false);
    }
  }
  {
    const std::string p = "joint_control";
    const YAML::Node n = r.map(root, "", p, {"leak_time", "joints"});
    c.joint.leak_time = r.atLeast(n, p, "leak_time", 0.0, false, /*allow_inf=*/true);
    const std::vector<YAML::Node> js = r.perJoint<Robot>(n, p, "joints");
    for (int j = 0; j < nj; ++j) {
      const std::string jp = r.join(p + ".joints", detail::ConfigReader::jointName<Robot>(j));
      const YAML::Node& e = js[static_cast<std::size_t>(j)];
      if (!e.IsMap()) r.fail("'" + jp + "' must be a map");
      r.onlyKeys(e, jp, {"torque_constant", "current_limit", "coulomb", "viscous", "dq_star", "k_f", "k_dq",
                         "leak_time"});
      c.joint.torque_constant[j] = r.atLeast(e, jp, "torque_constant", 0.0, true);
      c.joint.current_limit[j] = r.atLeast(e, jp, "current_limit", 0.0, true);
      JointFriction& f = c.joint.friction[static_cast<std::size_t>(j)];
      f.coulomb = r.atLeast(e, jp, "coulomb", 0.0, false);
      f.viscous = r.atLeast(e, jp, "viscous", 0.0, false);
      f.dq_star = r.atLeast(e, jp, "dq_star", 0.0, true);
      c.joint.k_f[j] = r.atLeast(e, jp, "k_f", 0.0, false);
      c.joint.k_dq[j] = r.atLeast(e, jp, "k_dq", 0.0, false);
      if (e["leak_time"])  // optional, beyond the paper: this joint's own leak of ∫q̈ dt
        c.joint.joint_leak_time[j] = r.atLeast(e, jp, "leak_time", 0.0, false, /*allow_inf=*/true);
    }
  }
  {
    const std::string p = "safe_mode";
    const YAML::Node n = r.map(root, "", p, {"damping", "min_base_height", "max_tilt"});
    c.safe.damping = r.atLeast(n, p, "damping", 0.0, false);
    c.safe.min_base_height = r.finite(n, p, "min_base_height");
    c.safe.max_tilt = r.atLeast(n, p, "max_tilt", 0.0, true);
  }
  if (root["qp"]) {  // optional section and keys: absent = the solvers' defaults
    const YAML::Node n = r.map(root, "", "qp", {"hqp", "wqp"});
    // The QpSettings keys of one solver, each optional.
    const auto qpKeys = [&](const YAML::Node& m, const std::string& p, QpSettings& q) {
      if (m["max_iterations"]) q.max_iterations = r.integer(m, p, "max_iterations", 1, 1000000);
      if (m["feasibility_tol"]) q.feasibility_tol = r.tolerance(m, p, "feasibility_tol");
      if (m["rank_tol"]) q.rank_tol = r.tolerance(m, p, "rank_tol");
      if (m["dual_tol"]) q.dual_tol = r.tolerance(m, p, "dual_tol");
      if (m["max_magnitude"]) {
        q.max_magnitude = r.atLeast(m, p, "max_magnitude", 0.0, true);
        // The solvers square and multiply such numbers: keep that far from overflow.
        if (q.max_magnitude > 1e100) r.fail("'" + p + ".max_magnitude' must be <= 1e100");
      }
    };
    if (n["hqp"]) {
      const std::string p = "qp.hqp";
      const YAML::Node m = r.map(n, "qp", "hqp",
                                 {"max_iterations", "feasibility_tol", "rank_tol", "dual_tol", "max_magnitude",
                                  "level_rank_tol", "warm_start", "dual_last_level", "defer_constraints",
                                  "residual_rise_tol", "budget_us", "budget_iterations", "time_levels"});
      HqpSettings& h = c.qp.hqp;
      qpKeys(m, p, h.qp);
      if (m["level_rank_tol"]) h.rank_tol = r.tolerance(m, p, "level_rank_tol");
      if (m["warm_start"]) h.warm_start = r.boolean(m, p, "warm_start");
      if (m["dual_last_level"]) h.dual_last_level = r.boolean(m, p, "dual_last_level");
      if (m["defer_constraints"]) h.defer_constraints = r.boolean(m, p, "defer_constraints");
      if (m["residual_rise_tol"]) h.residual_rise_tol = r.tolerance(m, p, "residual_rise_tol");
      // Per-tick budget of the solve; 0 = none (HqpSettings::budget_us / budget_iterations).
      if (m["budget_us"]) h.budget_us = r.atLeast(m, p, "budget_us", 0.0, false);
      if (m["budget_iterations"]) h.budget_iterations = r.integer(m, p, "budget_iterations", 0, 1000000);
      // Per-level wall time (HqpSettings::time_levels); off: no clock read unless budget_us is set.
      if (m["time_levels"]) h.time_levels = r.boolean(m, p, "time_levels");
    }
    if (n["wqp"]) {
      const std::string p = "qp.wqp";
      const YAML::Node m = r.map(n, "qp", "wqp",
                                 {"max_iterations", "feasibility_tol", "rank_tol", "dual_tol", "max_magnitude",
                                  "warm_start", "dual_method"});
      qpKeys(m, p, c.qp.wqp);
      if (m["warm_start"]) c.qp.wqp_warm_start = r.boolean(m, p, "warm_start");
      if (m["dual_method"]) c.qp.wqp_dual_method = r.boolean(m, p, "dual_method");
    }
  }
  return c;
}

}  // namespace hqp::tasks
