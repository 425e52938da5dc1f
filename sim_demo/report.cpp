#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "hqp/qp_status.hpp"

namespace hqp::sim {

namespace {

constexpr double kDeg = 180.0 / M_PI;
constexpr const char* kFoot[kContacts] = {"left", "right"};

// NaN/inf become null (JSON has no NaN).
nlohmann::ordered_json num(double x) { return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(nullptr); }

nlohmann::ordered_json parametersJson(const ScenarioParams& p) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& [k, v] : parameterValues(p)) j[k] = v;
  return j;
}

std::string fmt(const char* f, double x) {
  char b[64];
  std::snprintf(b, sizeof(b), f, x);
  return b;
}

std::string fmtOr(const nlohmann::ordered_json& j, const char* f, const char* missing = "–") {
  return j.is_number() ? fmt(f, j.get<double>()) : std::string(missing);
}

// What every record starts with: the scenario, its controller and its verdict.
nlohmann::ordered_json recordHeader(const ScenarioParams& p, bool passed) {
  return {{"scenario", p.name}, {"description", p.description}, {"controller", p.controller}, {"passed", passed}};
}

}  // namespace

nlohmann::ordered_json runRecord(const ScenarioParams& p, const RunSummary& r) {
  nlohmann::ordered_json j = recordHeader(p, r.passed);
  j["driver"] = r.driver;
  j["fell"] = r.fell;
  j["fall_time"] = r.fell ? nlohmann::ordered_json(r.fall_time) : nlohmann::ordered_json(nullptr);
  j["fall_reason"] = r.fall_reason;
  j["duration_s"] = r.duration;
  j["max_torso_pitch_deg"] = r.max_abs_pitch * kDeg;
  j["max_torso_roll_deg"] = r.max_abs_roll * kDeg;
  j["min_torso_height_m"] = r.min_torso_height;
  j["com_x_min_mm"] = r.com_x_min * 1e3;
  j["com_x_max_mm"] = r.com_x_max * 1e3;
  // The CoM's return between pushes (PassRules::com_return); null where it is not measured.
  if (std::isfinite(r.com_return)) j["com_return_mm"] = r.com_return * 1e3;
  else j["com_return_mm"] = nullptr;
  j["com_y_min_mm"] = r.com_y_min * 1e3;
  j["com_y_max_mm"] = r.com_y_max * 1e3;
  j["max_foot_pitch_deg"] = r.max_abs_foot_pitch[1] * kDeg;  // the right foot, as in the paper's Fig. 8(a)
  j["zmp_inside"] = r.zmp_inside;
  double margin = std::numeric_limits<double>::infinity();
  for (int c = 0; c < kContacts; ++c) {
    if (std::isfinite(r.zmp_margin[c])) margin = std::min(margin, r.zmp_margin[c]);
  }
  j["zmp_margin_mm"] = num(margin * 1e3);
  nlohmann::ordered_json feet = nlohmann::ordered_json::array();
  for (int c = 0; c < kContacts; ++c) {
    feet.push_back({{"foot", kFoot[c]},
                    {"max_pitch_deg", r.max_abs_foot_pitch[c] * kDeg},
                    {"max_roll_deg", r.max_abs_foot_roll[c] * kDeg},
                    {"zmp_margin_mm", num(r.zmp_margin[c] * 1e3)},
                    {"zmp_edge_time_s", r.zmp_edge_time[c]},
                    {"zmp_x_range_mm", {num(r.cop_min[c].x() * 1e3), num(r.cop_max[c].x() * 1e3)}},
                    {"zmp_y_range_mm", {num(r.cop_min[c].y() * 1e3), num(r.cop_max[c].y() * 1e3)}},
                    {"zmp_tracking_rms_mm", num(r.zmp_tracking_rms[c] * 1e3)}});
  }
  j["feet"] = feet;
  j["torque_tracking_rms_Nm"] = num(r.torque_tracking_rms);
  j["torque_tracking_max_Nm"] = num(r.torque_tracking_max);
  j["torque_tracking_link_rms_Nm"] = num(r.torque_tracking_link_rms);
  nlohmann::ordered_json tau_joint = nlohmann::ordered_json::object();
  for (int i = 0; i < kJoints; ++i) tau_joint[Robot::bodies[i + 1].joint] = num(r.torque_tracking_rms_joint[i]);
  j["torque_tracking_rms_joint_Nm"] = tau_joint;
  // Moving supports: the right foot's peak velocity (MuJoCo ground truth, low-passed at 20 Hz)
  // and orientation change, the paper's Fig. 11 and 14 figures.
  const RunOptions ro = runOptions(p);
  if (!ro.supports.empty()) {
    nlohmann::ordered_json sup = nlohmann::ordered_json::array();
    for (const SupportMotion& m : ro.supports) {
      sup.push_back({{"axis", m.axis}, {"amplitude", m.amplitude}, {"offset", m.offset}, {"frequency_hz", m.frequency},
                     {"peak_velocity", m.peakVelocity()}, {"peak_acceleration", m.peakAcceleration()}, {"start_s", m.start}, {"duration_s", m.duration}});
    }
    j["supports"] = sup;
    const Eigen::Vector3d& w = r.foot_angular_velocity_peak[1];
    const Eigen::Vector3d& v = r.foot_linear_velocity_peak[1];
    j["right_foot_peak_angular_velocity_rad_s"] = {w.x(), w.y(), w.z()};
    j["right_foot_peak_velocity_m_s"] = {v.x(), v.y(), v.z()};
    j["right_foot_max_roll_pitch_yaw_deg"] = {r.max_abs_foot_roll[1] * kDeg, r.max_abs_foot_pitch[1] * kDeg,
                                              r.max_abs_foot_yaw[1] * kDeg};
    const Eigen::Vector3d& wl = r.foot_angular_velocity_peak[0];
    const Eigen::Vector3d& vl = r.foot_linear_velocity_peak[0];
    j["left_foot_peak_angular_velocity_rad_s"] = {wl.x(), wl.y(), wl.z()};
    j["left_foot_peak_velocity_m_s"] = {vl.x(), vl.y(), vl.z()};
  }
  j["lowest_level_error_max"] = r.lowest_level_error_max;
  j["lowest_level_error_mean"] = r.lowest_level_error_mean;
  nlohmann::ordered_json levels = nlohmann::ordered_json::array();
  for (int l = 0; l < r.num_levels; ++l) {
    nlohmann::ordered_json c;
    for (int s = 0; s < RunSummary::kStatuses; ++s) c[toString(static_cast<QpStatus>(s))] = r.level_status_counts[l][s];
    levels.push_back(c);
  }
  j["level_status_counts"] = levels;
  j["safe_mode_ticks"] = r.safe_mode_ticks;
  j["non_optimal_ticks"] = r.non_optimal_ticks;
  nlohmann::ordered_json rules = nlohmann::ordered_json::array();
  for (const RuleResult& x : r.rules) {
    rules.push_back({{"rule", x.name}, {"value", x.value}, {"threshold", x.threshold}, {"unit", x.unit}, {"passed", x.passed}});
  }
  j["rules"] = rules;
  j["foot_contact"] = nlohmann::ordered_json::array();
  for (int c = 0; c < kContacts; ++c) {
    j["foot_contact"].push_back({{"foot", kFoot[c]},
                                 {"tilt_time_s", r.foot_tilt_time[c]},
                                 {"max_tilt_deg", r.max_foot_tilt[c] * kDeg},
                                 {"slide_mm", r.sole_slide[c] * 1e3}});
  }
  if (r.estimator.available) {
    const auto& a = r.estimator;
    auto stat = [](const ErrorStats& e, double scale) {
      return nlohmann::ordered_json{{"rms", num(e.rms * scale)}, {"max", e.n > 0 ? num(e.max * scale) : num(NAN)}};
    };
    j["estimator_error"] = {{"base_position_mm", stat(a.base_position, 1e3)},
                            {"base_velocity_mm_s", stat(a.base_velocity, 1e3)},
                            {"orientation_deg", stat(a.orientation, kDeg)},
                            {"com_mm", stat(a.com, 1e3)},
                            {"com_velocity_mm_s", stat(a.com_velocity, 1e3)},
                            {"support_velocity_mm_s", stat(a.support_velocity, 1e3)}};
  }
  j["feet_touch_s"] = r.feet_touch_ticks * 1e-3;
  j["tick_mean_us"] = r.tick_mean_us;
  j["tick_max_us"] = r.tick_max_us;
  j["tick_p999_us"] = r.tick_p999_us;
  j["real_time_factor"] = r.real_time_factor;
  j["wall_time_s"] = r.wall_time;
  nlohmann::ordered_json pushes = nlohmann::ordered_json::array();
  for (const Push& push : runOptions(p).pushes) {
    pushes.push_back({{"time", push.time},
                      {"impulse", {push.impulse.x(), push.impulse.y(), push.impulse.z()}},
                      {"method", push.ball ? "ball" : "force"}});
  }
  j["pushes"] = pushes;
  j["ball_impulse_delivered"] = {r.ball_impulse.x(), r.ball_impulse.y(), r.ball_impulse.z()};
  j["parameters"] = parametersJson(p);
  j["files"] = {{"csv", r.csv_path}, {"video", r.video_path}, {"plots", nlohmann::ordered_json::array()}};
  return j;
}

nlohmann::ordered_json sweepRecord(const ScenarioParams& p, const SweepResult& s) {
  nlohmann::ordered_json j = recordHeader(p, s.passed);
  j["required_impulse"] = p.sweep_params.required;
  if (p.sweep_params.skate && p.sweep_params.frequency > 0) j["frequency_hz"] = p.sweep_params.frequency;
  j["wall_time_s"] = s.wall_time;
  nlohmann::ordered_json dirs = nlohmann::ordered_json::array();
  double tick_max = 0, tick_p999 = 0;
  for (const SweepDirection& d : s.directions) {
    nlohmann::ordered_json trials = nlohmann::ordered_json::array();
    for (const SweepTrial& t : d.trials) {
      trials.push_back({{"value", t.impulse},
                        {"passed", t.run.passed},
                        {"fall_reason", t.run.fall_reason},
                        {"max_torso_pitch_deg", t.run.max_abs_pitch * kDeg},
                        {"max_torso_roll_deg", t.run.max_abs_roll * kDeg},
                        {"ball_impulse_delivered",
                         {t.run.ball_impulse.x(), t.run.ball_impulse.y(), t.run.ball_impulse.z()}}});
      tick_max = std::max(tick_max, t.run.tick_max_us);
      tick_p999 = std::max(tick_p999, t.run.tick_p999_us);
    }
    dirs.push_back({{"direction", d.direction},
                    {"unit", d.unit},
                    {"required", d.required},
                    {"largest_passed", d.largest_passed},
                    {"smallest_failed", num(d.smallest_failed > 0 ? d.smallest_failed : NAN)},
                    {"trials", trials}});
  }
  j["directions"] = dirs;
  j["tick_max_us"] = tick_max;
  j["tick_p999_us_worst_trial"] = tick_p999;
  j["parameters"] = parametersJson(p);
  return j;
}

void printRecord(std::FILE* out, const nlohmann::ordered_json& j) {
  const std::string name = j.value("scenario", "?");
  std::fprintf(out, "\n== %s (%s): %s ==\n", name.c_str(), j.value("controller", "").c_str(),
               j.value("passed", false) ? "PASS" : "FAIL");
  if (j.contains("directions")) {
    for (const auto& d : j["directions"]) {
      const std::string unit = d["unit"].get<std::string>();
      std::fprintf(out, "  largest %s survived along %s : %s %s (next failure at %s %s, %zu trials; required %s)\n",
                   unit == "N·s" ? "impulse" : "peak velocity", d["direction"].get<std::string>().c_str(),
                   fmt("%.2f", d["largest_passed"].get<double>()).c_str(), unit.c_str(),
                   fmtOr(d["smallest_failed"], "%.2f", "none up to the bracket end").c_str(), unit.c_str(),
                   d["trials"].size(), fmt("%.2f", d["required"].get<double>()).c_str());
    }
    std::fprintf(out, "  wall time                         : %.1f s\n", j["wall_time_s"].get<double>());
    return;
  }
  if (j["fell"].get<bool>()) {
    std::fprintf(out, "  result             : FELL at t = %.3f s (%s)\n", j["fall_time"].get<double>(),
                 j["fall_reason"].get<std::string>().c_str());
  } else {
    std::fprintf(out, "  result             : standing after %.2f s (no fall)\n", j["duration_s"].get<double>());
  }
  std::fprintf(out, "  max torso pitch    : %.2f deg (paper, push_x: 25.7)\n", j["max_torso_pitch_deg"].get<double>());
  std::fprintf(out, "  max torso roll     : %.2f deg\n", j["max_torso_roll_deg"].get<double>());
  std::fprintf(out, "  CoM x excursion    : %+.1f .. %+.1f mm (paper, push_x: -29 .. +56)\n",
               j["com_x_min_mm"].get<double>(), j["com_x_max_mm"].get<double>());
  std::fprintf(out, "  CoM y excursion    : %+.1f .. %+.1f mm\n", j["com_y_min_mm"].get<double>(),
               j["com_y_max_mm"].get<double>());
  for (const auto& f : j["feet"]) {
    std::fprintf(out, "  %-5s foot         : pitch %.2f deg, roll %.2f deg; ZMP x %s .. %s mm, y %s .. %s mm, margin %s mm, "
                      "%.3f s on the edge, measured-optimized RMS %s mm\n",
                 f["foot"].get<std::string>().c_str(), f["max_pitch_deg"].get<double>(), f["max_roll_deg"].get<double>(),
                 fmtOr(f["zmp_x_range_mm"][0], "%+.1f").c_str(), fmtOr(f["zmp_x_range_mm"][1], "%+.1f").c_str(),
                 fmtOr(f["zmp_y_range_mm"][0], "%+.1f").c_str(), fmtOr(f["zmp_y_range_mm"][1], "%+.1f").c_str(),
                 fmtOr(f["zmp_margin_mm"], "%.1f").c_str(), f["zmp_edge_time_s"].get<double>(),
                 fmtOr(f["zmp_tracking_rms_mm"], "%.1f").c_str());
  }
  std::fprintf(out, "  ZMPs inside soles  : %s\n", j["zmp_inside"].get<bool>() ? "yes" : "NO");
  if (j["torque_tracking_rms_Nm"].is_number()) {
    std::fprintf(out, "  torque tracking    : RMS %.2f N·m, max %.1f N·m (tau_opt - torque delivered after the joint friction); "
                      "RMS %.2f N·m at the links (rotor inertia off too)\n",
                 j["torque_tracking_rms_Nm"].get<double>(), j["torque_tracking_max_Nm"].get<double>(),
                 j["torque_tracking_link_rms_Nm"].get<double>());
  }
  if (j.contains("supports")) {
    for (const auto& m : j["supports"]) {
      std::fprintf(out, "  support servo      : %s amplitude %.4g, offset %.4g, %.3g Hz, commanded peak %.3f, peak acceleration %.1f\n",
                   m["axis"].get<std::string>().c_str(), m["amplitude"].get<double>(), m["offset"].get<double>(),
                   m["frequency_hz"].get<double>(), m["peak_velocity"].get<double>(), m["peak_acceleration"].get<double>());
    }
    const auto& v = j["right_foot_peak_velocity_m_s"];
    const auto& w = j["right_foot_peak_angular_velocity_rad_s"];
    const auto& a = j["right_foot_max_roll_pitch_yaw_deg"];
    std::fprintf(out, "  right foot (20 Hz) : peak |v| x %.3f, y %.3f, z %.3f m/s; |w| x %.3f, y %.3f, z %.3f rad/s; "
                      "max roll %.2f, pitch %.2f, yaw %.2f deg\n",
                 v[0].get<double>(), v[1].get<double>(), v[2].get<double>(), w[0].get<double>(), w[1].get<double>(),
                 w[2].get<double>(), a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
  }
  if (!j["level_status_counts"].empty()) {
    std::fprintf(out, "  QP status per level:");
    int l = 1;
    for (const auto& c : j["level_status_counts"]) {
      std::fprintf(out, " L%d %ld opt", l++, c["Optimal"].get<long>());
      const long bad = c["Infeasible"].get<long>() + c["IterationLimit"].get<long>() + c["NumericalFailure"].get<long>() +
                       c["InvalidInput"].get<long>();
      if (bad > 0) {
        std::fprintf(out, " (%ld infeasible, %ld iteration limit, %ld numerical)", c["Infeasible"].get<long>(),
                     c["IterationLimit"].get<long>(), c["NumericalFailure"].get<long>());
        if (c["InvalidInput"].get<long>() > 0) std::fprintf(out, " (%ld invalid input)", c["InvalidInput"].get<long>());
      }
      std::fprintf(out, ";");
    }
    std::fprintf(out, "\n  lowest-level error : max %.3g, mean %.3g (||A x - b||^2)\n",
                 j["lowest_level_error_max"].get<double>(), j["lowest_level_error_mean"].get<double>());
  }
  if (j.contains("estimator_error")) {
    const auto& e = j["estimator_error"];
    std::fprintf(out, "  estimator error    : RMS / max: base position %s / %s mm, base velocity %s / %s mm/s, "
                      "orientation %s / %s deg, CoM %s / %s mm, CoM velocity %s / %s mm/s, support velocity %s / %s mm/s\n",
                 fmtOr(e["base_position_mm"]["rms"], "%.1f").c_str(), fmtOr(e["base_position_mm"]["max"], "%.1f").c_str(),
                 fmtOr(e["base_velocity_mm_s"]["rms"], "%.1f").c_str(), fmtOr(e["base_velocity_mm_s"]["max"], "%.1f").c_str(),
                 fmtOr(e["orientation_deg"]["rms"], "%.2f").c_str(), fmtOr(e["orientation_deg"]["max"], "%.2f").c_str(),
                 fmtOr(e["com_mm"]["rms"], "%.1f").c_str(), fmtOr(e["com_mm"]["max"], "%.1f").c_str(),
                 fmtOr(e["com_velocity_mm_s"]["rms"], "%.1f").c_str(), fmtOr(e["com_velocity_mm_s"]["max"], "%.1f").c_str(),
                 fmtOr(e["support_velocity_mm_s"]["rms"], "%.1f").c_str(),
                 fmtOr(e["support_velocity_mm_s"]["max"], "%.1f").c_str());
  }
  std::fprintf(out, "  controller time    : mean %.1f us, max %.1f us, 99.9%% %.1f us (budget 1000 us)\n",
               j["tick_mean_us"].get<double>(), j["tick_max_us"].get<double>(), j["tick_p999_us"].get<double>());
  std::fprintf(out, "  real-time factor   : %.1f (%.1f s wall)\n", j["real_time_factor"].get<double>(),
               j["wall_time_s"].get<double>());
  const auto& b = j["ball_impulse_delivered"];
  if (b[0].get<double>() != 0 || b[1].get<double>() != 0 || b[2].get<double>() != 0) {
    std::fprintf(out, "  ball impulse       : %.2f %.2f %.2f N·s delivered in all (momentum the ball lost)\n",
                 b[0].get<double>(), b[1].get<double>(), b[2].get<double>());
  }
  if (j["safe_mode_ticks"].get<long>() > 0) std::fprintf(out, "  safe-mode ticks    : %ld\n", j["safe_mode_ticks"].get<long>());
  for (const auto& f : j["foot_contact"]) {
    std::fprintf(out, "  %-5s sole contact  : max tilt %.2f deg to its support, %.3f s tilted, slide %.1f mm\n",
                 f["foot"].get<std::string>().c_str(), f["max_tilt_deg"].get<double>(), f["tilt_time_s"].get<double>(),
                 f["slide_mm"].get<double>());
  }
  if (!j["com_return_mm"].is_null()) {
    std::fprintf(out, "  CoM return         : %.1f mm, the farthest it rested from where it was before the first push\n",
                 j["com_return_mm"].get<double>());
  }
  std::fprintf(out, "  pass rules         :");
  for (const auto& x : j["rules"]) {
    std::fprintf(out, " %s %s %.4g%s%s (<= %.4g);", x["passed"].get<bool>() ? "ok" : "FAILED",
                 x["rule"].get<std::string>().c_str(), x["value"].get<double>(), x["unit"].get<std::string>().empty() ? "" : " ",
                 x["unit"].get<std::string>().c_str(), x["threshold"].get<double>());
  }
  std::fprintf(out, "\n");
  if (j["feet_touch_s"].get<double>() > 0) std::fprintf(out, "  feet touching      : %.3f s\n", j["feet_touch_s"].get<double>());
  for (const char* k : {"csv", "video"}) {
    const std::string f = j["files"][k].get<std::string>();
    if (!f.empty()) std::fprintf(out, "  %-18s : %s\n", k, f.c_str());
  }
  for (const auto& f : j["files"]["plots"]) std::fprintf(out, "  plot               : %s\n", f.get<std::string>().c_str());
}

std::string markdownTable(const std::vector<nlohmann::ordered_json>& records) {
  std::ostringstream s;
  s << "| scenario | controller | result | max torso pitch (°) | max torso roll (°) | CoM x (mm) | "
       "max right-foot pitch (°) | min ZMP margin (mm) | sole slide (mm) / tilted (s) | lowest-level error max | "
       "tick mean / p99.9 / max (µs) | RTF |\n"
    << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  bool push_x = false;
  for (const auto& j : records) {
    if (j.contains("directions") || j.contains("ablation") || j.contains("cells")) continue;  // their own tables
    push_x = push_x || j["scenario"] == "push_x";
    std::string result = j["passed"].get<bool>() ? "PASS" : "FAIL";
    if (j["fell"].get<bool>()) result += fmt(" (fell at %.2f s: ", j["fall_time"].get<double>()) + j["fall_reason"].get<std::string>() + ")";
    else if (!j["zmp_inside"].get<bool>()) result += " (ZMP left a sole)";
    else {
      std::string failed;
      for (const auto& x : j["rules"]) {
        if (!x["passed"].get<bool>()) failed += (failed.empty() ? "" : ", ") + x["rule"].get<std::string>();
      }
      if (!failed.empty()) result += " (" + failed + ")";
    }
    s << "| " << j["scenario"].get<std::string>() << " | " << j["controller"].get<std::string>() << " | " << result
      << " | " << fmt("%.1f", j["max_torso_pitch_deg"].get<double>()) << " | "
      << fmt("%.1f", j["max_torso_roll_deg"].get<double>()) << " | " << fmt("%+.0f", j["com_x_min_mm"].get<double>())
      << " … " << fmt("%+.0f", j["com_x_max_mm"].get<double>()) << " | "
      << fmt("%.2f", j["max_foot_pitch_deg"].get<double>()) << " | " << fmtOr(j["zmp_margin_mm"], "%.1f") << " | "
      << fmt("%.1f", std::max(j["foot_contact"][0]["slide_mm"].get<double>(), j["foot_contact"][1]["slide_mm"].get<double>()))
      << " / "
      << fmt("%.2f", std::max(j["foot_contact"][0]["tilt_time_s"].get<double>(), j["foot_contact"][1]["tilt_time_s"].get<double>()))
      << " | " << fmt("%.3g", j["lowest_level_error_max"].get<double>()) << " | " << fmt("%.0f", j["tick_mean_us"].get<double>())
      << " / " << fmt("%.0f", j["tick_p999_us"].get<double>()) << " / " << fmt("%.0f", j["tick_max_us"].get<double>())
      << " | " << fmt("%.1f", j["real_time_factor"].get<double>()) << " |\n";
  }
  if (push_x) {
    s << "| *paper, push_x (Table II, Fig. 8)* | HQP | survived 12 N·s | 25.7 | – | −29 … +56 | 1.5 | – | – | ~10³ peaks | 363 (loop mean) | – |\n";
  }
  // Moving supports: what the right foot went through (MuJoCo ground truth, 20 Hz low-pass).
  bool header = false;
  for (const auto& j : records) {
    if (j.contains("directions") || j.contains("cells") || !j.contains("supports")) continue;
    if (!header) {
      s << "\n| moving support | result | right-foot peak velocity x / y / z (m/s) | peak angular velocity x / y / z "
           "(rad/s) | max roll / pitch / yaw (°) | min ZMP margin (mm) |\n|---|---|---|---|---|---|\n";
      header = true;
    }
    const auto& v = j["right_foot_peak_velocity_m_s"];
    const auto& w = j["right_foot_peak_angular_velocity_rad_s"];
    const auto& a = j["right_foot_max_roll_pitch_yaw_deg"];
    s << "| " << j["scenario"].get<std::string>() << " | " << (j["passed"].get<bool>() ? "PASS" : "FAIL") << " | "
      << fmt("%.2f", v[0].get<double>()) << " / " << fmt("%.2f", v[1].get<double>()) << " / "
      << fmt("%.2f", v[2].get<double>()) << " | " << fmt("%.2f", w[0].get<double>()) << " / "
      << fmt("%.2f", w[1].get<double>()) << " / " << fmt("%.2f", w[2].get<double>()) << " | "
      << fmt("%.1f", a[0].get<double>()) << " / " << fmt("%.1f", a[1].get<double>()) << " / "
      << fmt("%.1f", a[2].get<double>()) << " | " << fmtOr(j["zmp_margin_mm"], "%.1f") << " |\n";
  }
  for (const auto& j : records) {
    if (!j.contains("directions")) continue;
    s << "\n**" << j["scenario"].get<std::string>() << "** (" << j["controller"].get<std::string>()
      << "): " << (j["passed"].get<bool>() ? "PASS" : "FAIL") << " — every direction must survive the "
      << "required value (the paper's largest push, or its peak support velocity).\n\n"
      << "| direction | largest survived | first failure | required | trials |\n|---|---|---|---|---|\n";
    for (const auto& d : j["directions"]) {
      const std::string unit = " " + d["unit"].get<std::string>();
      s << "| " << d["direction"].get<std::string>() << " | " << fmt("%.2f", d["largest_passed"].get<double>()) << unit
        << " | " << fmtOr(d["smallest_failed"], "%.2f", "none up to the bracket end") << unit << " | "
        << fmt("%.2f", d["required"].get<double>()) << unit << " | " << d["trials"].size() << " |\n";
    }
  }
  return s.str();
}

void writeJson(const std::string& path, const nlohmann::ordered_json& j) { writeText(path, j.dump(2) + "\n"); }

void writeText(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + path);
}

}  // namespace hqp::sim
