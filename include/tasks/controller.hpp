#pragma once
// Controller: one 1 kHz tick from sensor data to motor currents (Fig. 2 of the paper):
// state estimator → RobotDynamics::calcWbcDependence → task planner (Sec. III-A) → task and
// constraint update (Table I) → HqpWbc or WqpWbc (Sec. IV-A) → τ_opt (eq. 6) → joint-level
// control (eqs. 5, 7, 8). tick() allocates nothing, throws nothing, does no I/O, and never emits
// a non-finite current: any failure switches to the safe mode of docs/controller.md.
// The hierarchy is a template argument (a definition, tasks/hierarchy.hpp; Table I by default):
// the solvers, the diagnostics' level count and task errors all follow from it.

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "tasks/balance_hierarchy.hpp"
#include "tasks/controller_config.hpp"
#include "tasks/controller_diagnostics.hpp"
#include "tasks/inverse_dynamics.hpp"
#include "tasks/joint_controller.hpp"
#include "tasks/references.hpp"
#include "tasks/sensor_data.hpp"
#include "tasks/state_estimator.hpp"
#include "tasks/task_planner.hpp"

namespace hqp::tasks {

template <class Layout, class Definition = BalanceHierarchy>
class Controller {
 public:
  using Robot = typename Layout::robot;
  static constexpr int nj = Layout::nj;
  static constexpr int nv = Layout::nv;
  static constexpr int nc = Layout::num_contacts;
  static constexpr int cd = Layout::contact_dim;
  static constexpr int nx = Layout::nx;
  static_assert(cd == 6, "the Controller drives flat feet (6-D contact wrenches)");
  using Dynamics = typename Layout::Dynamics;
  using Hierarchy = tasks::Hierarchy<Definition, Layout>;
  using Hqp = typename Hierarchy::Hqp;
  using Wqp = typename Hierarchy::Wqp;
  using Config = ControllerConfig<nj>;
  using Sensors = SensorData<nj, nc>;
  using Command = ActuatorCommand<nj>;
  using VectorJ = Eigen::Matrix<double, nj, 1>;
  using VectorX = Eigen::Matrix<double, nx, 1>;
  static constexpr int num_levels = Hqp::num_levels;
  static constexpr int max_active = Hqp::max_active;
  using Diagnostics = ControllerDiagnostics<num_levels, nc, max_active, Hierarchy::error_rows>;

  // Frames by index into Robot::frames: the soles (contact frames), the F/T sensors, and the
  // IMU (on the torso; the torso-posture task uses it). Configuration is applied here, once.
  Controller(const Config& config, const std::array<int, nc>& sole_frames,
             const std::array<int, nc>& ft_frames, int imu_frame)
      : config_(config),
        dyn_(dynamicsFrames(sole_frames, imu_frame)),
        estimator_(sole_frames, ft_frames, imu_frame),
        hqp_(config.qp.hqp),
        wqp_(config.qp.wqp, config.wqp_priority_ratio) {
    wqp_.setWarmStart(config.qp.wqp_warm_start);
    wqp_.setDualMethod(config.qp.wqp_dual_method);
    estimator_.configure(config_.estimator);
    planner_.configure(config_.planner, Robot::total_mass, config_.dt);
    joint_.configure(config_.joint);
    config_.balance.dt = config_.dt;
    configureHierarchy(hqp_, config_.balance);
    configureHierarchy(wqp_, config_.balance);
    reset();
  }

  // Back to the state after construction: estimator, planner and ∫q̈ dt re-initialise on the
  // next tick, warm starts are dropped, and the safe mode is left.
  void reset() noexcept {
    estimator_.reset();
    planner_.reset();
    hqp_.resetWarmStart();
    resetHierarchyState(hqp_);
    resetHierarchyState(wqp_);
    started_ = false;
    diag_ = Diagnostics{};
    diag_.task_error_offset = Hierarchy::error_offset;
    tau_hold_.setZero();
    dq_last_.setZero();
  }

  // The safe mode latches: only reset() leaves it (a robot that fell or whose sensors failed
  // must be looked at before it balances again).
  void tick(const Sensors& s, Command& cmd) noexcept {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    auto lap = t0;
    auto stage = [&](Stage st) {
      const auto now = Clock::now();
      diag_.time_us[static_cast<int>(st)] = std::chrono::duration<double, std::micro>(now - lap).count();
      lap = now;
    };
    diag_.time_us.fill(0.0);
    diag_.cut_level = -1;  // set by recordSolver() on ticks that reach the solver
    ++diag_.ticks;
    const double dt = config_.dt;

    if (diag_.mode == ControllerMode::Safe) return safeCommand(s, cmd, t0);

    // 1. State estimator.
    if (!estimator_.update(s, dt)) return enterSafeMode(SafeModeReason::NonFiniteSensor, s, cmd, t0);
    dq_last_ = s.dq;
    stage(Stage::Estimator);

    // 2. Dynamics: M, h, J, J̇v, CoM, A_G (Sec. IV-A).
    dyn_.calcWbcDependence(estimator_.q(), estimator_.v());
    stage(Stage::Dynamics);
    if (fallen()) return enterSafeMode(SafeModeReason::Fallen, s, cmd, t0);

    // 3. Task planner (Sec. III-A).
    std::array<Eigen::Vector2d, nc> cop;
    std::array<bool, nc> contact;
    std::array<Eigen::Vector3d, nc> support_acceleration;
    for (int c = 0; c < nc; ++c) {
      cop[c] = estimator_.cop(c);
      contact[c] = estimator_.inContact(c);
      support_acceleration[c] = estimator_.supportAcceleration(c);
      refs_.contact_load[c] = estimator_.soleWrench(c)[2];
    }
    planner_.update(dyn_, cop, contact, refs_, &support_acceleration);
    stage(Stage::Planner);

    // 4.–5. Tasks and constraints (Table I), then the hierarchy (eqs. 3–4).
    VectorX x;
    QpStatus status;
    const RobotState<Robot> state{estimator_.q(), estimator_.v()};
    if (config_.solver == Config::Solver::Hqp) {
      updateHierarchy(hqp_, dyn_, refs_, state);
      stage(Stage::TaskUpdate);
      status = hqp_.solve();
      x = hqp_.x();
    } else {
      updateHierarchy(wqp_, dyn_, refs_, state);
      stage(Stage::TaskUpdate);
      status = wqp_.solve();
      x = wqp_.x();
    }
    stage(Stage::Solve);
    recordSolver(status);
    if (!solutionUsable(x)) return enterSafeMode(SafeModeReason::SolverFailure, s, cmd, t0);

    // 6. Joint level: τ_opt (eq. 6), then eqs. 5, 7, 8.
    const VectorJ tau_opt = jointTorque<Layout>(dyn_, x);
    const VectorJ ddq_opt = x.template segment<nj>(6);
    if (!started_) {
      joint_.reset(s.dq);
      started_ = true;
    }
    joint_.compute(tau_opt, ddq_opt, s.dq, dt, cmd);
    if (!joint_.status().input_finite || !cmd.current.allFinite() || !cmd.torque.allFinite())
      return enterSafeMode(SafeModeReason::NonFiniteOutput, s, cmd, t0);
    cmd.safe_mode = false;
    tau_hold_ = tau_opt;
    diag_.current_saturated = joint_.status().num_saturated > 0;
    stage(Stage::JointControl);

    recordContacts(x);
    diag_.time_us[static_cast<int>(Stage::Total)] =
        std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
  }

  const Diagnostics& diagnostics() const { return diag_; }
  const Config& config() const { return config_; }
  const Dynamics& dynamics() const { return dyn_; }
  const StateEstimator<Robot, nc>& estimator() const { return estimator_; }
  const References<nc>& references() const { return refs_; }
  const Hqp& hqp() const { return hqp_; }
  const Wqp& wqp() const { return wqp_; }
  // x* = [q̈*; F*] of the last tick that ran the solver.
  const VectorX& solution() const {
    return config_.solver == Config::Solver::Hqp ? hqp_.x() : wqp_.x();
  }

  // f(item) on every task or constraint of type T in both solvers, for what configure(p) cannot
  // carry (a task's own reference or gains). Set-up time; not in the tick.
  template <class T, class F>
  void configureItems(F f) {
    forEachItemOfType<T>(hqp_, f);
    forEachItemOfType<T>(wqp_, f);
  }

 private:
  static std::array<int, nc + 1> dynamicsFrames(const std::array<int, nc>& soles, int imu) {
    std::array<int, nc + 1> f{};
    for (int c = 0; c < nc; ++c) f[c] = soles[c];
    f[nc] = imu;
    return f;
  }
  // Torso tilt (angle between the torso z axis and world z) or torso height above the mean
  // sole height beyond the limits of SafeModeParameters.
  bool fallen() const {
    const Eigen::Matrix3d& R = dyn_.placement(nc).linear();
    const double tilt = std::acos(std::clamp(R(2, 2), -1.0, 1.0));
    double sole_z = 0.0;
    for (int c = 0; c < nc; ++c) sole_z += dyn_.placement(c).translation().z();
    sole_z /= nc;
    const double height = dyn_.placement(nc).translation().z() - sole_z;
    return tilt > config_.safe.max_tilt || height < config_.safe.min_base_height;
  }

  // Level 1 (the dynamics) must be optimal; lower levels may stop at their iteration cap
  // (their iterate is feasible and higher levels are kept) or be cut by the budget (never
  // level 1); a numerical failure or invalid
  // input anywhere, a higher level degraded by the lower ones (numerical health) or a
  // non-finite x is a failure.
  bool solutionUsable(const VectorX& x) const {
    if (!x.allFinite()) return false;
    if (diag_.levels[0].status != QpStatus::Optimal) return false;
    if (diag_.higher_level_degraded) return false;
    for (const auto& l : diag_.levels)
      if (l.status == QpStatus::NumericalFailure || l.status == QpStatus::InvalidInput) return false;
    return true;
  }

  void recordSolver(QpStatus status) {
    diag_.status = status;
    diag_.higher_level_degraded = false;
    diag_.cut_level = -1;
    if (config_.solver == Config::Solver::Hqp) {
      const auto& r = hqp_.result();
      diag_.higher_level_degraded = r.higher_level_degraded;
      diag_.cut_level = r.cut_level;
      if (r.cut_level >= 0) ++diag_.budget_cuts;
      for (int p = 0; p < num_levels; ++p) {
        const auto& src = r.levels[p];
        auto& dst = diag_.levels[p];
        dst.status = src.status;
        dst.residual = src.residual;
        dst.iterations = src.iterations;
        dst.rank = src.rank;
        dst.num_active = src.num_active;
        dst.time_us = src.time_us;
        for (int k = 0; k < src.num_active; ++k) dst.active_row[k] = src.active_row[k];
      }
    } else {
      const auto& r = wqp_.result();
      for (int p = 0; p < num_levels; ++p) {
        auto& dst = diag_.levels[p];
        dst.status = r.status;
        dst.residual = r.residual[p];
        dst.iterations = r.iterations;
        dst.rank = 0;
        dst.num_active = 0;
        dst.time_us = 0.0;
      }
      for (int k = 0; k < r.num_active; ++k) {
        const int row = r.active_row[k];
        int p = 0;
        while (p + 1 < num_levels && row >= Wqp::constraint_offset[p + 1]) ++p;
        auto& dst = diag_.levels[p];
        dst.active_row[dst.num_active++] = row;
      }
    }
  }

  // ZMPs, task errors, contact flags (diagnostics only).
  void recordContacts(const VectorX& x) {
    for (int c = 0; c < nc; ++c) {
      diag_.in_contact[c] = estimator_.inContact(c);
      diag_.following[c] = planner_.inSafeRegion(c);
      diag_.zmp_measured[c] = estimator_.cop(c);
      const Eigen::Matrix<double, 6, 1> F = x.template segment<6>(Layout::forceIndex(c));
      const Eigen::Matrix3d Rt = dyn_.placement(c).linear().transpose();
      const Eigen::Vector3d f = Rt * F.template head<3>();
      const Eigen::Vector3d m = Rt * F.template tail<3>();
      // CoP of a wrench about the sole origin, in the sole frame: p = (−m_y, m_x) / f_z.
      diag_.zmp_optimized[c] =
          f.z() > 1e-9 ? Eigen::Vector2d(-m.y() / f.z(), m.x() / f.z()) : Eigen::Vector2d::Zero();
      diag_.force_error[c] = F - refs_.contact_force[c];
    }
    taskErrors();
  }

  void taskErrors() {
    if (config_.solver == Config::Solver::Hqp) taskErrorsOf(hqp_);
    else taskErrorsOf(wqp_);
  }
  // Every task's error by level, and the balance tasks' by name wherever their level is.
  template <class Wbc>
  void taskErrorsOf(const Wbc& wbc) {
    stackTaskErrors(wbc, diag_.task_error);
    if (const auto* t = findTask<ContactPoseTask<Layout>>(wbc))
      for (int c = 0; c < nc; ++c) diag_.foot_error[c] = t->error().template segment<6>(6 * c);
    if (const auto* t = findTask<LinearMomentumTask<Layout>>(wbc)) diag_.com_error = t->error();
    if (const auto* t = findTask<TorsoPostureTask<Layout>>(wbc)) diag_.torso_error = t->error();
  }

  // Safe mode: τ = τ_hold − d q̇ (the last good torques, damped), k_f = 0, no ∫q̈ dt.
  template <class TimePoint>
  void enterSafeMode(SafeModeReason why, const Sensors& s, Command& cmd, TimePoint t0) {
    diag_.mode = ControllerMode::Safe;
    diag_.reason = why;
    safeCommand(s, cmd, t0);
  }
  template <class TimePoint>
  void safeCommand(const Sensors& s, Command& cmd, TimePoint t0) {
    for (int j = 0; j < nj; ++j) {
      const double dq = std::isfinite(s.dq(j)) ? s.dq(j) : dq_last_(j);
      if (std::isfinite(s.dq(j))) dq_last_(j) = s.dq(j);
      double tau = tau_hold_(j) - config_.safe.damping * dq;
      if (!std::isfinite(tau)) tau = 0.0;
      const double kt = config_.joint.torque_constant[j];
      const double lim = config_.joint.current_limit[j];
      cmd.current(j) = std::clamp(tau / kt, -lim, lim);
      cmd.torque(j) = cmd.current(j) * kt;
    }
    cmd.safe_mode = true;
    diag_.time_us[static_cast<int>(Stage::Total)] =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  }

  Config config_;
  Dynamics dyn_;
  StateEstimator<Robot, nc> estimator_;
  TaskPlanner<nc> planner_;
  JointController<nj> joint_;
  Hqp hqp_;
  Wqp wqp_;
  References<nc> refs_;
  Diagnostics diag_;
  VectorJ tau_hold_ = VectorJ::Zero();  // last good τ_opt (safe mode holds it, damped)
  VectorJ dq_last_ = VectorJ::Zero();   // last finite joint rates
  bool started_ = false;
};

}  // namespace hqp::tasks
