// The balance controller (include/tasks/controller.hpp) as the simulation's driver. The only
// translation unit of sim_demo that instantiates the hierarchy (it is expensive to compile).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "hqp/problem_file.hpp"
#include "hqp/problem_instance.hpp"
#include "recording.hpp"
#include "run.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/controller.hpp"
#include "tasks/controller_config_yaml.hpp"

namespace hqp::sim {

namespace {

using Layout = hqp::tasks::ContactLayout<Robot, kContacts, 6>;
using BalanceController = hqp::tasks::Controller<Layout>;

class BalanceDriver final : public Driver {
 public:
  explicit BalanceDriver(const hqp::tasks::ControllerConfig<kJoints>& config)
      : controller_(std::make_unique<BalanceController>(
            config, std::array<int, kContacts>{Robot::Frames::l_sole, Robot::Frames::r_sole},
            std::array<int, kContacts>{Robot::Frames::l_ft_sensor, Robot::Frames::r_ft_sensor}, Robot::Frames::imu)),
        name_(config.solver == hqp::tasks::ControllerConfig<kJoints>::Solver::Hqp ? "balance controller (HQP)"
                                                                                    : "balance controller (WQP)") {}
  const char* name() const override { return name_; }
  void reset() override {
    controller_->reset();
    tick_ = 0;
    used_ = 0;
  }
  void tick(const Sensors& s, Command& cmd) override {
    // Recording (docs/recording.md): the incoming working sets before the tick, the problem
    // and its result after it, into the preallocated buffer (fixed-size copies, no heap).
    const bool rec = used_ < buffer_.size() && tick_ >= rec_first_ && tick_ < rec_end_ &&
                     (tick_ - rec_first_) % rec_every_ == 0;
    if (rec) hqp::captureWarmStart(controller_->hqp(), buffer_[used_]);
    controller_->tick(s, cmd);
    // The solve stage's clock is set only on ticks that reached the solver (not in safe mode).
    const auto& d = controller_->diagnostics();
    if (rec && d.time_us[static_cast<int>(hqp::tasks::Stage::Solve)] > 0.0) {
      auto& in = buffer_[used_++];
      hqp::captureProblem(controller_->hqp(), in);
      in.tick = tick_;
      in.time = static_cast<double>(tick_) * controller_->config().dt;
    }
    ++tick_;
  }
  bool safeMode() const override {
    return controller_->diagnostics().mode == hqp::tasks::ControllerMode::Safe;
  }
  std::string logHeader() const override {
    std::string h = ",ctrl_status";
    for (int l = 1; l <= BalanceController::num_levels; ++l) {
      h += ",level" + std::to_string(l) + "_status,level" + std::to_string(l) + "_residual,level" +
           std::to_string(l) + "_active";
    }
    for (const char* f : {"l", "r"}) {
      const std::string p = std::string(",") + f;
      h += p + "_in_contact" + p + "_following" + p + "_zmp_meas_x" + p + "_zmp_meas_y" + p + "_zmp_opt_x" + p +
           "_zmp_opt_y";
    }
    h += ",com_err_x,com_err_y,com_err_z,torso_err_x,torso_err_y,torso_err_z,current_saturated";
    // State estimate (world axes): base velocity, per foot trust, moving flag, support velocity.
    h += ",est_base_vx,est_base_vy,est_base_vz,est_accel_bias_x,est_accel_bias_y,est_accel_bias_z";
    h += ",est_L_x,est_L_y,est_L_z";  // centroidal angular momentum of the estimate (N·m·s, world)
    for (const char* f : {"l", "r"}) {
      const std::string p = std::string(",") + f;
      h += p + "_trust" + p + "_moving" + p + "_support_vx" + p + "_support_vy" + p + "_support_vz";
    }
    return h;
  }
  bool solverStatus(SolverStatus& st) const override {
    const auto& d = controller_->diagnostics();
    st.num_levels = std::min<int>(BalanceController::num_levels, kMaxLevels);
    for (int l = 0; l < st.num_levels; ++l) {
      st.level_status[l] = static_cast<int>(d.levels[l].status);
      st.level_residual[l] = d.levels[l].residual;
    }
    for (int c = 0; c < kContacts; ++c) {
      st.zmp_optimized[c] = d.in_contact[c] ? d.zmp_optimized[c]
                                            : Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
    return true;
  }
  bool jointTargets(JointTargets& t) const override {
    if (controller_->diagnostics().mode != hqp::tasks::ControllerMode::Balance) return false;
    const auto& x = controller_->solution();
    t.tau_opt = hqp::tasks::jointTorque<Layout>(controller_->dynamics(), x);  // eq. 6, as the tick did
    t.ddq_opt = x.template segment<kJoints>(6);
    return true;
  }
  bool estimate(EstimateSample& e) const override {
    if (controller_->diagnostics().mode != hqp::tasks::ControllerMode::Balance) return false;
    const auto& est = controller_->estimator();
    const auto& q = est.q();
    e.base_position = q.template head<3>();
    e.base_orientation = Eigen::Quaterniond(q[3], q[4], q[5], q[6]);
    e.base_velocity = e.base_orientation * Eigen::Vector3d(est.v().template head<3>());
    e.com = controller_->dynamics().com();
    e.com_velocity = controller_->dynamics().vcom();
    for (int c = 0; c < kContacts; ++c) {
      e.in_contact[c] = est.inContact(c);
      e.support_velocity[c] = est.supportVelocity(c);
    }
    return true;
  }
  void logRow(std::FILE* f) const override {
    const auto& d = controller_->diagnostics();
    std::fprintf(f, ",%d", static_cast<int>(d.status));
    for (const auto& l : d.levels) std::fprintf(f, ",%d,%.6g,%d", static_cast<int>(l.status), l.residual, l.num_active);
    for (int c = 0; c < kContacts; ++c) {
      std::fprintf(f, ",%d,%d,%.5f,%.5f,%.5f,%.5f", d.in_contact[c] ? 1 : 0, d.following[c] ? 1 : 0,
                   d.zmp_measured[c].x(), d.zmp_measured[c].y(), d.zmp_optimized[c].x(), d.zmp_optimized[c].y());
    }
    std::fprintf(f, ",%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d", d.com_error.x(), d.com_error.y(), d.com_error.z(),
                 d.torso_error.x(), d.torso_error.y(), d.torso_error.z(), d.current_saturated ? 1 : 0);
    const auto& est = controller_->estimator();
    const auto& q = est.q();
    const Eigen::Vector3d vb =
        Eigen::Quaterniond(q[3], q[4], q[5], q[6]) * Eigen::Vector3d(est.v().template head<3>());
    const Eigen::Vector3d ab = est.accelerometerBias();
    std::fprintf(f, ",%.5f,%.5f,%.5f,%.5f,%.5f,%.5f", vb.x(), vb.y(), vb.z(), ab.x(), ab.y(), ab.z());
    const Eigen::Vector3d L = controller_->dynamics().hg().template tail<3>();
    std::fprintf(f, ",%.4f,%.4f,%.4f", L.x(), L.y(), L.z());
    for (int c = 0; c < kContacts; ++c) {
      const Eigen::Vector3d& vs = est.supportVelocity(c);
      std::fprintf(f, ",%.3f,%d,%.5f,%.5f,%.5f", est.footTrust(c), est.footMoving(c) ? 1 : 0, vs.x(), vs.y(), vs.z());
    }
  }

  bool startRecording(const RecordOptions& o) {
    if (controller_->config().solver != hqp::tasks::ControllerConfig<kJoints>::Solver::Hqp) return false;
    if (o.every < 1 || o.duration <= 0.0 || o.start < 0.0) throw std::runtime_error("--record: bad window");
    const double dt = controller_->config().dt;
    rec_ = o;
    rec_first_ = std::lround(o.start / dt);
    rec_every_ = o.every;
    const long ticks = std::lround(o.duration / dt);
    rec_end_ = rec_first_ + ticks;
    buffer_.assign(static_cast<std::size_t>((ticks + o.every - 1) / o.every), Instance{});  // ~19 kB each
    used_ = 0;
    return true;
  }
  std::size_t finishRecording() const {
    if (rec_.file.empty()) return 0;
    hqp::writeProblemFile<BalanceController::Hqp>(rec_.file, buffer_.data(), used_, controller_->hqp().settings(),
                                                  rec_.source);
    return used_;
  }

 private:
  using Instance = hqp::ProblemInstance<BalanceController::Hqp>;
  std::unique_ptr<BalanceController> controller_;  // large: keep it off the stack
  const char* name_;
  std::vector<Instance> buffer_;  // sized by startRecording(), before the run
  std::size_t used_ = 0;
  long tick_ = 0, rec_first_ = 0, rec_end_ = 0, rec_every_ = 1;
  RecordOptions rec_;
};

}  // namespace

std::unique_ptr<Driver> makeBalanceController(const std::string& config_path, bool wqp,
                                              const ControllerOverrides& overrides) {
  auto config = hqp::tasks::loadControllerConfig<Robot>(config_path);
  using Solver = hqp::tasks::ControllerConfig<kJoints>::Solver;
  config.solver = wqp ? Solver::Wqp : Solver::Hqp;
  auto& joint = config.joint;
  if (overrides.k_f >= 0.0) joint.k_f.setConstant(overrides.k_f);
  joint.k_dq *= overrides.kinematic_compensation;
  using Method = hqp::tasks::EstimatorParameters::Method;
  if (overrides.estimator == "stance") config.estimator.method = Method::Stance;
  else if (overrides.estimator == "kinematic_inertial") config.estimator.method = Method::KinematicInertial;
  for (int j = 0; j < kJoints; ++j) {
    auto& f = joint.friction[static_cast<std::size_t>(j)];
    if (overrides.plant_friction) {
      f.coulomb = overrides.coulomb[j];
      f.viscous = overrides.viscous[j];
    }
    f.coulomb *= overrides.friction_model_scale;
    f.viscous *= overrides.friction_model_scale;
  }
  return std::make_unique<BalanceDriver>(config);
}

bool balanceControllerAvailable() { return true; }

bool startRecording(Driver& driver, const RecordOptions& options) {
  auto* d = dynamic_cast<BalanceDriver*>(&driver);
  return d != nullptr && d->startRecording(options);
}

std::size_t finishRecording(Driver& driver) {
  auto* d = dynamic_cast<BalanceDriver*>(&driver);
  return d != nullptr ? d->finishRecording() : 0;
}

}  // namespace hqp::sim
