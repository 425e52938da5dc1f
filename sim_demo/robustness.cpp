#include "robustness.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "report.hpp"
#include "scenario.hpp"

extern char** environ;

namespace hqp::sim {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw std::invalid_argument(file + ": " + what);
}

// A scalar as text; a sequence joined by ',' (items that are sequences by ':'), as --config does.
std::string valueText(const YAML::Node& v, const std::string& file, const std::string& where) {
  if (v.IsScalar()) return v.as<std::string>();
  if (!v.IsSequence()) fail(file, where + ": expected a value or a list");
  std::string text;
  for (const auto& item : v) {
    std::string t;
    if (item.IsSequence()) {
      for (const auto& x : item) t += (t.empty() ? "" : ":") + x.as<std::string>();
    } else {
      t = item.as<std::string>();
    }
    text += (text.empty() ? "" : ",") + t;
  }
  return text.empty() ? "none" : text;
}

Assignments assignments(const YAML::Node& n, const std::string& file, const std::string& where) {
  Assignments out;
  if (!n) return out;
  if (!n.IsMap()) fail(file, where + ": expected a map of parameter: value");
  for (const auto& kv : n) {
    const std::string key = kv.first.as<std::string>();
    out.emplace_back(key, valueText(kv.second, file, where + "." + key));
  }
  return out;
}

void applyAll(ScenarioParams& p, const Assignments& a, const std::string& file, const std::string& where) {
  for (const auto& [k, v] : a) {
    try {
      setParameter(p, k, v);
    } catch (const std::invalid_argument& e) {
      fail(file, where + ": " + e.what());
    }
  }
}

struct Job {
  std::size_t cell = 0;
  bool margin = false;
  unsigned seed = 0;
  int variant = -1;
  std::string dir;
  std::vector<std::string> args;
};

void addSets(std::vector<std::string>& args, const Assignments& a) {
  for (const auto& [k, v] : a) {
    args.push_back("--set");
    args.push_back(k + "=" + v);
  }
}

pid_t spawn(const std::string& exe, const std::vector<std::string>& args, const std::string& log) {
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, exe.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("robustness: cannot start " + exe);
  return pid;
}

// What a finished child left: its first record, or an error note.
json readChild(const Job& job, int status) {
  const fs::path summary = fs::path(job.dir) / "summary.json";
  json rec;
  try {
    std::ifstream f(summary);
    if (f) rec = json::parse(f);
  } catch (const std::exception&) {
    rec = json();
  }
  const bool ok = rec.is_array() && !rec.empty();
  json out = {{"seed", job.seed}, {"variant", job.variant}, {"dir", job.dir}};
  if (!ok) {
    out["passed"] = false;
    out["error"] = "sim_demo exit status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
                   ", no summary (see " + (fs::path(job.dir) / "log.txt").string() + ")";
    return out;
  }
  const json& r = rec[0];
  if (job.margin) {
    const json& d = r["directions"][0];
    out["direction"] = d["direction"];
    out["value"] = d["largest_passed"];
    out["unit"] = d["unit"];
    out["first_failure"] = d["smallest_failed"];
    return out;
  }
  out["passed"] = r["passed"];
  out["max_torso_pitch_deg"] = r["max_torso_pitch_deg"];
  out["max_torso_roll_deg"] = r["max_torso_roll_deg"];
  out["zmp_margin_mm"] = r["zmp_margin_mm"];
  std::string reason;
  if (r["fell"].get<bool>()) {
    char b[160];
    std::snprintf(b, sizeof(b), "fell at %.2f s (%s)", r["fall_time"].get<double>(),
                  r["fall_reason"].get<std::string>().c_str());
    reason = b;
  } else if (!r["zmp_inside"].get<bool>()) {
    reason = "ZMP left a sole";
  }
  for (const auto& x : r["rules"]) {
    if (x["passed"].get<bool>()) continue;
    char b[160];
    std::snprintf(b, sizeof(b), "%s %.3g%s%s", x["rule"].get<std::string>().c_str(), x["value"].get<double>(),
                  x["unit"].get<std::string>().empty() ? "" : " ", x["unit"].get<std::string>().c_str());
    reason += (reason.empty() ? "" : "; ") + std::string(b);
  }
  out["reason"] = reason;
  return out;
}

std::string fmt(const char* f, double x) {
  char b[64];
  std::snprintf(b, sizeof(b), f, x);
  return b;
}

}  // namespace

RobustnessMatrix loadRobustnessMatrix(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    fail(path, e.what());
  }
  if (!root.IsMap()) fail(path, "expected a map (seeds, noise, controllers, perturbations, experiments)");
  RobustnessMatrix m;
  try {
    for (const auto& kv : root) {
      const std::string key = kv.first.as<std::string>();
      if (key != "seeds" && key != "noise" && key != "controllers" && key != "perturbations" && key != "experiments" &&
          key != "margins" && key != "push_resolution" && key != "skate_resolution") {
        fail(path, "unknown key '" + key + "'");
      }
    }
    if (root["seeds"]) m.seeds = root["seeds"].as<std::vector<unsigned>>();
    if (root["noise"]) m.noise = root["noise"].as<bool>();
    if (root["controllers"]) m.controllers = root["controllers"].as<std::vector<std::string>>();
    if (root["margins"]) m.margins = root["margins"].as<bool>();
    if (root["push_resolution"]) m.push_resolution = root["push_resolution"].as<double>();
    if (root["skate_resolution"]) m.skate_resolution = root["skate_resolution"].as<double>();
  } catch (const YAML::Exception& e) {
    fail(path, std::string("bad value: ") + e.what());
  }
  if (m.seeds.empty()) fail(path, "'seeds' is empty");
  for (const std::string& c : m.controllers) {
    if (c != "hqp" && c != "wqp") fail(path, "controller '" + c + "' (expected hqp or wqp)");
  }
  const YAML::Node ps = root["perturbations"], es = root["experiments"];
  if (!ps || !ps.IsSequence() || ps.size() == 0) fail(path, "'perturbations' must be a non-empty list");
  if (!es || !es.IsSequence() || es.size() == 0) fail(path, "'experiments' must be a non-empty list");
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const std::string where = "perturbations[" + std::to_string(i) + "]";
    if (!ps[i]["name"]) fail(path, where + ": missing 'name'");
    RobustnessPerturbation p{ps[i]["name"].as<std::string>(), assignments(ps[i]["set"], path, where + ".set")};
    ScenarioParams check = presetScenario("stand");
    applyAll(check, p.set, path, where + " (" + p.name + ")");
    m.perturbations.push_back(p);
  }
  for (std::size_t i = 0; i < es.size(); ++i) {
    const std::string where = "experiments[" + std::to_string(i) + "]";
    const YAML::Node e = es[i];
    if (!e["scenario"]) fail(path, where + ": missing 'scenario'");
    RobustnessExperiment x;
    x.scenario = e["scenario"].as<std::string>();
    x.name = e["name"] ? e["name"].as<std::string>() : x.scenario;
    x.set = assignments(e["set"], path, where + ".set");
    if (e["variants"]) {
      if (!e["variants"].IsSequence()) fail(path, where + ".variants: expected a list of maps");
      for (std::size_t v = 0; v < e["variants"].size(); ++v) {
        x.variants.push_back(assignments(e["variants"][v], path, where + ".variants[" + std::to_string(v) + "]"));
      }
    }
    if (e["margin"]) x.margin = e["margin"].as<std::string>();
    ScenarioParams p;
    try {
      p = presetScenario(x.scenario);
    } catch (const std::invalid_argument& err) {
      fail(path, where + ": " + err.what());
    }
    if (p.sweep || p.ablation || p.robustness) fail(path, where + ": '" + x.scenario + "' is not a single-run scenario");
    applyAll(p, x.set, path, where + " (" + x.name + ")");
    for (const Assignments& v : x.variants) {
      ScenarioParams pv = p;
      applyAll(pv, v, path, where + " (" + x.name + ") variant");
    }
    if (!x.margin.empty()) {
      const bool skate = x.margin.rfind("skate:", 0) == 0;
      ScenarioParams s = presetScenario(skate ? "skate_sweep" : "push_sweep");
      applyAll(s, {{"sweep_directions", skate ? x.margin.substr(6) : x.margin}}, path, where + ".margin");
    }
    m.experiments.push_back(x);
  }
  return m;
}

json runRobustness(const RobustnessMatrix& m, const std::string& exe, const std::vector<std::string>& common,
                   const std::string& out, int jobs) {
  if (jobs <= 0) jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const auto wall0 = std::chrono::steady_clock::now();
  json cells = json::array();
  std::vector<Job> queue;
  for (const std::string& c : m.controllers) {
    for (std::size_t pi = 0; pi < m.perturbations.size(); ++pi) {
      const RobustnessPerturbation& pert = m.perturbations[pi];
      for (std::size_t ei = 0; ei < m.experiments.size(); ++ei) {
        const RobustnessExperiment& e = m.experiments[ei];
        const std::size_t cell = cells.size();
        cells.push_back({{"controller", c},
                         {"perturbation", pert.name},
                         {"experiment", e.name},
                         {"runs", json::array()},
                         {"margin", nullptr}});
        const std::string base = (fs::path(out) / "cells" / (c + "_p" + std::to_string(pi) + "_e" + std::to_string(ei))).string();
        const int nv = std::max<int>(1, static_cast<int>(e.variants.size()));
        for (unsigned seed : m.seeds) {
          for (int v = 0; v < nv; ++v) {
            Job j;
            j.cell = cell;
            j.seed = seed;
            j.variant = e.variants.empty() ? -1 : v;
            j.dir = base + "_s" + std::to_string(seed) + (e.variants.empty() ? "" : "_v" + std::to_string(v));
            j.args = common;
            for (const char* a : {"--no-video", "--no-plots"}) j.args.push_back(a);
            j.args.insert(j.args.end(), {"--scenario", e.scenario, "--out", j.dir, "--set", "controller=" + c, "--set",
                                         std::string("noise=") + (m.noise ? "true" : "false"), "--set",
                                         "seed=" + std::to_string(seed)});
            addSets(j.args, e.set);
            if (!e.variants.empty()) addSets(j.args, e.variants[static_cast<std::size_t>(v)]);
            addSets(j.args, pert.set);
            queue.push_back(j);
          }
        }
        if (m.margins && !e.margin.empty()) {
          const bool skate = e.margin.rfind("skate:", 0) == 0;
          Job j;
          j.cell = cell;
          j.margin = true;
          j.seed = m.seeds.front();
          j.dir = base + "_margin";
          j.args = common;
          for (const char* a : {"--no-video", "--no-plots"}) j.args.push_back(a);
          j.args.insert(j.args.end(),
                        {"--scenario", skate ? "skate_sweep" : "push_sweep", "--out", j.dir, "--set", "controller=" + c,
                         "--set", std::string("noise=") + (m.noise ? "true" : "false"), "--set",
                         "seed=" + std::to_string(j.seed), "--set",
                         "sweep_directions=" + (skate ? e.margin.substr(6) : e.margin), "--set",
                         "sweep_resolution=" + fmt("%g", skate ? m.skate_resolution : m.push_resolution)});
          addSets(j.args, pert.set);
          queue.push_back(j);
        }
      }
    }
  }
  // Margin sweeps take several runs each: start them first so that they do not finish last alone.
  std::stable_partition(queue.begin(), queue.end(), [](const Job& j) { return j.margin; });

  const bool tty = isatty(fileno(stdout));
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0, done = 0, failed = 0;
  auto progress = [&](bool final_line) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    const double left = done > 0 ? s / done * (queue.size() - done) : 0.0;
    std::printf("%s  robustness: %zu / %zu runs done (%zu failed), %zu running, %.0f s elapsed, ~%.0f s left%s",
                tty ? "\r" : "", done, queue.size(), failed, running.size(), s, left, tty && !final_line ? "" : "\n");
    std::fflush(stdout);
  };
  std::printf("robustness: %zu cells, %zu runs (margin sweeps included), %d at a time\n", cells.size(), queue.size(), jobs);
  while (next < queue.size() || !running.empty()) {
    while (next < queue.size() && static_cast<int>(running.size()) < jobs) {
      fs::create_directories(queue[next].dir);
      running[spawn(exe, queue[next].args, (fs::path(queue[next].dir) / "log.txt").string())] = next;
      ++next;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) throw std::runtime_error("robustness: waitpid failed");
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const Job& job = queue[it->second];
    running.erase(it);
    json r = readChild(job, status);
    if (job.margin) {
      cells[job.cell]["margin"] = r;
    } else {
      if (!r["passed"].get<bool>()) ++failed;
      cells[job.cell]["runs"].push_back(r);
    }
    ++done;
    if (tty || done % 10 == 0 || done == queue.size()) progress(done == queue.size());
  }
  bool all_passed = true;
  for (json& c : cells) {
    long passed = 0;
    for (const json& r : c["runs"]) passed += r["passed"].get<bool>() ? 1 : 0;
    c["passed"] = passed;
    c["total"] = c["runs"].size();
    c["pass_rate"] = c["runs"].empty() ? 0.0 : static_cast<double>(passed) / c["runs"].size();
    all_passed = all_passed && passed == static_cast<long>(c["runs"].size());
  }
  json record = {{"scenario", "robustness"},
                 {"passed", all_passed},
                 {"seeds", m.seeds},
                 {"noise", m.noise},
                 {"controllers", m.controllers},
                 {"perturbations", json::array()},
                 {"experiments", json::array()},
                 {"wall_time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count()},
                 {"cells", cells}};
  for (const auto& p : m.perturbations) {
    json sets = json::object();
    for (const auto& [k, v] : p.set) sets[k] = v;
    record["perturbations"].push_back({{"name", p.name}, {"set", sets}});
  }
  for (const auto& e : m.experiments) {
    record["experiments"].push_back({{"name", e.name}, {"scenario", e.scenario}, {"margin", e.margin},
                                     {"variants", e.variants.size()}});
  }
  writeJson((fs::path(out) / "robustness.json").string(), record);
  writeText((fs::path(out) / "robustness.md").string(), robustnessMarkdown(record));
  return record;
}

std::string robustnessMarkdown(const json& record) {
  std::ostringstream s;
  s << "# Robustness matrix\n\nPass rate per cell over " << record["seeds"].size() << " noise seed(s)"
    << (record["noise"].get<bool>() ? " (sensor noise on)" : " (noise off)")
    << " and each experiment's variants, with the stricter pass rules; after the dot, the margin: the largest "
       "push (N·s) or board peak velocity (m/s, rad/s) survived in a sweep of that cell (first seed). "
    << fmt("%.0f", record["wall_time_s"].get<double>()) << " s wall.\n";
  for (const auto& c : record["controllers"]) {
    s << "\n## " << c.get<std::string>() << "\n\n| experiment |";
    for (const auto& p : record["perturbations"]) s << " " << p["name"].get<std::string>() << " |";
    s << "\n|---|";
    for (std::size_t i = 0; i < record["perturbations"].size(); ++i) s << "---|";
    s << "\n";
    for (const auto& e : record["experiments"]) {
      s << "| " << e["name"].get<std::string>() << " |";
      for (const auto& p : record["perturbations"]) {
        for (const auto& cell : record["cells"]) {
          if (cell["controller"] != c || cell["experiment"] != e["name"] || cell["perturbation"] != p["name"]) continue;
          const long passed = cell["passed"].get<long>(), total = cell["total"].get<long>();
          s << " " << (passed == total ? "**" : "") << passed << "/" << total << (passed == total ? "**" : "");
          const json& mg = cell["margin"];
          if (mg.is_object() && mg.contains("value")) {
            s << " · " << fmt("%.2f", mg["value"].get<double>()) << " " << mg["unit"].get<std::string>();
          }
          s << " |";
        }
      }
      s << "\n";
    }
  }
  s << "\n## Failed runs\n\n";
  bool any = false;
  for (const auto& cell : record["cells"]) {
    for (const auto& r : cell["runs"]) {
      if (r["passed"].get<bool>()) continue;
      any = true;
      s << "- " << cell["controller"].get<std::string>() << ", " << cell["experiment"].get<std::string>() << ", "
        << cell["perturbation"].get<std::string>() << ", seed " << r["seed"].get<unsigned>();
      if (r["variant"].get<int>() >= 0) s << ", variant " << r["variant"].get<int>();
      s << ": " << (r.contains("error") ? r["error"].get<std::string>() : r["reason"].get<std::string>()) << "\n";
    }
  }
  if (!any) s << "none\n";
  return s.str();
}

}  // namespace hqp::sim
