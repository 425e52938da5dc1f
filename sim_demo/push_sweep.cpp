#include "push_sweep.hpp"

#include <chrono>
#include <stdexcept>

namespace hqp::sim {

namespace {

Eigen::Vector3d unitOf(const std::string& d) {
  if (d == "+x") return Eigen::Vector3d::UnitX();
  if (d == "-x") return -Eigen::Vector3d::UnitX();
  if (d == "+y") return Eigen::Vector3d::UnitY();
  if (d == "-y") return -Eigen::Vector3d::UnitY();
  // Diagonals: "+x+y" and the like, a unit vector at 45°.
  if (d.size() == 4 && (d[0] == '+' || d[0] == '-') && d[1] == 'x' && (d[2] == '+' || d[2] == '-') && d[3] == 'y') {
    return Eigen::Vector3d(d[0] == '+' ? 1.0 : -1.0, d[2] == '+' ? 1.0 : -1.0, 0.0).normalized();
  }
  throw std::invalid_argument("sweep direction '" + d + "' (expected +x, -x, +y, -y or a diagonal such as +x-y)");
}

}  // namespace

SweepResult runPushSweep(Simulation& sim, Driver& driver, const ScenarioParams& p,
                         const std::function<void(const SweepDirection&, const SweepTrial&)>& on_trial) {
  const SweepParams& sp = p.sweep_params;
  if (!(sp.max_impulse > sp.min_impulse)) throw std::invalid_argument("push_sweep: sweep_max must exceed sweep_min");
  for (const std::string& dir : sp.directions) {  // refuse a wrong direction before any trial
    if (sp.skate) paperSkatePeak(dir);
    else unitOf(dir);
  }
  const auto wall0 = std::chrono::steady_clock::now();
  SweepResult result;
  result.passed = true;
  for (const std::string& dir : sp.directions) {
    SweepDirection sd;
    sd.direction = dir;
    // Push: the value is the impulse. Skate: the value is a fraction of the paper's peak velocity.
    const Eigen::Vector3d u = sp.skate ? Eigen::Vector3d::Zero() : unitOf(dir);
    const double unit_scale = sp.skate ? paperSkatePeak(dir) : 1.0;
    sd.unit = sp.skate ? (dir.size() == 1 ? "m/s" : "rad/s") : "N·s";
    sd.required = sp.required * unit_scale;
    const ScenarioParams skate_preset = sp.skate ? presetScenario("skate_" + dir) : ScenarioParams{};
    auto trial = [&](double value) {
      ScenarioParams tp = p;
      if (sp.skate) {
        // The preset's motion with its displacement scaled to this peak velocity; p's other
        // settings (controller, noise, criteria) stay.
        tp.supports = skate_preset.supports;
        for (SupportMotion& m : tp.supports) {
          if (!m.active()) continue;
          if (sp.frequency > 0.0) m.frequency = sp.frequency;
          const double k = value * unit_scale / m.peakVelocity();
          m.amplitude *= k;
          m.offset *= k;
        }
        tp.run.duration = skate_preset.run.duration;
      } else {
        tp.run.pushes.clear();
        Push push;
        push.time = sp.push_time;
        push.impulse = value * u;
        tp.run.pushes.push_back(push);
        tp.run.duration = sp.push_time + sp.observe;
      }
      RunOptions o = runOptions(tp);
      o.out_dir.clear();  // trials leave no files
      o.video = false;
      o.progress = false;
      SweepTrial t;
      t.impulse = value * unit_scale;
      t.run = runScenario(sim, driver, o);
      sd.trials.push_back(t);
      if (on_trial) on_trial(sd, sd.trials.back());
      return t.run.passed;
    };
    double lo = sp.min_impulse, hi = sp.max_impulse;
    if (!trial(lo)) {
      sd.largest_passed = 0.0;
      sd.smallest_failed = lo * unit_scale;
    } else if (trial(hi)) {
      sd.largest_passed = hi * unit_scale;
      sd.smallest_failed = 0.0;
    } else {
      while (hi - lo > sp.resolution) {
        const double mid = 0.5 * (lo + hi);
        (trial(mid) ? lo : hi) = mid;
      }
      sd.largest_passed = lo * unit_scale;
      sd.smallest_failed = hi * unit_scale;
    }
    if (sd.largest_passed < sd.required) result.passed = false;
    result.directions.push_back(std::move(sd));
  }
  result.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

}  // namespace hqp::sim
