#pragma once
// push_sweep: the largest single impulse on the torso survived along each direction, found by
// bisection on [min, max] (docs/scenarios.md). Each trial is a fresh run from the standing pose.
// Survival is the same pass criterion as every run (no fall, no safe mode, ZMPs inside their
// soles); bisection assumes it is monotonic in the impulse, which the trials list lets one check.

#include <functional>
#include <string>
#include <vector>

#include "run.hpp"
#include "scenario.hpp"

namespace hqp::sim {

struct SweepTrial {
  double impulse = 0;  // N·s (push_sweep), or the board's peak velocity, m/s or rad/s (skate_sweep)
  RunSummary run;
};

struct SweepDirection {
  std::string direction;         // +x, -x, +y, -y; skate_sweep: x, y, z, roll, pitch, yaw
  std::string unit = "N·s";      // of the values below
  double required = 0;           // the value that must pass (sweep_required in this unit)
  double largest_passed = 0;     // N·s; 0 when even min_impulse fails
  double smallest_failed = 0;    // N·s; 0 when even max_impulse passes
  std::vector<SweepTrial> trials;
};

struct SweepResult {
  std::vector<SweepDirection> directions;
  bool passed = false;           // every direction passed at least SweepParams::required
  double wall_time = 0;          // s
};

// `on_trial` (optional) is called after every trial, for progress output. With
// p.sweep_params.skate the swept value is the right board's peak velocity along each skate axis
// (the skate_<axis> preset with its displacement profile scaled; bracket and resolution are
// fractions of the paper's peak velocity, and values are reported in m/s or rad/s).
SweepResult runPushSweep(Simulation& sim, Driver& driver, const ScenarioParams& p,
                         const std::function<void(const SweepDirection&, const SweepTrial&)>& on_trial = {});

}  // namespace hqp::sim
