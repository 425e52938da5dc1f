// sim_demo: Walker3 in MuJoCo 2.2 under the balance controller, the paper's Section VI-A
// scenarios with metrics, pass/fail, CSV logs, PNG plots and a headless MP4 (docs/scenarios.md).
//   sim_demo --list
//   sim_demo --scenario NAME [--scenario NAME ...] [--set key=value ...] [--config FILE.yaml]
//            [--out DIR] [--no-video] [--no-plots] [--controller hqp|wqp]
//   sim_demo --all
//   sim_demo --scenario NAME --record FILE [--record-start S] [--record-duration S] [--record-every N]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "friction_ablation.hpp"
#include "push_sweep.hpp"
#include "recording.hpp"
#include "report.hpp"
#include "robustness.hpp"
#include "run.hpp"
#include "scenario.hpp"
#include "simulation.hpp"

#ifndef HQP_SIM_SCENE
#define HQP_SIM_SCENE ""
#endif
#ifndef HQP_SIM_PLANT
#define HQP_SIM_PLANT ""
#endif
#ifndef HQP_SIM_CONTROLLER_CONFIG
#define HQP_SIM_CONTROLLER_CONFIG ""
#endif
#ifndef HQP_SIM_ROBUSTNESS
#define HQP_SIM_ROBUSTNESS ""
#endif
#ifndef HQP_SIM_PYTHON
#define HQP_SIM_PYTHON "/usr/bin/python3"
#endif
#ifndef HQP_SIM_PLOT_SCRIPT
#define HQP_SIM_PLOT_SCRIPT ""
#endif

namespace {

namespace fs = std::filesystem;
using hqp::sim::ScenarioParams;

struct Paths {
  std::string scene = HQP_SIM_SCENE, plant = HQP_SIM_PLANT, controller_config = HQP_SIM_CONTROLLER_CONFIG;
  std::string python = HQP_SIM_PYTHON, plot_script = HQP_SIM_PLOT_SCRIPT;
  std::string robustness = HQP_SIM_ROBUSTNESS;
};

std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The paper's figures as PNG (sim_demo/plots/plot_scenario.py, matplotlib; it finds the pushes,
// with their impulses, in the CSV); a missing Python or matplotlib costs the plots, not the run.
std::vector<std::string> makePlots(const Paths& paths, const ScenarioParams& p, const std::string& csv,
                                   const std::string& dir) {
  if (paths.plot_script.empty() || !fs::exists(paths.plot_script)) return {};
  std::string cmd = shellQuote(paths.python) + " " + shellQuote(paths.plot_script) + " " + shellQuote(csv) + " --out " +
                    shellQuote(dir) + " --title " + shellQuote(p.name + " (" + p.controller + ")");
  std::fflush(stdout);
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "sim_demo: plotting failed (%s); the CSV is complete\n", cmd.c_str());
    return {};
  }
  std::vector<std::string> files;
  const std::string stem = fs::path(csv).stem().string();
  for (const char* fig : {"_fig8.png", "_fig9.png", "_fig11.png", "_fig12.png", "_fig13.png", "_fig14.png"}) {
    const fs::path f = fs::path(dir) / (stem + fig);
    if (fs::exists(f)) files.push_back(f.string());
  }
  return files;
}

std::unique_ptr<hqp::sim::Driver> makeDriver(const std::string& driver_name, const Paths& paths,
                                             const ScenarioParams& p, const hqp::sim::Simulation& sim) {
  if (driver_name == "pd") return hqp::sim::makeJointPdDriver(sim);
  auto d = hqp::sim::makeBalanceController(paths.controller_config, p.controller == "wqp",
                                           hqp::sim::controllerOverrides(p, sim.plant()));
  if (!d) throw std::runtime_error("this build has no balance controller; use --driver pd");
  return d;
}

hqp::sim::SimulationOptions simulationOptions(const Paths& paths, const ScenarioParams& p) {
  hqp::sim::SimulationOptions so;
  so.scene = hqp::sim::scenePath(p, paths.scene);  // moving supports bring their own scene
  so.plant = paths.plant;
  so.noise = p.noise;
  so.seed = p.seed;
  so.substeps = p.substeps;
  so.perturbation = p.perturbation;
  return so;
}

// friction_ablation: each run as a plain run of its base scenario (CSV, summary.json, no video or
// per-run plots) in DIR/<scenario>_<variant>/, then the table and sim_demo/plots/plot_ablation.py.
nlohmann::ordered_json runAblation(const Paths& paths, const std::string& driver_name, const ScenarioParams& p,
                                   const std::string& dir, bool no_plots) {
  fs::create_directories(dir);
  const auto run_one = [&](const ScenarioParams& v, const std::string& variant) {
    hqp::sim::Simulation sim(simulationOptions(paths, v));
    auto driver = makeDriver(driver_name, paths, v, sim);
    hqp::sim::RunOptions o = hqp::sim::runOptions(v);
    o.out_dir = (fs::path(dir) / (v.name + "_" + variant)).string();
    std::printf("  %s, friction compensation %s ...\n", v.name.c_str(), variant.c_str());
    std::fflush(stdout);
    const hqp::sim::RunSummary r = hqp::sim::runScenario(sim, *driver, o);
    hqp::sim::writeJson((fs::path(o.out_dir) / "summary.json").string(), hqp::sim::runRecord(v, r));
    return r;
  };
  nlohmann::ordered_json record = hqp::sim::ablationRecord(p, hqp::sim::runFrictionAblation(p, run_one));
  const std::string json = (fs::path(dir) / "ablation.json").string();
  hqp::sim::writeJson(json, record);
  hqp::sim::writeText((fs::path(dir) / "ablation.md").string(), hqp::sim::ablationMarkdown(record));
  const fs::path script = fs::path(paths.plot_script).parent_path() / "plot_ablation.py";
  if (!no_plots && !paths.plot_script.empty() && fs::exists(script)) {
    const std::string png = (fs::path(dir) / "friction_ablation.png").string();
    const std::string cmd = shellQuote(paths.python) + " " + shellQuote(script.string()) + " " + shellQuote(json) +
                            " --out " + shellQuote(png);
    std::fflush(stdout);
    if (std::system(cmd.c_str()) == 0 && fs::exists(png)) record["files"]["plots"].push_back(png);
    else std::fprintf(stderr, "sim_demo: plotting failed (%s); the JSON is complete\n", cmd.c_str());
  }
  return record;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Walker3 balance scenarios in MuJoCo 2.2 (1 kHz sensor -> current loop); docs/scenarios.md"};
  Paths paths;
  bool list = false, all = false, no_video = false, no_plots = false;
  std::vector<std::string> names, sets, video_only;
  std::string config, out = "out", controller, driver_name = "controller";
  int jobs = 0;
  app.add_flag("--list", list, "list the scenarios and their parameters");
  app.add_option("--scenario", names, "scenario to run (repeatable); see --list");
  app.add_flag("--all", all, "run every scenario");
  app.add_option("--set", sets, "override a parameter, key=value (repeatable; see --list)");
  app.add_option("--config", config, "YAML file of parameter overrides (applied before --set)")->check(CLI::ExistingFile);
  app.add_option("--out", out, "output directory")->capture_default_str();
  app.add_flag("--no-video", no_video, "skip the MP4 videos");
  app.add_option("--video-only", video_only, "render videos only for these scenarios (repeatable)");
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_option("--jobs", jobs, "robustness: simulations at a time (0: one per core)")->capture_default_str();
  app.add_option("--controller", controller, "hqp (strict hierarchy) or wqp (weighted); same as --set controller=")
      ->check(CLI::IsMember({"hqp", "wqp"}));
  app.add_option("--driver", driver_name, "controller (balance controller) or pd (joint PD stand-in, no QP)")
      ->check(CLI::IsMember({"controller", "pd"}))->capture_default_str();
  app.add_option("--scene", paths.scene, "scene MJCF")->capture_default_str();
  app.add_option("--plant", paths.plant, "plant parameter YAML")->capture_default_str();
  app.add_option("--controller-config", paths.controller_config, "controller YAML")->capture_default_str();
  hqp::sim::RecordOptions recording;
  app.add_option("--record", recording.file, "record the HQP problem of the ticks in a window to FILE (docs/recording.md)");
  app.add_option("--record-start", recording.start, "s, start of the recorded window")->capture_default_str();
  app.add_option("--record-duration", recording.duration, "s, length of the recorded window")->capture_default_str();
  app.add_option("--record-every", recording.every, "keep every Nth tick of the window")
      ->check(CLI::PositiveNumber)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  for (int i = 0; i < argc; ++i) recording.source += std::string(i ? " " : "") + argv[i];

  if (list) {
    std::printf("scenarios:\n");
    for (const std::string& n : hqp::sim::scenarioNames()) {
      std::printf("  %-11s %s\n", n.c_str(), hqp::sim::presetScenario(n).description.c_str());
    }
    std::printf("\nparameters (--set key=value, or key: value in a --config YAML file):\n");
    for (const auto& [k, h] : hqp::sim::parameterHelp()) std::printf("  %-17s %s\n", k.c_str(), h.c_str());
    std::printf("\npreset values:\n");
    for (const std::string& n : hqp::sim::scenarioNames()) {
      std::printf("  %s:", n.c_str());
      for (const auto& [k, v] : hqp::sim::parameterValues(hqp::sim::presetScenario(n))) {
        const bool support = (k == "scene" && v != "scene.xml") || (k.rfind("motion_", 0) == 0 && k != "motion_ramp" && v != "none");
        if (k == "duration" || k == "pushes" || support) std::printf(" %s=%s", k.c_str(), v.c_str());
      }
      std::printf("\n");
    }
    return 0;
  }
  if (all) {  // every scenario but the robustness matrix, which runs the others many times over
    names = hqp::sim::scenarioNames();
    names.erase(std::remove(names.begin(), names.end(), "robustness"), names.end());
  }
  if (names.empty()) {
    std::fprintf(stderr, "sim_demo: nothing to run: give --scenario NAME, --all or --list\n");
    return 2;
  }

  // Resolve every scenario before running any: a typo fails at once, not after minutes.
  std::vector<ScenarioParams> scenarios;
  try {
    for (const std::string& n : names) {
      ScenarioParams p = hqp::sim::presetScenario(n);
      if (!config.empty()) hqp::sim::applyParameterFile(p, config);
      for (const std::string& s : sets) hqp::sim::applyAssignment(p, s);
      if (!controller.empty()) p.controller = controller;
      scenarios.push_back(p);
    }
    for (const std::string& v : video_only) hqp::sim::presetScenario(v);
    if (!recording.file.empty() && (scenarios.size() != 1 || scenarios[0].sweep))
      throw std::runtime_error("--record needs exactly one scenario that is not a sweep");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_demo: %s\n", e.what());
    return 2;
  }

  std::vector<nlohmann::ordered_json> records;
  bool all_passed = true;
  try {
    fs::create_directories(out);
    for (const ScenarioParams& p : scenarios) {
      if (p.robustness) {
        const std::string dir = (fs::path(out) / "robustness").string();
        const std::string matrix = p.robustness_matrix.empty() ? paths.robustness : p.robustness_matrix;
        std::printf("\n== robustness: %s (%s) ==\n", p.description.c_str(), matrix.c_str());
        const hqp::sim::RobustnessMatrix m = hqp::sim::loadRobustnessMatrix(matrix);
        const std::vector<std::string> common = {"--scene", paths.scene, "--plant", paths.plant, "--controller-config",
                                                 paths.controller_config};
        nlohmann::ordered_json record =
            hqp::sim::runRobustness(m, fs::read_symlink("/proc/self/exe").string(), common, dir, jobs);
        record["files"] = {{"json", dir + "/robustness.json"}, {"markdown", dir + "/robustness.md"}};
        const fs::path script = fs::path(paths.plot_script).parent_path() / "plot_robustness.py";
        if (!no_plots && !paths.plot_script.empty() && fs::exists(script)) {
          const std::string png = dir + "/robustness.png";
          const std::string cmd = shellQuote(paths.python) + " " + shellQuote(script.string()) + " " +
                                  shellQuote(dir + "/robustness.json") + " --out " + shellQuote(png);
          if (std::system(cmd.c_str()) == 0 && fs::exists(png)) record["files"]["heatmap"] = png;
          else std::fprintf(stderr, "sim_demo: plotting failed (%s); the JSON is complete\n", cmd.c_str());
        }
        std::printf("\n%s\nrobustness: %s/robustness.md, robustness.json%s\n", hqp::sim::robustnessMarkdown(record).c_str(),
                    dir.c_str(), record["files"].contains("heatmap") ? ", robustness.png" : "");
        all_passed = all_passed && record["passed"].get<bool>();
        records.push_back(record);
        continue;
      }
      if (p.ablation) {
        const std::string dir = (fs::path(out) / (p.name + (p.controller == "hqp" ? "" : "_" + p.controller))).string();
        std::printf("\n== %s: %s ==\n", p.name.c_str(), p.description.c_str());
        nlohmann::ordered_json record = runAblation(paths, driver_name, p, dir, no_plots);
        hqp::sim::writeJson((fs::path(dir) / "summary.json").string(), record);
        hqp::sim::printAblation(stdout, record);
        all_passed = all_passed && record["passed"].get<bool>();
        records.push_back(record);
        continue;
      }
      hqp::sim::Simulation sim(simulationOptions(paths, p));
      auto driver = makeDriver(driver_name, paths, p, sim);
      const std::string dir = (fs::path(out) / (p.name + (p.controller == "hqp" ? "" : "_" + p.controller))).string();
      fs::create_directories(dir);
      std::printf("\n== %s: %s; %s%s ==\n", p.name.c_str(), p.description.c_str(), driver->name(),
                  p.noise ? ", sensor noise on" : "");
      std::fflush(stdout);
      nlohmann::ordered_json record;
      if (p.sweep) {
        const auto on_trial = [](const hqp::sim::SweepDirection& d, const hqp::sim::SweepTrial& t) {
          std::printf("  %s %6.2f %s: %s (max pitch %.1f deg, roll %.1f deg)%s%s\n", d.direction.c_str(), t.impulse,
                      d.unit.c_str(),
                      t.run.passed ? "pass" : "FAIL", t.run.max_abs_pitch * 180 / M_PI,
                      t.run.max_abs_roll * 180 / M_PI, t.run.fell ? ", fell: " : "", t.run.fall_reason.c_str());
          std::fflush(stdout);
        };
        record = hqp::sim::sweepRecord(p, hqp::sim::runPushSweep(sim, *driver, p, on_trial));
      } else {
        hqp::sim::RunOptions o = hqp::sim::runOptions(p);
        o.out_dir = dir;
        o.progress = true;
        if (!recording.file.empty() && !hqp::sim::startRecording(*driver, recording))
          throw std::runtime_error("--record: this driver has no HQP to record (use the balance controller, hqp)");
        o.video = !no_video && (video_only.empty() || std::find(video_only.begin(), video_only.end(), p.name) !=
                                                          video_only.end());
        const hqp::sim::RunSummary r = hqp::sim::runScenario(sim, *driver, o);
        if (!recording.file.empty()) {
          const std::size_t n = hqp::sim::finishRecording(*driver);
          std::printf("recorded %zu problem instances (%.3f s from %.3f s, every %d ticks) to %s\n", n,
                      recording.duration, recording.start, recording.every, recording.file.c_str());
        }
        record = hqp::sim::runRecord(p, r);
        if (!no_plots) record["files"]["plots"] = makePlots(paths, p, r.csv_path, dir);
      }
      hqp::sim::writeJson((fs::path(dir) / "summary.json").string(), record);
      hqp::sim::printRecord(stdout, record);
      all_passed = all_passed && record["passed"].get<bool>();
      records.push_back(record);
    }
    bool plain = false;  // a record with a row in the main table
    for (const auto& r : records) plain = plain || !(r.contains("ablation") || r.contains("cells"));
    std::string table = plain ? hqp::sim::markdownTable(records) : std::string();
    for (const auto& r : records) {
      if (r.contains("ablation")) table += "\n" + hqp::sim::ablationMarkdown(r);
    }
    hqp::sim::writeText((fs::path(out) / "summary.md").string(), "# Walker3 balance scenarios (sim_demo)\n\n" + table);
    hqp::sim::writeJson((fs::path(out) / "summary.json").string(), records);
    std::printf("\n%s\nsummary: %s/summary.md, %s/summary.json\n", table.c_str(), out.c_str(), out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_demo: %s\n", e.what());
    return 2;
  }
  return all_passed ? 0 : 1;
}
