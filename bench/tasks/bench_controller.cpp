// The whole Controller::tick() for Walker3 (sensors → currents), HqpWbc and WqpWbc, on a
// sequence of 1000 perturbed standing states (uneven loads, moving CoPs, joint rates), warm as
// in a real run. Reports the median and the 99.9th percentile of the tick and of each stage
// (from the controller's own stage clocks) as counters, in µs. The inputs repeat, so every
// input is ticked ~100 times from the same warm state: tick_inst_p999_us is the 99.9th
// percentile over the 1000 inputs of each input's median tick (the slowest inputs, free of
// the shared machine's preemptions, which dominate tick_p999_us).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "support/walker3_controller.hpp"
#include "support/walker3_standing.hpp"

namespace {

using Robot = walker3::Robot;
using Controller = hqp::testing::Walker3Controller;
using Sensors = Controller::Sensors;
using hqp::tasks::Stage;

std::vector<Sensors> makeInputs(const hqp::testing::Walker3Standing& s, int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double half = 0.5 * Robot::total_mass * 9.81;
  std::vector<Sensors> out;
  out.reserve(static_cast<std::size_t>(n));
  double shift = 0.0, cx = 0.0;
  for (int k = 0; k < n; ++k) {
    // A slow random walk of the load split and CoP, as under pushes.
    shift = std::clamp(shift + 0.02 * u(rng), -0.5, 0.5);
    cx = std::clamp(cx + 0.004 * u(rng), -0.09, 0.09);
    auto in = hqp::testing::walker3RestingSensors(
        s, {(1 + shift) * half, (1 - shift) * half},
        {Eigen::Vector2d(cx, 0.01 * u(rng)), Eigen::Vector2d(-cx, 0.01 * u(rng))});
    for (int j = 0; j < 12; ++j) {
      in.q(j) += 0.002 * u(rng);
      in.dq(j) = 0.2 * u(rng);
    }
    in.imu_gyro = Eigen::Vector3d(0.1 * u(rng), 0.1 * u(rng), 0.02 * u(rng));
    out.push_back(in);
  }
  return out;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

void BM_Tick(benchmark::State& state) {
  const auto solver = state.range(0) == 0 ? Controller::Config::Solver::Hqp
                                          : Controller::Config::Solver::Wqp;
  const auto s = hqp::testing::walker3Standing();
  auto ctrl = hqp::testing::makeWalker3Controller(hqp::testing::walker3Config(solver, s.com_height));
  const auto inputs = makeInputs(s, 1000);
  Controller::Command cmd;
  constexpr int kStages = static_cast<int>(Stage::Count);
  std::vector<std::vector<double>> t(kStages);
  for (auto& v : t) v.reserve(1 << 20);
  std::vector<std::vector<double>> level_t(Controller::num_levels);
  for (auto& v : level_t) v.reserve(1 << 20);
  std::vector<std::vector<double>> per_input(inputs.size());
  std::size_t k = 0;
  long safe = 0, non_optimal = 0;
  // Per level: ticks whose QP changed its working set (iterations > 0), and active rows.
  std::vector<long> iter_ticks(Controller::num_levels, 0), active(Controller::num_levels, 0);
  for (auto _ : state) {
    ctrl->tick(inputs[k], cmd);
    benchmark::DoNotOptimize(cmd.current.data());
    const auto& d = ctrl->diagnostics();
    for (int st = 0; st < kStages; ++st) t[st].push_back(d.time_us[st]);
    per_input[k].push_back(d.time_us[static_cast<int>(Stage::Total)]);
    for (int p = 0; p < Controller::num_levels; ++p) {
      level_t[p].push_back(d.levels[p].time_us);
      if (d.levels[p].iterations > 0) ++iter_ticks[p];
      active[p] += d.levels[p].num_active;
    }
    if (d.mode != hqp::tasks::ControllerMode::Balance) {
      ++safe;
      ctrl->reset();
    }
    if (d.status != hqp::QpStatus::Optimal) ++non_optimal;
    k = (k + 1) % inputs.size();
  }
  const char* names[kStages] = {"estimator", "dynamics", "planner", "tasks", "solve", "joint", "tick"};
  for (int st = 0; st < kStages; ++st) {
    if (t[st].empty()) continue;
    state.counters[std::string(names[st]) + "_p50_us"] = percentile(t[st], 0.5);
    if (st == static_cast<int>(Stage::Solve) || st == static_cast<int>(Stage::Total))
      state.counters[std::string(names[st]) + "_p999_us"] = percentile(t[st], 0.999);
  }
  std::vector<double> medians;
  for (const auto& v : per_input)
    if (!v.empty()) medians.push_back(percentile(v, 0.5));
  if (!medians.empty()) state.counters["tick_inst_p999_us"] = percentile(medians, 0.999);
  if (solver == Controller::Config::Solver::Hqp)
    for (int p = 0; p < Controller::num_levels; ++p)
      state.counters["level" + std::to_string(p + 1) + "_p50_us"] = percentile(level_t[p], 0.5);
  const double ticks = static_cast<double>(state.iterations());
  if (solver == Controller::Config::Solver::Hqp) {
    for (int p = 0; p < Controller::num_levels; ++p) {
      const std::string l = "level" + std::to_string(p + 1);
      state.counters[l + "_iter_frac"] = static_cast<double>(iter_ticks[p]) / ticks;
      state.counters[l + "_active"] = static_cast<double>(active[p]) / ticks;
    }
  }
  state.counters["safe_mode_ticks"] = static_cast<double>(safe);
  state.counters["non_optimal_ticks"] = static_cast<double>(non_optimal);
  state.SetLabel(solver == Controller::Config::Solver::Hqp ? "HqpWbc" : "WqpWbc");
}
BENCHMARK(BM_Tick)->Arg(0)->Arg(1)->ArgName("wqp")->Unit(benchmark::kMicrosecond)->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
