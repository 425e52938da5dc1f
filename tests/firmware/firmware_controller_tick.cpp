// Firmware build of the whole Controller::tick with the Walker3 model: this file and the
// controller's translation unit are compiled with -fno-exceptions -fno-rtti; only the YAML
// loading (firmware/config.cpp) is built with exceptions, and it runs before the ticks.
// Checks on a robot standing at rest: balance mode, finite currents, and that a solver budget
// cuts the lower levels every tick without leaving balance mode and is counted.
#include <cmath>
#include <cstdio>

#include "support/walker3_standing.hpp"
#include "walker3_firmware.hpp"

namespace fw = hqp::firmware;

namespace {

int fail(const char* what, long tick) {
  std::printf("FAILED: %s (tick %ld)\n", what, tick);
  return 1;
}

// 300 ticks; budget_us > 0: every tick must be cut at level 1 (level 0 is always solved).
int run(fw::Config config, double budget_us) {
  const auto pose = hqp::testing::walker3Standing();
  const double half = 0.5 * fw::Robot::total_mass * 9.81;
  const fw::Sensors s = hqp::testing::walker3RestingSensors(
      pose, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  config.planner.com_height = pose.com_height;
  config.qp.hqp.budget_us = budget_us;
  fw::FirmwareController ctrl(config);
  fw::Command cmd;
  constexpr long kTicks = 300;
  for (long k = 0; k < kTicks; ++k) {
    ctrl.tick(s, cmd);
    const fw::TickInfo info = ctrl.info();
    if (info.safe_mode || cmd.safe_mode) return fail("safe mode", k);
    if (!cmd.current.allFinite()) return fail("non-finite current", k);
    if (budget_us > 0.0 && info.cut_level != 1) return fail("budget did not cut at level 1", k);
    if (budget_us == 0.0 && info.cut_level != -1) return fail("cut without a budget", k);
  }
  const fw::TickInfo info = ctrl.info();
  if (info.budget_cuts != (budget_us > 0.0 ? kTicks : 0)) return fail("budget cuts not counted", kTicks);
  std::printf("%s: %ld ticks in balance mode, budget cuts %ld, |i| max %.3f A\n",
              budget_us > 0.0 ? "tiny budget" : "no budget", kTicks, info.budget_cuts, cmd.current.cwiseAbs().maxCoeff());
  return 0;
}

}  // namespace

int main() {
  const fw::Config config = fw::loadConfig(HQP_SOURCE_DIR "/robots/walker3/controller.yaml");
  if (int rc = run(config, 0.0)) return rc;
  return run(config, 1e-6);  // 1 ps: nothing below level 0 fits
}
