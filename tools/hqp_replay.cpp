// hqp_replay: solves recorded HqpWbc problem instances again (docs/recording.md), for bug
// reports: per level status, residual, active set, iterations and time, recorded and replayed,
// and the difference of x* to the recorded solution.
//   hqp_replay FILE [--instance K] [--cold] [--tol 1e-9]
// Exit code: 0 all replayed instances match, 1 some differ (x* beyond --tol, or a level's
// status), 2 the file cannot be read (the message says why) or bad arguments.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "hqp/problem_file.hpp"
#include "hqp/problem_instance.hpp"
#include "tasks/balance_hierarchy.hpp"
#include "walker3_model.hpp"

namespace {

// The shape this replays: Walker3's hierarchy as its definition gives it (balance_hierarchy.hpp);
// a recording of another shape is refused by the reader with both shapes in the message.
using Replay = hqp::tasks::StackedHqpOf<hqp::tasks::BalanceHierarchy, hqp::tasks::ContactLayout<walker3::Robot, 2, 6>>;
using Instance = hqp::ProblemInstance<Replay>;

std::string activeSet(const hqp::HqpLevelResult<Replay::max_active>& l) {
  std::vector<std::pair<int, bool>> rows;
  for (int k = 0; k < l.num_active; ++k) rows.emplace_back(l.active_row[k], l.active_upper[k]);
  std::sort(rows.begin(), rows.end());
  std::string s = "{";
  for (std::size_t k = 0; k < rows.size(); ++k)
    s += (k ? " " : "") + std::to_string(rows[k].first) + (rows[k].second ? "u" : "l");
  return s + "}";
}

struct Outcome {
  double dx = 0.0;          // ‖x − x_rec‖∞ / max(1, ‖x_rec‖∞)
  bool status_same = true;  // every level's status as recorded
  bool active_same = true;  // every level's active set as recorded (informational)
  double time_us = 0.0;
};

Outcome replay(Replay& wbc, const Instance& in, bool cold) {
  hqp::loadInstance(in, wbc, !cold);
  const auto t0 = std::chrono::steady_clock::now();
  wbc.solve();
  Outcome o;
  o.time_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  const auto& r = wbc.result();
  const auto& rec = in.result;
  o.dx = (r.x - rec.x).lpNorm<Eigen::Infinity>() / std::max(1.0, rec.x.lpNorm<Eigen::Infinity>());
  for (int p = 0; p < Replay::num_levels; ++p) {
    o.status_same = o.status_same && r.levels[p].status == rec.levels[p].status;
    o.active_same = o.active_same && activeSet(r.levels[p]) == activeSet(rec.levels[p]);
  }
  return o;
}

void printDetail(const Replay& wbc, const Instance& in, const Outcome& o, bool cold) {
  std::printf("instance at tick %lld (t = %.3f s), replayed %s: |dx|/max(1,|x|) = %.3g, solve %.1f us\n",
              static_cast<long long>(in.tick), in.time, cold ? "cold" : "warm (recorded working sets)", o.dx,
              o.time_us);
  const auto& r = wbc.result();
  for (int p = 0; p < Replay::num_levels; ++p) {
    const auto& a = in.result.levels[p];
    const auto& b = r.levels[p];
    const auto& ws = in.warm[p];
    std::printf("level %d: incoming working set of %d rows (QP size %d)\n", p + 1, ws.num_active, ws.variables);
    std::printf("  %-9s %-16s %-12s %-5s %-5s %-6s %-9s %s\n", "", "status", "residual", "rank", "iter", "vars",
                "time_us", "active set (stacked rows, u/l = upper/lower)");
    std::printf("  %-9s %-16s %-12.5g %-5d %-5d %-6d %-9.2f %s\n", "recorded", hqp::toString(a.status), a.residual,
                a.rank, a.iterations, a.variables, a.time_us, activeSet(a).c_str());
    std::printf("  %-9s %-16s %-12.5g %-5d %-5d %-6d %-9.2f %s\n", "replayed", hqp::toString(b.status), b.residual,
                b.rank, b.iterations, b.variables, b.time_us, activeSet(b).c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Replays recorded HqpWbc problem instances (docs/recording.md)"};
  std::string file;
  long instance = -1;
  bool cold = false;
  double tol = 1e-9;
  std::string csv;
  app.add_option("file", file, "recording (sim_demo --record)")->required();
  app.add_option("--instance", instance, "replay only instance K (0-based) and print it in detail");
  app.add_flag("--cold", cold, "start every level cold instead of from the recorded working sets");
  app.add_option("--csv", csv, "write instance, QP iterations of each level, solve time (us) per instance here");
  app.add_option("--tol", tol, "largest accepted |x - x_rec|_inf / max(1, |x_rec|_inf)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  hqp::ProblemFileInfo info;
  std::vector<Instance> instances;
  try {
    instances = hqp::readProblemFile<Replay>(file, &info);
  } catch (const hqp::ProblemFileError& e) {
    std::fprintf(stderr, "hqp_replay: %s\n", e.what());
    return 2;
  }
  std::printf("%s: %llu instances, source: %s\n", file.c_str(), static_cast<unsigned long long>(info.count),
              info.source.c_str());
  if (instance >= static_cast<long>(instances.size())) {
    std::fprintf(stderr, "hqp_replay: no instance %ld (the file has %zu)\n", instance, instances.size());
    return 2;
  }
  auto wbc = std::make_unique<Replay>(info.settings);  // hundreds of KiB (docs/hqp.md): not on the stack
  if (instance >= 0) {
    const Instance& in = instances[static_cast<std::size_t>(instance)];
    const Outcome o = replay(*wbc, in, cold);
    printDetail(*wbc, in, o, cold);
    const bool ok = o.dx <= tol && o.status_same;
    std::printf("%s\n", ok ? "MATCH" : "DIFFERS");
    return ok ? 0 : 1;
  }
  long differ = 0, active_differ = 0;
  double worst = 0.0;
  // The worst case over the file (docs/realtime.md): QP iterations per level and solve time.
  std::array<int, Replay::num_levels> max_iter{}, max_iter_rec{};
  std::vector<double> times;
  std::FILE* out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (out) {
    std::fprintf(out, "instance");
    for (int p = 0; p < Replay::num_levels; ++p) std::fprintf(out, ",iterations_l%d", p + 1);
    std::fprintf(out, ",time_us\n");
  }
  for (std::size_t k = 0; k < instances.size(); ++k) {
    const Outcome o = replay(*wbc, instances[k], cold);
    worst = std::max(worst, o.dx);
    times.push_back(o.time_us);
    if (out) {
      std::fprintf(out, "%zu", k);
      for (int p = 0; p < Replay::num_levels; ++p) std::fprintf(out, ",%d", wbc->result().levels[p].iterations);
      std::fprintf(out, ",%.2f\n", o.time_us);
    }
    for (int p = 0; p < Replay::num_levels; ++p) {
      max_iter[p] = std::max(max_iter[p], wbc->result().levels[p].iterations);
      max_iter_rec[p] = std::max(max_iter_rec[p], instances[k].result.levels[p].iterations);
    }
    if (!o.active_same) ++active_differ;
    if (o.dx > tol || !o.status_same) {
      ++differ;
      std::printf("instance %zu (tick %lld): |dx| %.3g%s: hqp_replay %s --instance %zu%s\n", k,
                  static_cast<long long>(instances[k].tick), o.dx, o.status_same ? "" : ", a level's status differs",
                  file.c_str(), k, cold ? " --cold" : "");
    }
  }
  std::printf("%zu instances replayed %s: %ld differ beyond %.1e (largest |dx| %.3g), %ld with another active set\n",
              instances.size(), cold ? "cold" : "warm", differ, tol, worst, active_differ);
  if (out) std::fclose(out);
  std::printf("QP iterations per level, max over instances (replayed / recorded; cap %d per QP solve):",
              info.settings.qp.max_iterations);
  for (int p = 0; p < Replay::num_levels; ++p) std::printf(" L%d %d/%d", p + 1, max_iter[p], max_iter_rec[p]);
  std::sort(times.begin(), times.end());
  if (!times.empty())
    std::printf("\nsolve time (us): median %.1f, p99 %.1f, max %.1f\n", times[times.size() / 2],
                times[std::min(times.size() - 1, times.size() * 99 / 100)], times.back());
  return differ == 0 ? 0 : 1;
}
