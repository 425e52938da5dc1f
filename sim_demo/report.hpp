#pragma once
// What a scenario run leaves behind for a user (docs/scenarios.md): a JSON record per run, the
// console summary, and the markdown/JSON table over all runs of one invocation.

#include <nlohmann/json.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "push_sweep.hpp"
#include "run.hpp"
#include "scenario.hpp"

namespace hqp::sim {

nlohmann::ordered_json runRecord(const ScenarioParams& p, const RunSummary& r);
nlohmann::ordered_json sweepRecord(const ScenarioParams& p, const SweepResult& s);

// Human-readable summary of one record (run or sweep) on `out`.
void printRecord(std::FILE* out, const nlohmann::ordered_json& record);

// The summary table (markdown) of all records, with the paper's figures beside push_x.
std::string markdownTable(const std::vector<nlohmann::ordered_json>& records);

// Writes `path` (pretty JSON) and throws std::runtime_error when it cannot.
void writeJson(const std::string& path, const nlohmann::ordered_json& j);
void writeText(const std::string& path, const std::string& text);

}  // namespace hqp::sim
