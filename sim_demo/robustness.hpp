#pragma once
// The robustness matrix (docs/scenarios.md, "Robustness matrix"): the paper's experiments x plant
// perturbations x controllers x noise seeds, each run a sim_demo process of its own, several at
// a time. Per cell: the pass rate over the seeds (and variants), and the margin: the largest push
// or board velocity survived (a push_sweep or skate_sweep of that cell). The matrix is a YAML file
// (robots/walker3/robustness.yaml). Not real-time code.

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace hqp::sim {

using Assignments = std::vector<std::pair<std::string, std::string>>;  // (key, value) as --set takes them

struct RobustnessExperiment {
  std::string name;                   // row label
  std::string scenario;               // a single-run preset (not a sweep)
  Assignments set;                    // overrides of that preset
  std::vector<Assignments> variants;  // each variant is one run per seed (none: one run per seed)
  // Margin sweep: "" (none), a push direction ("+x", "-y", "+x-y", ...) or "skate:AXIS".
  std::string margin;
};

struct RobustnessPerturbation {
  std::string name;  // column label
  Assignments set;   // plant perturbations or controller overrides
};

struct RobustnessMatrix {
  std::vector<unsigned> seeds = {1, 2, 3};
  bool noise = true;
  std::vector<std::string> controllers = {"hqp", "wqp"};
  std::vector<RobustnessExperiment> experiments;
  std::vector<RobustnessPerturbation> perturbations;
  bool margins = true;                       // run the margin sweeps
  double push_resolution = 0.5;              // N·s, margin bisection
  double skate_resolution = 0.05;            // fraction of the paper's peak velocity
};

// Reads and checks the matrix: every scenario name and every key=value is applied to its preset
// here, so that a typo fails before any run. Throws std::invalid_argument naming the file and entry.
RobustnessMatrix loadRobustnessMatrix(const std::string& path);

// Runs the matrix: `exe` is sim_demo itself, `common` the arguments every child gets (paths of the
// scene, plant and controller files). Children write to out/cells/<id>/ (log.txt, summary.json).
// jobs <= 0: one per core. Prints a progress line to stdout. Returns the JSON record (cells with
// their runs, pass rates and margins); writes out/robustness.json and out/robustness.md.
nlohmann::ordered_json runRobustness(const RobustnessMatrix& m, const std::string& exe,
                                     const std::vector<std::string>& common, const std::string& out, int jobs);

// The markdown report of a record: one pass-rate table per controller, then each failed run.
std::string robustnessMarkdown(const nlohmann::ordered_json& record);

}  // namespace hqp::sim
