// hqp_identify: the identification procedure of §V-B for one generated robot
// model (docs/identification.md).
//
//   hqp_identify --robot-urdf robot.urdf --trajectory excitation.csv
//       optimizes the Fourier excitation (condition number of the base
//       regressor, URDF limits, rest at start and end) and writes it sampled.
//   hqp_identify --robot-urdf robot.urdf --fit log.csv --out params.yaml
//       fits the base parameters (and the joint friction) to a measured log and
//       writes the friction for the controller; --validate other.csv reports
//       torque prediction errors, CAD vs identified, per joint.
//
// The model is compiled in (HQP_IDENTIFY_HEADER / HQP_IDENTIFY_ROBOT, set by
// hqp_add_identify_tool() in tools/identify/HqpIdentifyTool.cmake); the URDF
// given at run time is checked against it joint by joint, so a tool built for
// one robot refuses another robot's URDF. Exit code 0 on success, 1 with one
// message on stderr otherwise.

#include <CLI/CLI.hpp>
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ident/base_parameters.hpp"
#include "ident/excitation_optimizer.hpp"
#include "ident/fourier_trajectory.hpp"
#include "ident/identification.hpp"
#include "ident/joint_log.hpp"
#include "ident/parameters_yaml.hpp"
#include HQP_IDENTIFY_HEADER

namespace {

using Robot = HQP_IDENTIFY_ROBOT;
namespace hi = hqp::ident;
namespace hm = hqp::model;

// The URDF must describe the compiled-in robot: same name, same movable joints.
void checkUrdf(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(ss.str());
  if (!model) throw std::runtime_error(path + ": urdfdom cannot parse the file");
  const std::string hint =
      "; this hqp_identify is built for '" + std::string(Robot::name) +
      "' — build one for your robot with hqp_add_identify_tool() (docs/identification.md)";
  if (model->getName() != Robot::name) {
    throw std::runtime_error(path + ": robot '" + model->getName() + "'" + hint);
  }
  constexpr int first = Robot::floating_base ? 1 : 0;
  for (int j = 0; j < Robot::nj; ++j) {
    const hm::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(j + first)];
    const urdf::JointConstSharedPtr uj = model->getJoint(b.joint);
    if (!uj) throw std::runtime_error(path + ": no joint '" + b.joint + "'" + hint);
    if (uj->limits && b.type != hm::JointType::Continuous &&
        (std::abs(uj->limits->lower - b.lower) > 1e-9 || std::abs(uj->limits->upper - b.upper) > 1e-9 ||
         std::abs(uj->limits->velocity - b.velocity) > 1e-9)) {
      throw std::runtime_error(path + ": limits of joint '" + b.joint +
                               "' differ from the compiled model" + hint);
    }
  }
}

void writeTrajectory(const std::string& path, const hi::FourierTrajectory& traj, double rate,
                     int periods, const hi::ExcitationResult& r) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  const std::vector<std::string> joints = hi::jointNames<Robot>();
  out << "# hqp_identify excitation for " << Robot::name << ": " << traj.settings().harmonics
      << " harmonics of " << traj.settings().base_frequency << " Hz, condition number "
      << r.cond_initial << " -> " << r.cond_final << "\n";
  out << "# free coefficients per joint [q0, a_2..a_L, b_2..b_L] (docs/identification.md):\n";
  const int per = hi::FourierTrajectory::freePerJoint(traj.settings());
  for (int j = 0; j < Robot::nj; ++j) {
    out << "# " << joints[static_cast<std::size_t>(j)] << ":";
    char buf[32];
    for (int i = 0; i < per; ++i) {
      std::snprintf(buf, sizeof buf, " %.17g", traj.free()[j * per + i]);
      out << buf;
    }
    out << "\n";
  }
  out << "time";
  for (const char* p : {"q_", "dq_", "ddq_"}) {
    for (const std::string& j : joints) out << "," << p << j;
  }
  out << "\n";
  const long n = std::lround(rate * traj.period() * periods);
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  char buf[32];
  for (long k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) / rate;
    traj.evaluate(t, q, dq, ddq);
    std::snprintf(buf, sizeof buf, "%.6f", t);
    out << buf;
    for (const Eigen::VectorXd* v : {&q, &dq, &ddq}) {
      for (int j = 0; j < Robot::nj; ++j) {
        std::snprintf(buf, sizeof buf, ",%.10g", (*v)[j]);
        out << buf;
      }
    }
    out << "\n";
  }
}

hi::JointLog readLog(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  return hi::readJointLog(in, hi::jointNames<Robot>(), path);
}

// CAD torques: full regressor with the URDF's π (friction from <dynamics>).
Eigen::MatrixXd cadTorques(const hi::ConditionedLog& c, const hm::JointVector<Robot>& dq_star) {
  hm::Data<Robot> d;
  hm::RegressorMatrix<Robot> Y;
  const hm::ParameterVector<Robot> pi = hm::nominalParameters<Robot>();
  Eigen::MatrixXd tau(c.q.rows(), Robot::nj);
  typename hm::Data<Robot>::VectorQ q;
  typename hm::Data<Robot>::VectorV v, a;
  for (Eigen::Index k = 0; k < c.q.rows(); ++k) {
    q = c.q.row(k).transpose();
    v = c.dq.row(k).transpose();
    a = c.ddq.row(k).transpose();
    hm::computeRegressor<Robot>(d, q, v, a, dq_star, Y);
    tau.row(k) = (Y * pi).transpose();
  }
  return tau;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Identification of the dynamic and friction parameters of " + std::string(Robot::name) +
               " (paper §V-B): excitation trajectory and least-squares fit."};
  std::string urdf, trajectory_out, fit_log, yaml_out = "identified_parameters.yaml", validate_log,
                                              predict_out, controller_yaml;
  hi::ExcitationSettings es;
  double acc_limit = 10.0, pos_margin = 0.05, vel_scale = 1.0, rate = 1000.0;
  int periods = 1;
  hi::FitSettings fs;
  bool unweighted = false;
  app.add_option("--robot-urdf", urdf, "URDF of the robot (checked against the compiled model)")
      ->required();
  auto* traj_opt = app.add_option("--trajectory", trajectory_out,
                                  "optimize the excitation and write it to this CSV");
  auto* fit_opt = app.add_option("--fit", fit_log, "fit the parameters to this log (CSV)");
  traj_opt->excludes(fit_opt);
  app.add_option("--out", yaml_out, "YAML with the identified friction (with --fit)");
  app.add_option("--controller-yaml", controller_yaml,
                 "controller configuration (e.g. robots/walker3/controller.yaml): the fit uses its "
                 "dq_star per joint and --out becomes a copy of it with the identified coulomb/viscous");
  app.add_option("--validate", validate_log,
                 "a second log: torque prediction error per joint, CAD vs identified (with --fit)");
  app.add_option("--predict", predict_out,
                 "write measured / identified / CAD torques of the validation log (or the fit log)");
  app.add_option("--harmonics", es.fourier.harmonics, "Fourier harmonics")->capture_default_str();
  app.add_option("--base-frequency", es.fourier.base_frequency, "Fourier base frequency (Hz)")
      ->capture_default_str();
  app.add_option("--acc-limit", acc_limit, "joint acceleration limit (rad/s^2; URDF has none)")
      ->capture_default_str();
  app.add_option("--pos-margin", pos_margin, "margin inside the URDF position limits (rad)")
      ->capture_default_str();
  app.add_option("--vel-scale", vel_scale, "fraction of the URDF velocity limits")->capture_default_str();
  app.add_option("--max-evals", es.max_evaluations, "optimizer evaluations")->capture_default_str();
  app.add_option("--max-seconds", es.max_seconds, "optimizer time budget (s)")->capture_default_str();
  app.add_option("--seed", es.seed, "seed of the random start")->capture_default_str();
  app.add_option("--rate", rate, "sample rate of the written trajectory (Hz)")->capture_default_str();
  app.add_option("--periods", periods, "periods written")->capture_default_str();
  app.add_option("--dq-star", fs.dq_star, "q̇* of the friction law, eq. 7 (rad/s)")->capture_default_str();
  app.add_option("--cutoff", fs.cutoff_hz, "low-pass cutoff for q (Hz)")->capture_default_str();
  app.add_option("--min-speed", fs.min_speed,
                 "leave out joints slower than this (rad/s; stiction)")->capture_default_str();
  app.add_option("--filter-order", fs.filter_order, "Butterworth order")->capture_default_str();
  app.add_option("--decimation", fs.decimation, "use every n-th sample")->capture_default_str();
  app.add_flag("--filter-torque", fs.filter_torque, "low-pass the torque too");
  fs.average_torque = true;
  app.add_flag("--average-torque,!--no-average-torque", fs.average_torque,
               "each decimated row's torque is the mean over its decimation window (less noise; "
               "default on)");
  app.add_flag("--fit-dq-star", fs.fit_dq_star,
               "estimate q̇* of eq. 7 per joint from the samples slower than --min-speed "
               "(with --controller-yaml, its dq_star values are replaced too)");
  app.add_flag("--unweighted", unweighted, "ordinary instead of weighted least squares");
  CLI11_PARSE(app, argc, argv);
  fs.weighted = !unweighted;
  es.dq_star = fs.dq_star;

  try {
    if (trajectory_out.empty() && fit_log.empty()) {
      throw std::runtime_error("give --trajectory <out.csv> or --fit <log.csv> (see --help)");
    }
    checkUrdf(urdf);
    const hi::BaseParameters bp =
        hi::computeBaseParameters<Robot>(hm::JointVector<Robot>::Constant(fs.dq_star));
    std::printf("%s: %d joints, %d parameters, %d base parameters\n", Robot::name, Robot::nj,
                hm::RegressorSizes<Robot>::np, bp.rank);

    if (!trajectory_out.empty()) {
      const hi::JointLimits limits = hi::jointLimitsFromModel<Robot>(acc_limit, pos_margin, vel_scale);
      hi::FourierTrajectory traj(Robot::nj, es.fourier);
      const hi::ExcitationResult r = hi::optimizeExcitation<Robot>(bp, limits, es, traj);
      std::printf("excitation: condition number %.1f -> %.1f (%d evaluations, %s), "
                  "max normalized constraint %.2e\n",
                  r.cond_initial, r.cond_final, r.evaluations, r.status.c_str(), r.max_violation);
      writeTrajectory(trajectory_out, traj, rate, periods, r);
      std::printf("wrote %s (%d period(s) of %.1f s at %.0f Hz)\n", trajectory_out.c_str(), periods,
                  traj.period(), rate);
      return 0;
    }

    std::string controller_text;
    if (!controller_yaml.empty()) {
      std::ifstream in(controller_yaml);
      if (!in) throw std::runtime_error(controller_yaml + ": cannot open");
      std::stringstream ss;
      ss << in.rdbuf();
      controller_text = ss.str();
      fs.dq_star_joint = hi::controllerYamlDqStar(controller_text, hi::jointNames<Robot>());
    }
    const hi::JointLog log = readLog(fit_log);
    const hi::ConditionedLog c = hi::conditionLog(log, fs);
    const hi::FitResult fit = hi::fitBaseParameters<Robot>(bp, c, fs);
    std::printf("fit: %ld samples used, condition number %.1f\n", static_cast<long>(c.q.rows()),
                fit.ls.condition);
    std::printf("%-16s %10s %10s %10s %12s\n", "joint", "coulomb", "viscous", "dq_star", "residual RMS");
    for (int j = 0; j < Robot::nj; ++j) {
      std::printf("%-16s %10.4f %10.4f %10.4f %12.4f\n", fit.friction[j].joint.c_str(), fit.friction[j].coulomb,
                  fit.friction[j].viscous, fit.friction[j].dq_star, fit.ls.joint_rms[j]);
    }
    std::ofstream out(yaml_out);
    if (!out) throw std::runtime_error(yaml_out + ": cannot write");
    if (controller_text.empty()) {
      hi::writeParametersYaml(out, std::string("identified by hqp_identify from ") + fit_log + " for " +
                                       Robot::name,
                              fit.friction, fit.base);
    } else {
      std::vector<std::string> warnings;
      out << hi::controllerYamlWithFriction(controller_text, fit.friction, &warnings, fs.fit_dq_star);
      for (const std::string& w : warnings) std::printf("warning: %s\n", w.c_str());
    }
    std::printf("wrote %s\n", yaml_out.c_str());

    const hi::ConditionedLog v = validate_log.empty() ? c : hi::conditionLog(readLog(validate_log), fs);
    const Eigen::MatrixXd ident =
        hi::predictTorques<Robot>(bp, fit.ls.beta, v.q, v.dq, v.ddq, hi::dqStar<Robot>(fit));
    const Eigen::MatrixXd cad = cadTorques(v, hi::dqStar<Robot>(fs));
    std::printf("%s torque error per joint (N m): %-9s %-9s | %-9s %-9s\n",
                validate_log.empty() ? "fit-log" : "validation", "CAD rms", "CAD max", "ID rms", "ID max");
    const std::vector<std::string> joints = hi::jointNames<Robot>();
    for (int j = 0; j < Robot::nj; ++j) {
      const Eigen::VectorXd ec = cad.col(j) - v.tau.col(j);
      const Eigen::VectorXd ei = ident.col(j) - v.tau.col(j);
      std::printf("  %-16s %9.3f %9.3f | %9.3f %9.3f\n", joints[static_cast<std::size_t>(j)].c_str(),
                  std::sqrt(ec.squaredNorm() / ec.size()), ec.cwiseAbs().maxCoeff(),
                  std::sqrt(ei.squaredNorm() / ei.size()), ei.cwiseAbs().maxCoeff());
    }
    if (!predict_out.empty()) {
      std::ofstream p(predict_out);
      if (!p) throw std::runtime_error(predict_out + ": cannot write");
      hi::writeTorquePrediction(p, v.time, joints, v.tau, ident, cad);
      std::printf("wrote %s\n", predict_out.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hqp_identify: %s\n", e.what());
    return 1;
  }
  return 0;
}
