#pragma once
// Everything the Controller is configured with, as plain data (no yaml-cpp here,
// so firmware need not link it; controller_config_yaml.hpp reads it from
// robots/<robot>/controller.yaml at start-up). Units SI. The YAML keys and the
// reason for every Walker3 value: robots/walker3/controller.yaml, docs/controller.md.

#include <cstddef>

#include "hqp/hqp_wbc.hpp"
#include "hqp/qp_settings.hpp"
#include "tasks/balance_parameters.hpp"
#include "tasks/joint_controller.hpp"
#include "tasks/state_estimator.hpp"
#include "tasks/task_planner.hpp"

namespace hqp::tasks {

// Safe mode (docs/controller.md): joint damping around the last good gravity compensation.
struct SafeModeParameters {
  double damping = 5.0;          // N·m·s/rad, joint damping in safe mode
  double min_base_height = 0.5;  // m, base below this (world z) counts as fallen
  double max_tilt = 0.8;         // rad, base tilt from upright beyond this counts as fallen
};

// The solvers' settings (YAML section `qp`); the defaults are HqpSettings' and QpSettings'.
struct SolverSettings {
  HqpSettings hqp{};             // HqpWbc: every level's QP (hqp.qp) and the hierarchy's options
  QpSettings wqp{};              // WqpWbc's single QP
  bool wqp_warm_start = true;    // WqpWbc::setWarmStart
  bool wqp_dual_method = true;   // WqpWbc::setDualMethod
};

template <int NJ>
struct ControllerConfig {
  enum class Solver { Hqp, Wqp };
  Solver solver = Solver::Hqp;      // strict hierarchy (HqpWbc) or weighted (WqpWbc)
  double dt = 0.001;                // s, control period
  double wqp_priority_ratio = 1e3;  // WqpWbc: each level weighs this much more than the next
  BalanceParameters<NJ> balance;
  PlannerParameters planner;
  EstimatorParameters estimator;
  JointControlParameters<NJ> joint;
  SafeModeParameters safe;
  SolverSettings qp;
};

// A configuration from the URDF alone (no YAML): torque limits = effort, friction
// = URDF friction/damping, k_t = 1 N·m/A (current = torque) limited at the effort,
// full friction compensation, no kinematic compensation. For tests and bring-up.
template <class Robot>
ControllerConfig<Robot::nj> defaultControllerConfig() {
  ControllerConfig<Robot::nj> c;
  c.balance = defaultBalanceParameters<Robot>();
  constexpr int first = Robot::floating_base ? 1 : 0;
  for (int j = 0; j < Robot::nj; ++j) {
    const auto& b = Robot::bodies[static_cast<std::size_t>(j + first)];
    c.joint.friction[static_cast<std::size_t>(j)] = JointFriction{b.friction, b.damping, 0.05};
    c.joint.current_limit[j] = b.effort;
  }
  return c;
}

}  // namespace hqp::tasks
