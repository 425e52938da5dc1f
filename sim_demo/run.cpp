#include "run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <vector>

#include "video_recorder.hpp"

namespace hqp::sim {

namespace {

class JointPdDriver final : public Driver {
 public:
  JointPdDriver(const VectorJ& q_ref, const VectorJ& k_t, double kp, double kd)
      : q_ref_(q_ref), k_t_(k_t), kp_(kp), kd_(kd) {}
  const char* name() const override { return "joint PD"; }
  void reset() override {}
  void tick(const Sensors& s, Command& cmd) override {
    cmd.torque = kp_ * (q_ref_ - s.q) - kd_ * s.dq;
    cmd.current = cmd.torque.cwiseQuotient(k_t_);
    cmd.safe_mode = false;
  }

 private:
  VectorJ q_ref_, k_t_;
  double kp_, kd_;
};

// A CSV file with one row per tick (docs/simulation.md lists the columns).
class CsvLog {
 public:
  CsvLog(const std::string& path, const Driver& driver, const std::vector<SupportMotion>& supports)
      : f_(std::fopen(path.c_str(), "w")), driver_(driver) {
    if (!f_) throw std::runtime_error("cannot write " + path);
    std::setvbuf(f_, nullptr, _IOFBF, 1 << 20);
    std::fprintf(f_, "time");
    for (int i = 0; i < kJoints; ++i) std::fprintf(f_, ",q_%s", Robot::bodies[i + 1].joint);
    for (int i = 0; i < kJoints; ++i) std::fprintf(f_, ",tau_%s", Robot::bodies[i + 1].joint);
    for (const char* foot : {"l", "r"}) {
      for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"}) std::fprintf(f_, ",%s_ft_%s", foot, c);
    }
    std::fprintf(f_, ",l_cop_x,l_cop_y,r_cop_x,r_cop_y,torso_pitch,torso_roll,torso_z,com_x,com_y,com_z,"
                     "l_foot_pitch,l_foot_roll,r_foot_pitch,r_foot_roll,push_fx,push_fy,push_fz,ball_px,ball_py,ball_pz,tick_us,safe_mode");
    // Moving supports: foot yaw and sole velocity (world), then each driven support's position.
    std::fprintf(f_, ",l_foot_yaw,r_foot_yaw,base_vx,base_vy,base_vz");
    for (const char* foot : {"l", "r"}) {
      for (const char* c : {"wx", "wy", "wz", "vx", "vy", "vz"}) std::fprintf(f_, ",%s_foot_%s", foot, c);
    }
    for (const SupportMotion& m : supports) std::fprintf(f_, ",support_%s", m.axis.c_str());
    std::fprintf(f_, "%s", driver_.logHeader().c_str());
    for (int i = 0; i < kJoints; ++i) std::fprintf(f_, ",tau_err_%s", Robot::bodies[i + 1].joint);
    std::fprintf(f_, ",l_sole_slide,r_sole_slide,l_sole_tilt,r_sole_tilt");
    std::fputc('\n', f_);
  }
  ~CsvLog() { std::fclose(f_); }
  void row(const Simulation& sim, const Sensors& s, const Eigen::Vector3d& push, double tick_us, bool safe,
           const std::vector<int>& support_actuators) {
    std::fprintf(f_, "%.4f", s.time);
    const VectorJ q = sim.jointPositions(), tau = sim.appliedTorque();
    for (int i = 0; i < kJoints; ++i) std::fprintf(f_, ",%.6f", q[i]);
    for (int i = 0; i < kJoints; ++i) std::fprintf(f_, ",%.4f", tau[i]);
    for (int c = 0; c < kContacts; ++c) {
      for (int k = 0; k < 6; ++k) std::fprintf(f_, ",%.4f", s.ft[c][k]);
    }
    for (int c = 0; c < kContacts; ++c) {
      const Eigen::Vector2d cop = sim.copInSole(c, s.ft[c]);
      std::fprintf(f_, ",%.5f,%.5f", cop.x(), cop.y());
    }
    const Eigen::Vector3d com = sim.centerOfMass();
    const Eigen::Vector3d ball = sim.ballMomentum();
    std::fprintf(f_, ",%.6f,%.6f,%.6f,%.6f,%.6f,%.6f", sim.torsoPitch(), sim.torsoRoll(), sim.torsoHeight(), com.x(),
                 com.y(), com.z());
    for (int c = 0; c < kContacts; ++c) std::fprintf(f_, ",%.6f,%.6f", sim.footPitch(c), sim.footRoll(c));
    std::fprintf(f_, ",%.2f,%.2f,%.2f,%.4f,%.4f,%.4f,%.2f,%d", push.x(), push.y(), push.z(), ball.x(), ball.y(), ball.z(),
                 tick_us, safe ? 1 : 0);
    std::fprintf(f_, ",%.6f,%.6f", sim.footYaw(0), sim.footYaw(1));
    const double* vb = sim.data()->qvel + sim.baseDofAdr();  // free joint: world linear
    std::fprintf(f_, ",%.5f,%.5f,%.5f", vb[0], vb[1], vb[2]);
    for (int c = 0; c < kContacts; ++c) {
      const Vector6 v = sim.footVelocity(c);
      for (int k = 0; k < 6; ++k) std::fprintf(f_, ",%.5f", v[k]);
    }
    for (int a : support_actuators) std::fprintf(f_, ",%.6f", sim.supportPosition(a));
    driver_.logRow(f_);
  }
  // The row's last columns, known only after the step: τ_opt − delivered torque (NaN: no τ_opt),
  // each sole's slide on its support since loaded (m) and tilt to it (rad) (NaN: unloaded).
  void endRow(const VectorJ& tau_err, const std::array<double, kContacts>& slide,
              const std::array<double, kContacts>& tilt) {
    for (int i = 0; i < kJoints; ++i) std::fprintf(f_, ",%.4f", tau_err[i]);
    std::fprintf(f_, ",%.6f,%.6f,%.6f,%.6f", slide[0], slide[1], tilt[0], tilt[1]);
    std::fputc('\n', f_);
  }

 private:
  std::FILE* f_;
  const Driver& driver_;
};

}  // namespace

std::unique_ptr<Driver> makeJointPdDriver(const Simulation& sim, double kp, double kd) {
  return std::make_unique<JointPdDriver>(sim.standingPose(), sim.torqueConstant(), kp, kd);
}

RunSummary runScenario(Simulation& sim, Driver& driver, const RunOptions& o) {
  RunSummary r;
  r.driver = driver.name();
  std::unique_ptr<CsvLog> log;
  std::unique_ptr<VideoRecorder> video;
  if (!o.out_dir.empty()) {
    std::filesystem::create_directories(o.out_dir);
    r.csv_path = o.out_dir + "/" + o.scenario + ".csv";
    log = std::make_unique<CsvLog>(r.csv_path, driver, o.supports);
    if (o.video) {
      r.video_path = o.out_dir + "/" + o.scenario + ".mp4";
      video = std::make_unique<VideoRecorder>(sim.model(), r.video_path, o.video_width, o.video_height, o.video_fps,
                                              mj_name2id(sim.model(), mjOBJ_BODY, Robot::bodies[0].name), o.scenario);
    }
  }
  std::vector<int> support_actuators;
  for (const SupportMotion& m : o.supports) support_actuators.push_back(sim.supportActuator(m.axis));
  sim.reset();
  driver.reset();
  const long ticks = std::lround(o.duration / sim.controlDt());
  std::vector<double> tick_us;
  tick_us.reserve(static_cast<std::size_t>(ticks));
  Sensors s;
  Command cmd;
  double next_frame = 0.0;
  long next_progress = std::lround(1.0 / sim.controlDt());
  const auto wall0 = std::chrono::steady_clock::now();
  double video_s = 0.0;
  for (int c = 0; c < kContacts; ++c) {
    r.cop_min[c].setConstant(std::numeric_limits<double>::infinity());
    r.cop_max[c].setConstant(-std::numeric_limits<double>::infinity());
  }
  const Eigen::Vector3d com0 = sim.centerOfMass();
  std::vector<double> push_times;  // PassRules::com_return: the pushes in time order
  for (const Push& p : o.pushes) push_times.push_back(p.time);
  std::sort(push_times.begin(), push_times.end());
  std::size_t next_push = 0;  // the first of them not yet reached
  Eigen::Vector2d com_rest0 = Eigen::Vector2d::Zero();
  double com_return = 0.0;
  std::array<double, kContacts> foot_pitch0{}, foot_roll0{}, zmp_sq_sum{};
  std::array<long, kContacts> zmp_tracked{};
  for (int c = 0; c < kContacts; ++c) {
    foot_pitch0[c] = sim.footPitch(c);
    foot_roll0[c] = sim.footRoll(c);
    r.zmp_margin[c] = std::numeric_limits<double>::infinity();
    r.foot_angular_velocity_peak[c].setZero();
    r.foot_linear_velocity_peak[c].setZero();
  }
  std::array<double, kContacts> foot_yaw0{};
  for (int c = 0; c < kContacts; ++c) foot_yaw0[c] = sim.footYaw(c);
  // First-order low-pass of the foot velocities for their peaks (the paper filters at 20 Hz).
  const double lp_alpha = sim.controlDt() / (sim.controlDt() + 1.0 / (2.0 * M_PI * o.foot_velocity_cutoff));
  std::array<Vector6, kContacts> foot_v_lp;
  for (int c = 0; c < kContacts; ++c) foot_v_lp[c].setZero();
  SolverStatus solver;
  JointTargets targets;
  long tau_ticks = 0;
  double lowest_error_sum = 0.0;
  long solver_ticks = 0;
  // Delivered ball impulse: momentum at launch (straight flight) minus momentum when the ball
  // leaves the robot. 0: idle, 1: flying, 2: touching the robot.
  int ball_state = 0;
  Eigen::Vector3d ball_p0 = Eigen::Vector3d::Zero();
  EstimateSample est;
  Eigen::Vector3d est_p0 = Eigen::Vector3d::Zero(), est_com0 = Eigen::Vector3d::Zero();
  bool est_started = false;
  // Contact quality (PassRules): the body each loaded sole stands on and where it was loaded.
  std::array<int, kContacts> anchor_body{-1, -1};
  std::array<Eigen::Vector2d, kContacts> anchor;
  for (long k = 0; k < ticks; ++k) {
    sim.readSensors(s);
    const auto t0 = std::chrono::steady_clock::now();
    driver.tick(s, cmd);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    tick_us.push_back(us);
    if (driver.safeMode()) ++r.safe_mode_ticks;
    if (driver.estimate(est)) {
      // Truth of the state the sensors were read from (before this tick's step).
      const mjData* d = sim.data();
      const double* qp = d->qpos + sim.baseQposAdr();
      const Eigen::Vector3d p_true(qp[0], qp[1], qp[2]);
      const Eigen::Quaterniond quat_true(qp[3], qp[4], qp[5], qp[6]);
      const Eigen::Vector3d v_true(d->qvel + sim.baseDofAdr());  // free joint: world-frame linear
      mj_subtreeVel(sim.model(), sim.data());
      const Eigen::Vector3d com_true = sim.centerOfMass(), vcom_true = sim.centerOfMassVelocity();
      if (!est_started) {
        est_p0 = est.base_position - p_true;
        est_com0 = est.com - com_true;
        est_started = true;
      }
      auto& a = r.estimator;
      a.available = true;
      a.base_position.add((est.base_position - est_p0 - p_true).norm());
      a.base_velocity.add((est.base_velocity - v_true).norm());
      a.orientation.add(est.base_orientation.angularDistance(quat_true));
      a.com.add((est.com - est_com0 - com_true).norm());
      a.com_velocity.add((est.com_velocity - vcom_true).norm());
      for (int c = 0; c < kContacts; ++c) {
        if (!est.in_contact[c] || !(sim.wrenchInSole(c, sim.trueForceTorque(c))[2] >= o.zmp_min_fz)) continue;
        a.support_velocity.add((est.support_velocity[c] - sim.footVelocity(c).tail<3>()).norm());
      }
    }
    sim.applyCommand(cmd);
    for (std::size_t i = 0; i < o.supports.size(); ++i) {
      double q = 0.0, dq = 0.0;
      supportTarget(o.supports[i], sim.time(), q, dq);
      sim.setSupportTarget(support_actuators[i], q, dq);
    }
    Eigen::Vector3d push = Eigen::Vector3d::Zero();
    while (next_push < push_times.size() && sim.time() + 1e-9 >= push_times[next_push]) {
      // Where the CoM rests just before this push.
      const Eigen::Vector2d c = sim.centerOfMass().head<2>();
      if (next_push == 0) com_rest0 = c;
      else com_return = std::max(com_return, (c - com_rest0).norm());
      ++next_push;
    }
    for (const Push& p : o.pushes) {
      if (p.ball) {
        if (std::abs(sim.time() - p.time) < 0.5 * sim.controlDt()) {
          if (!sim.hasBall()) throw std::runtime_error("the scene has no ball to throw");
          sim.launchBall(p.impulse);
          ball_p0 = sim.ballMomentum();
          ball_state = 1;
        }
      } else if (sim.time() + 1e-9 >= p.time && sim.time() + 1e-9 < p.time + p.duration) {
        push += p.impulse / p.duration;
      }
    }
    sim.setTorsoForce(push);
    if (log) log->row(sim, s, push, us, driver.safeMode(), support_actuators);
    if (video && sim.time() + 1e-9 >= next_frame) {
      const auto v0 = std::chrono::steady_clock::now();
      // Name the latest push for 0.6 s: a force push is invisible otherwise.
      std::string caption;
      for (const Push& p : o.pushes) {
        if (sim.time() >= p.time && sim.time() < p.time + 0.6) {
          char c[96];
          std::snprintf(c, sizeof(c), "push %.1f Ns %s%s", p.impulse.norm(),
                        p.impulse.x() != 0 && p.impulse.y() != 0 ? "" : (p.impulse.x() + p.impulse.y() > 0 ? "+" : "-"),
                        p.impulse.y() == 0 ? "X" : p.impulse.x() == 0 ? "Y" : "(XY)");
          caption = c;
        }
      }
      video->frame(sim.data(), caption);
      video_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - v0).count();
      next_frame += 1.0 / o.video_fps;
    }
    const bool has_solver = driver.solverStatus(solver);
    if (has_solver) {
      r.num_levels = std::min(solver.num_levels, kMaxLevels);
      for (int l = 0; l < r.num_levels; ++l) {
        const int st = solver.level_status[l];
        if (st >= 0 && st < RunSummary::kStatuses) ++r.level_status_counts[l][st];
      }
      for (int l = 0; l < r.num_levels; ++l) {
        if (solver.level_status[l] != 0) {  // QpStatus::Optimal
          ++r.non_optimal_ticks;
          break;
        }
      }
      if (r.num_levels > 0) {
        const double e = solver.level_residual[r.num_levels - 1];
        r.lowest_level_error_max = std::max(r.lowest_level_error_max, e);
        lowest_error_sum += e;
        ++solver_ticks;
      }
    }
    for (int c = 0; c < kContacts; ++c) {
      // Judged on the noise-free F/T wrench (with --set noise=true the controller sees the noisy one).
      const Vector6 ft = sim.trueForceTorque(c);
      const Eigen::Vector2d cop = sim.copInSole(c, ft);
      if (!cop.allFinite()) continue;
      r.cop_min[c] = r.cop_min[c].cwiseMin(cop);
      r.cop_max[c] = r.cop_max[c].cwiseMax(cop);
      if (!(sim.wrenchInSole(c, ft)[2] >= o.zmp_min_fz)) continue;  // unloaded: no ZMP to check
      const auto& rect = sim.soleRectangle(c);
      const double margin = std::min({cop.x() - rect[0].x(), rect[1].x() - cop.x(), cop.y() - rect[0].y(),
                                      rect[1].y() - cop.y()});
      r.zmp_margin[c] = std::min(r.zmp_margin[c], margin);
      if (margin < o.zmp_edge) r.zmp_edge_time[c] += sim.controlDt();
      if (margin < -o.zmp_tolerance) r.zmp_inside = false;
      if (has_solver && solver.zmp_optimized[c].allFinite()) {
        zmp_sq_sum[c] += (cop - solver.zmp_optimized[c]).squaredNorm();
        ++zmp_tracked[c];
      }
    }
    VectorJ dq0;
    for (int i = 0; i < kJoints; ++i) dq0[i] = sim.data()->qvel[sim.jointDofAdr(i)];
    sim.step();
    VectorJ tau_err = VectorJ::Constant(std::numeric_limits<double>::quiet_NaN());
    if (driver.jointTargets(targets)) {
      tau_err = targets.tau_opt - sim.deliveredTorque();
      for (int i = 0; i < kJoints; ++i) {
        const int dof = sim.jointDofAdr(i);
        const double ddq = (sim.data()->qvel[dof] - dq0[i]) / sim.controlDt();
        r.torque_tracking_link_rms += std::pow(tau_err[i] + sim.model()->dof_armature[dof] * ddq, 2);
      }
      r.torque_tracking_rms_joint += tau_err.cwiseAbs2();
      r.torque_tracking_max = std::max(r.torque_tracking_max, tau_err.cwiseAbs().maxCoeff());
      ++tau_ticks;
    }
    if (ball_state > 0) {
      const bool touching = sim.ballTouchesRobot();
      if (ball_state == 1 && touching) ball_state = 2;
      if (ball_state == 2 && !touching) {
        r.ball_impulse += ball_p0 - sim.ballMomentum();
        ball_state = 0;
      }
    }

    if (sim.feetTouch()) ++r.feet_touch_ticks;
    std::array<double, kContacts> slide_now, tilt_now;
    slide_now.fill(std::numeric_limits<double>::quiet_NaN());
    tilt_now.fill(std::numeric_limits<double>::quiet_NaN());
    for (int c = 0; c < kContacts; ++c) {
      const int b = sim.soleSupport(c);
      if (b < 0 || !(sim.wrenchInSole(c, sim.trueForceTorque(c))[2] >= o.zmp_min_fz)) {
        anchor_body[c] = -1;  // unloaded: a new slide starts where it lands again
        continue;
      }
      const Eigen::Isometry3d T = sim.soleInBody(c, b);
      const double tilt = std::acos(std::clamp(T.linear()(2, 2), -1.0, 1.0));  // between the z axes
      r.max_foot_tilt[c] = std::max(r.max_foot_tilt[c], tilt);
      if (tilt > o.rules.foot_tilt_angle) r.foot_tilt_time[c] += sim.controlDt();
      const Eigen::Vector2d p = T.translation().head<2>();  // in the support's plane
      if (anchor_body[c] != b) {
        anchor_body[c] = b;
        anchor[c] = p;
      }
      slide_now[c] = (p - anchor[c]).norm();
      tilt_now[c] = tilt;
      r.sole_slide[c] = std::max(r.sole_slide[c], slide_now[c]);
    }
    if (log) log->endRow(tau_err, slide_now, tilt_now);
    const Eigen::Vector3d com_d = sim.centerOfMass() - com0;
    r.com_x_min = std::min(r.com_x_min, com_d.x());
    r.com_x_max = std::max(r.com_x_max, com_d.x());
    r.com_y_min = std::min(r.com_y_min, com_d.y());
    r.com_y_max = std::max(r.com_y_max, com_d.y());
    for (int c = 0; c < kContacts; ++c) {
      r.max_abs_foot_pitch[c] = std::max(r.max_abs_foot_pitch[c], std::abs(sim.footPitch(c) - foot_pitch0[c]));
      r.max_abs_foot_roll[c] = std::max(r.max_abs_foot_roll[c], std::abs(sim.footRoll(c) - foot_roll0[c]));
      r.max_abs_foot_yaw[c] = std::max(r.max_abs_foot_yaw[c], std::abs(sim.footYaw(c) - foot_yaw0[c]));
      foot_v_lp[c] += lp_alpha * (sim.footVelocity(c) - foot_v_lp[c]);
      // Only what the robot withstood: the peaks stop at the first ZMP outside a sole (a fall
      // would add the falling foot's own motion).
      if (!r.zmp_inside) continue;
      r.foot_angular_velocity_peak[c] = r.foot_angular_velocity_peak[c].cwiseMax(foot_v_lp[c].head<3>().cwiseAbs());
      r.foot_linear_velocity_peak[c] = r.foot_linear_velocity_peak[c].cwiseMax(foot_v_lp[c].tail<3>().cwiseAbs());
    }
    const double pitch = sim.torsoPitch(), roll = sim.torsoRoll(), z = sim.torsoHeight();
    r.max_abs_pitch = std::max(r.max_abs_pitch, std::abs(pitch));
    r.max_abs_roll = std::max(r.max_abs_roll, std::abs(roll));
    r.min_torso_height = std::min(r.min_torso_height, z);
    r.duration = sim.time();
    if (!r.fell) {
      if (z < o.fall_height) {
        char b[48];
        std::snprintf(b, sizeof(b), "torso below %.2f m", o.fall_height);
        r.fall_reason = b;
      }
      else if (std::abs(pitch) > o.fall_tilt || std::abs(roll) > o.fall_tilt) r.fall_reason = "torso tilt";
      else if (sim.nonFootContact()) r.fall_reason = "contact other than the soles";
      if (!r.fall_reason.empty()) {
        r.fell = true;
        r.fall_time = sim.time();
        if (video) {  // the run stops here: the video shows where and why
          const auto v0 = std::chrono::steady_clock::now();
          video->fall(sim.data(), r.fall_time, r.fall_reason);
          video_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - v0).count();
        }
        break;
      }
    }
    if (o.progress && k + 1 == next_progress) {
      std::printf("  t = %5.1f / %.1f s  pitch %6.2f deg  roll %6.2f deg  torso z %.3f m\n", sim.time(), o.duration,
                  pitch * 180 / M_PI, roll * 180 / M_PI, z);
      std::fflush(stdout);
      next_progress += std::lround(1.0 / sim.controlDt());
    }
  }
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  for (int c = 0; c < kContacts; ++c) {
    if (!std::isfinite(r.zmp_margin[c])) r.zmp_margin[c] = std::numeric_limits<double>::quiet_NaN();  // never loaded
    r.zmp_tracking_rms[c] = zmp_tracked[c] > 0 ? std::sqrt(zmp_sq_sum[c] / zmp_tracked[c])
                                               : std::numeric_limits<double>::quiet_NaN();
  }
  for (ErrorStats* e : {&r.estimator.base_position, &r.estimator.base_velocity, &r.estimator.orientation,
                        &r.estimator.com, &r.estimator.com_velocity, &r.estimator.support_velocity})
    e->finish();
  if (solver_ticks > 0) r.lowest_level_error_mean = lowest_error_sum / solver_ticks;
  if (tau_ticks > 0) {
    r.torque_tracking_rms = std::sqrt(r.torque_tracking_rms_joint.sum() / (kJoints * tau_ticks));
    r.torque_tracking_link_rms = std::sqrt(r.torque_tracking_link_rms / (kJoints * tau_ticks));
    r.torque_tracking_rms_joint = (r.torque_tracking_rms_joint / tau_ticks).cwiseSqrt();
  } else {
    r.torque_tracking_rms = r.torque_tracking_max = r.torque_tracking_link_rms = std::numeric_limits<double>::quiet_NaN();
    r.torque_tracking_rms_joint.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  auto rule = [&](const char* name, double value, double threshold, const char* unit) {
    r.rules.push_back({name, value, threshold, unit, value <= threshold});
  };
  rule("foot_tilt_time", std::max(r.foot_tilt_time[0], r.foot_tilt_time[1]), o.rules.foot_tilt_time, "s");
  rule("sole_slide", std::max(r.sole_slide[0], r.sole_slide[1]), o.rules.sole_slide, "m");
  rule("feet_touch_time", r.feet_touch_ticks * sim.controlDt(), o.rules.feet_touch_time, "s");
  rule("non_optimal_ticks", static_cast<double>(r.non_optimal_ticks), static_cast<double>(o.rules.non_optimal_ticks), "");
  rule("safe_mode_ticks", static_cast<double>(r.safe_mode_ticks), static_cast<double>(o.rules.safe_mode_ticks), "");
  if (o.supports.empty() && next_push > 0 && !r.fell) {
    r.com_return = std::max(com_return, (sim.centerOfMass().head<2>() - com_rest0).norm());
    if (std::isfinite(o.rules.com_return)) rule("com_return", r.com_return, o.rules.com_return, "m");
  }
  r.passed = !r.fell && r.zmp_inside;
  for (const RuleResult& x : r.rules) r.passed = r.passed && x.passed;
  // The real-time factor of the loop itself, without video rendering (which is offline work).
  r.real_time_factor = r.duration / std::max(1e-9, r.wall_time - video_s);
  if (!tick_us.empty()) {
    double sum = 0;
    for (double t : tick_us) sum += t;
    r.tick_mean_us = sum / tick_us.size();
    std::sort(tick_us.begin(), tick_us.end());
    r.tick_max_us = tick_us.back();
    r.tick_p999_us = tick_us[std::min(tick_us.size() - 1, static_cast<std::size_t>(0.999 * tick_us.size()))];
  }
  return r;
}

}  // namespace hqp::sim
