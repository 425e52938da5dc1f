#pragma once
// One simulated run: the 1 kHz loop sensors -> driver (controller) -> currents -> plant, with a
// CSV log, fall detection, timing and an optional video. Not real-time code.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "simulation.hpp"
#include "support_motion.hpp"

namespace hqp::sim {

constexpr int kMaxLevels = 8;

// One tick of a QP-based driver, as the run's metrics need it.
struct SolverStatus {
  int num_levels = 0;
  std::array<int, kMaxLevels> level_status{};        // hqp::QpStatus as int
  std::array<double, kMaxLevels> level_residual{};   // ||A x - b||^2 of each level's tasks
  std::array<Eigen::Vector2d, kContacts> zmp_optimized;  // from F*, sole frame (m)
};

// The controller's state estimate of one tick, world frame, for the accuracy metrics.
struct EstimateSample {
  Eigen::Vector3d base_position = Eigen::Vector3d::Zero();   // m
  Eigen::Vector3d base_velocity = Eigen::Vector3d::Zero();   // m/s, world axes
  Eigen::Quaterniond base_orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d com = Eigen::Vector3d::Zero();              // m
  Eigen::Vector3d com_velocity = Eigen::Vector3d::Zero();     // m/s
  std::array<Eigen::Vector3d, kContacts> support_velocity;    // m/s, world; loaded feet only
  std::array<bool, kContacts> in_contact{};
};

// RMS and largest error of one estimated quantity against MuJoCo's true state.
struct ErrorStats {
  double rms = 0, max = 0;
  long n = 0;
  void add(double e) {
    rms += e * e;  // sum of squares until finish()
    max = std::max(max, e);
    ++n;
  }
  void finish() { rms = n > 0 ? std::sqrt(rms / n) : std::numeric_limits<double>::quiet_NaN(); }
};

// Estimator accuracy over a run (docs/controller.md, "State estimator"). Positions are compared
// after removing the offset of the first tick (the estimator chooses its own world origin).
struct EstimatorAccuracy {
  bool available = false;
  ErrorStats base_position, base_velocity, orientation, com, com_velocity, support_velocity;
};

struct JointTargets {
  VectorJ tau_opt = VectorJ::Zero();  // N·m, eq. 6
  VectorJ ddq_opt = VectorJ::Zero();  // rad/s², q̈* (eqs. 7, 8 integrate it)
};

// What sits between the sensors and the motors. Virtual is fine here: this is the simulator,
// not the controller's real-time path.
class Driver {
 public:
  virtual ~Driver() = default;
  virtual const char* name() const = 0;
  virtual void reset() = 0;
  virtual void tick(const Sensors& s, Command& cmd) = 0;
  virtual bool safeMode() const { return false; }
  // Extra CSV columns of this driver (diagnostics): header text starting with ',' and one row.
  virtual std::string logHeader() const { return {}; }
  virtual void logRow(std::FILE*) const {}
  // This tick's solver outcome for the run's metrics; false for drivers without a QP.
  virtual bool solverStatus(SolverStatus&) const { return false; }
  // This tick's whole-body optimum as the joint level received it: τ_opt (eq. 6) and q̈*; false
  // for drivers without one (and in the controller's safe mode).
  virtual bool jointTargets(JointTargets&) const { return false; }
  // This tick's state estimate; false for drivers without one (and in safe mode).
  virtual bool estimate(EstimateSample&) const { return false; }
};

// Joint PD to the standing pose from encoder data only (the stand-in before the balance
// controller): τ = kp (q* − q) − kd q̇, current = τ / k_t.
std::unique_ptr<Driver> makeJointPdDriver(const Simulation& sim, double kp = 400.0, double kd = 10.0);

// The balance controller (include/tasks/controller.hpp) configured from a controller YAML file;
// nullptr when this build has no controller (HQP_SIM_WITH_CONTROLLER off).
// Scenario overrides of the YAML's joint friction compensation (eqs. 5, 7; scenario parameters
// friction_compensation, friction_model, friction_model_scale).
struct ControllerOverrides {
  double k_f = -1.0;                       // k_f of every joint; < 0 keeps the YAML's
  bool plant_friction = false;             // F_c, F_v := the plant's (the simulation's true friction)
  VectorJ coulomb = VectorJ::Zero();       // N·m, the plant's F_c (used with plant_friction)
  VectorJ viscous = VectorJ::Zero();       // N·m·s/rad, the plant's F_v (used with plant_friction)
  double friction_model_scale = 1.0;       // factor on the resulting F_c and F_v
  double kinematic_compensation = 1.0;     // factor on k_q̇ (eq. 8)
  std::string estimator = "config";        // config, stance or kinematic_inertial
};
std::unique_ptr<Driver> makeBalanceController(const std::string& config_path, bool wqp,
                                              const ControllerOverrides& overrides = {});
bool balanceControllerAvailable();

// An impulse on the torso: a constant force impulse / duration at the torso's centre of mass
// from `time` on (xfrc_applied).
// With `ball`, the scene's ball is thrown instead, with momentum `impulse` (what it would
// deliver if it stopped dead; Simulation::launchBall).
struct Push {
  double time = 1.0;                                    // s
  Eigen::Vector3d impulse = Eigen::Vector3d::Zero();    // N·s, world
  double duration = 0.01;                               // s
  bool ball = false;
};

// Pass rules beyond "no fall, ZMP inside the soles" (docs/scenarios.md, "Pass rules"): each is a
// named metric measured on every run, with the threshold that fails it.
struct PassRules {
  double foot_tilt_angle = 2.0 * M_PI / 180.0;  // rad: a loaded sole tilted more than this from its support is tilted
  double foot_tilt_time = 0.05;                  // s per foot of tilted time that fails the run
  double sole_slide = 0.005;                     // m: a loaded sole moved further than this on its support fails
  double feet_touch_time = 0.0;                  // s the two soles may touch each other
  long non_optimal_ticks = 0;                    // ticks with any hierarchy level not Optimal
  long safe_mode_ticks = 0;                      // ticks in the controller's safe mode
  // m: on still ground, the CoM (horizontal) just before each push after the first and at the
  // end may be at most this far from where it was just before the first push (infinity: off).
  double com_return = std::numeric_limits<double>::infinity();
};

// One rule's outcome in a run.
struct RuleResult {
  std::string name;  // foot_tilt_time, sole_slide, feet_touch_time, non_optimal_ticks, safe_mode_ticks, com_return
  double value = 0, threshold = 0;
  const char* unit = "";
  bool passed = true;
};

struct RunOptions {
  std::string scenario = "stand";
  double duration = 10.0;          // s
  std::string out_dir;             // CSV (and video) go here; empty: no files
  bool video = false;
  int video_width = 640, video_height = 480, video_fps = 30;
  double fall_height = 0.6;        // m, torso frame below this = fall
  double fall_tilt = 1.0;          // rad, torso pitch or roll beyond this = fall
  // A measured ZMP (F/T CoP) more than this outside its sole rectangle fails the run. A real ZMP
  // cannot leave the sole; the F/T one can, by the soft contact's penetration times the
  // tangential/normal force ratio when a foot loads its edge (observed up to ~2 mm while tipping).
  double zmp_tolerance = 0.003;    // m
  double zmp_edge = 0.002;         // m, a ZMP closer than this to the edge counts as "on the edge"
  double zmp_min_fz = 30.0;        // N, a foot is loaded (its ZMP counts) above this normal force
  bool progress = false;           // a progress line every simulated second
  std::vector<Push> pushes;
  // Moving supports: each tick, before the physics step, every listed servo gets its target
  // (supportTarget at the current time); the scene must have the named actuators.
  std::vector<SupportMotion> supports;
  double foot_velocity_cutoff = 20.0;  // Hz, low-pass of the foot velocity peaks (the paper's Fig. 11)
  PassRules rules;
};

struct RunSummary {
  std::string driver;
  double duration = 0;             // simulated s
  bool fell = false;
  double fall_time = -1;           // s, -1 when no fall
  std::string fall_reason;
  double max_abs_pitch = 0, max_abs_roll = 0;  // rad, torso
  double min_torso_height = 1e9;   // m
  double wall_time = 0;            // s
  double real_time_factor = 0;     // simulated / wall
  double tick_mean_us = 0, tick_max_us = 0, tick_p999_us = 0;  // driver compute time
  long safe_mode_ticks = 0;
  long feet_touch_ticks = 0;       // ticks with the two sole plates in contact with each other
  // m, PassRules::com_return's metric; NaN if no push was reached, after a fall, or on moving
  // supports (where the CoM follows the boards).
  double com_return = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d ball_impulse = Eigen::Vector3d::Zero();  // N·s the thrown balls lost (delivered)
  // Measured CoP (sole frame, from the noise-free F/T wrench) extremes per foot while loaded (f_z >= 10 N).
  std::array<Eigen::Vector2d, kContacts> cop_min, cop_max;
  double com_x_min = 0, com_x_max = 0;  // m, CoM x excursion relative to t = 0
  double com_y_min = 0, com_y_max = 0;  // m, CoM y excursion relative to t = 0
  // Feet (sole plates, world pitch/roll relative to t = 0): the paper's Fig. 8(a).
  std::array<double, kContacts> max_abs_foot_pitch{}, max_abs_foot_roll{};
  // Measured ZMP against the sole rectangle (the scene's sole plate): smallest distance to an
  // edge over the loaded ticks (negative: outside), time on the edge, and whether it stayed inside.
  std::array<double, kContacts> zmp_margin{};
  std::array<double, kContacts> zmp_edge_time{};          // s
  bool zmp_inside = true;
  // Measured minus optimized ZMP (RMS over the ticks both exist, m): torque-tracking quality.
  std::array<double, kContacts> zmp_tracking_rms{};
  // τ_opt minus the torque the plant delivered after its friction (Simulation::deliveredTorque),
  // over the ticks with a τ_opt (Driver::jointTargets; NaN without any): RMS over ticks and
  // joints, RMS per joint, largest |error| (N·m).
  double torque_tracking_rms = 0, torque_tracking_max = 0;
  VectorJ torque_tracking_rms_joint = VectorJ::Zero();
  // The same with the rotor inertia's torque (MuJoCo armature J_m N² times the tick's mean q̈)
  // also taken off, i.e. what reaches the links: the controller's rigid-body model has no rotors.
  double torque_tracking_link_rms = 0;
  // Solver: per level the count of ticks by status (hqp::QpStatus order), and the lowest level's
  // task error ||A x - b||^2 (the paper's Fig. 9(b)).
  int num_levels = 0;
  static constexpr int kStatuses = 5;  // hqp::QpStatus values, Optimal … InvalidInput
  std::array<std::array<long, kStatuses>, kMaxLevels> level_status_counts{};
  double lowest_level_error_max = 0, lowest_level_error_mean = 0;
  // Moving supports: per foot the peak |component| of the sole's velocity (ground truth from
  // MuJoCo, world axes, low-passed at foot_velocity_cutoff) until the first ZMP outside a sole
  // (what the robot withstood, not the fall), and its largest yaw change.
  std::array<Eigen::Vector3d, kContacts> foot_angular_velocity_peak, foot_linear_velocity_peak;
  std::array<double, kContacts> max_abs_foot_yaw{};
  EstimatorAccuracy estimator;  // base_position/com (m), velocities (m/s), orientation (rad)
  // Contact quality of each loaded foot (f_z >= zmp_min_fz) relative to the body it stands on
  // (floor, seesaw, board): time tilted beyond PassRules::foot_tilt_angle, largest tilt, and the
  // largest distance the sole origin moved on that body since it was loaded (m).
  std::array<double, kContacts> foot_tilt_time{}, max_foot_tilt{}, sole_slide{};
  long non_optimal_ticks = 0;  // ticks with any level's status other than Optimal
  std::vector<RuleResult> rules;
  // No fall, every loaded ZMP inside its sole (+ tolerance), and every rule passed.
  bool passed = false;
  std::string csv_path, video_path;
};

// Runs until `duration` or the first fall (the run stops there).
RunSummary runScenario(Simulation& sim, Driver& driver, const RunOptions& options);

}  // namespace hqp::sim
