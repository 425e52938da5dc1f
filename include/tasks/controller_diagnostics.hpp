#pragma once
// What one Controller::tick() did: mode, each level's QP outcome, the optimized and measured ZMP of
// each foot, the task errors and the time of each stage. Filled in place; no heap.

#include <Eigen/Core>

#include <array>

#include "hqp/qp_status.hpp"

namespace hqp::tasks {

enum class ControllerMode : int {
  Balance = 0,  // the hierarchy runs and commands the joints
  Safe,         // joint damping around the last good torques (docs/controller.md, "Safe mode")
};

enum class SafeModeReason : int {
  None = 0,
  NonFiniteSensor,  // a NaN/inf in the sensor data
  SolverFailure,    // level 1 not optimal, a numerical failure or invalid input, a higher level
                    // degraded by lower ones (numerical health), or a non-finite solution
  Fallen,           // torso tilt or torso height beyond SafeModeParameters
  NonFiniteOutput,  // the joint-level command was not finite (never sent)
};

inline const char* toString(SafeModeReason r) {
  switch (r) {
    case SafeModeReason::None: return "None";
    case SafeModeReason::NonFiniteSensor: return "NonFiniteSensor";
    case SafeModeReason::SolverFailure: return "SolverFailure";
    case SafeModeReason::Fallen: return "Fallen";
    case SafeModeReason::NonFiniteOutput: return "NonFiniteOutput";
  }
  return "Unknown";
}

// Stages of one tick, in data-flow order (docs/architecture.md, "One control tick").
enum class Stage : int { Estimator = 0, Dynamics, Planner, TaskUpdate, Solve, JointControl, Total, Count };

// One priority level as solved this tick. For WqpWbc every level reports the single QP's
// status and iterations; active rows are attributed to the level that owns them.
template <int MaxActive>
struct LevelDiagnostics {
  QpStatus status = QpStatus::Optimal;
  double residual = 0.0;  // ‖A_p x* − b_p‖²
  int iterations = 0;
  int rank = 0;           // rank of the projected task (HqpWbc only; 0 for WqpWbc)
  int num_active = 0;     // constraint rows at a bound
  std::array<int, MaxActive> active_row{};  // index into the stacked constraint rows
  double time_us = 0.0;   // this level's solve time (HqpWbc only; 0 for WqpWbc, one QP)
};

// TaskErrorRows: all levels' task errors stacked (Hierarchy::error_rows).
template <int NumLevels, int NumContacts, int MaxActive, int TaskErrorRows = 0>
struct ControllerDiagnostics {
  using TaskErrors = Eigen::Matrix<double, (TaskErrorRows > 0 ? TaskErrorRows : 1), 1>;
  ControllerDiagnostics() {
    task_error.setZero();
    for (auto& z : zmp_measured) z.setZero();
    for (auto& z : zmp_optimized) z.setZero();
    for (auto& e : foot_error) e.setZero();
    for (auto& e : force_error) e.setZero();
  }

  ControllerMode mode = ControllerMode::Balance;
  SafeModeReason reason = SafeModeReason::None;
  long ticks = 0;                  // ticks since construction or reset()
  QpStatus status = QpStatus::Optimal;  // the solver's overall status this tick
  // HqpWbc's numerical health: some level's residual was raised beyond tolerance by the lower
  // levels (HqpResult::higher_level_degraded); the tick counts as a solver failure.
  bool higher_level_degraded = false;
  // HqpWbc's per-tick budget (qp.hqp.budget_us / budget_iterations): the first level it cut this
  // tick (−1: none; that level and all below have status BudgetCut), and the ticks cut so far.
  int cut_level = -1;
  long budget_cuts = 0;
  std::array<LevelDiagnostics<MaxActive>, NumLevels> levels{};
  std::array<bool, NumContacts> in_contact{};       // estimator: F/T normal force above threshold
  std::array<bool, NumContacts> following{};        // planner: ZMP in the safe region (Sec. III-A)
  std::array<Eigen::Vector2d, NumContacts> zmp_measured{};   // sole frame (m)
  std::array<Eigen::Vector2d, NumContacts> zmp_optimized{};  // from F*, sole frame (m)
  // Task errors (reference − current), as the tasks used them this tick: every task's error() in
  // priority order, level p in rows [task_error_offset[p], task_error_offset[p + 1]).
  TaskErrors task_error;
  std::array<int, NumLevels + 1> task_error_offset{};
  auto levelTaskError(int p) const {
    return task_error.segment(task_error_offset[p], task_error_offset[p + 1] - task_error_offset[p]);
  }
  // The same errors of the balance tasks by name (zero if the hierarchy lacks the task).
  std::array<Eigen::Matrix<double, 6, 1>, NumContacts> foot_error{};  // [position; rotation vector]
  Eigen::Vector3d com_error = Eigen::Vector3d::Zero();
  Eigen::Vector3d torso_error = Eigen::Vector3d::Zero();     // rotation vector, world
  std::array<Eigen::Matrix<double, 6, 1>, NumContacts> force_error{};  // F* − F_ref
  std::array<double, static_cast<int>(Stage::Count)> time_us{};        // per stage, this tick
  bool current_saturated = false;  // some joint's current command was clamped
};

}  // namespace hqp::tasks
