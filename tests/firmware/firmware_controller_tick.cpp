// Firmware build of the whole Controller::tick with the Walker3 model: this file and the
// controller's translation unit are compiled with -fno-exceptions -fno-rtti; only the YAML
// loading (firmware/config.cpp) is built with exceptions, and it runs before the ticks.
// Checks on a robot standing at rest: balance mode, finite currents; a solver budget that is
// never reached changes no command; a 1 ps budget cuts the lower levels every tick without
// leaving balance mode, and the cuts are counted.
#include <cmath>
#include <cstdio>
#include <vector>

#include "support/walker3_standing.hpp"
#include "walker3_firmware.hpp"

namespace fw = hqp::firmware;

namespace {

int fail(const char* what, long tick) {
  std::printf("FAILED: %s (tick %ld)\n", what, tick);
  return 1;
}

// 300 ticks; a budget below 1 µs must cut every tick at level 1 (level 0 is always solved), a
// larger one none. The currents of every tick go to `currents`.
int run(fw::Config config, double budget_us, std::vector<fw::Command>& currents) {
  const auto pose = hqp::testing::walker3Standing();
  const double half = 0.5 * fw::Robot::total_mass * 9.81;
  const fw::Sensors s = hqp::testing::walker3RestingSensors(
      pose, {half, half}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  config.planner.com_height = pose.com_height;
  config.qp.hqp.budget_us = budget_us;
  fw::FirmwareController ctrl(config);
  fw::Command cmd;
  constexpr long kTicks = 300;
  const bool tiny = budget_us > 0.0 && budget_us < 1.0;
  for (long k = 0; k < kTicks; ++k) {
    ctrl.tick(s, cmd);
    currents.push_back(cmd);
    const fw::TickInfo info = ctrl.info();
    if (info.safe_mode || cmd.safe_mode) return fail("safe mode", k);
    if (!cmd.current.allFinite()) return fail("non-finite current", k);
    if (tiny && info.cut_level != 1) return fail("budget did not cut at level 1", k);
    if (!tiny && info.cut_level != -1) return fail("cut without a (tight) budget", k);
  }
  const fw::TickInfo info = ctrl.info();
  if (info.budget_cuts != (tiny ? kTicks : 0)) return fail("budget cuts not counted", kTicks);
  std::printf("budget %g us: %ld ticks in balance mode, budget cuts %ld, |i| max %.3f A\n", budget_us, kTicks,
              info.budget_cuts, cmd.current.cwiseAbs().maxCoeff());
  return 0;
}

}  // namespace

int main() {
  const fw::Config config = fw::loadConfig(HQP_SOURCE_DIR "/robots/walker3/controller.yaml");
  std::vector<fw::Command> none, large, tiny;
  if (int rc = run(config, 0.0, none)) return rc;
  if (int rc = run(config, 1e9, large)) return rc;  // never reached: the same commands, bit for bit
  for (std::size_t k = 0; k < none.size(); ++k)
    if (!(none[k].current == large[k].current)) return fail("a budget never reached changed the command", long(k));
  return run(config, 1e-6, tiny);  // 1 ps: nothing below level 0 fits
}
