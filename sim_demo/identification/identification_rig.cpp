// hqp_identification_rig: the identification procedure of §V-B, end to end, on
// a MuJoCo 2.2 plant (sim_demo/identification/mujoco_rig.hpp): Walker3 hung by
// its torso, masses ±15 %, CoMs moved, Coulomb friction 1–5 N·m and viscous
// friction 0.2–2 N·m·s/rad that the identification never sees.
//
//  1. base parameters and the optimized Fourier excitation (NLopt COBYLA);
//  2. the plant tracks it for two periods under joint PD control at 1 kHz,
//     with CAD inverse dynamics and the URDF's nominal friction (eq. 7 at the
//     desired velocity) as feedforward; q and the motor torque are logged
//     with sensor noise;
//  3. the log is filtered, differentiated and fitted (weighted LS);
//  4. a different trajectory validates: torque prediction error per joint,
//     CAD (URDF inertias, no friction: "the 3D model" of the paper) vs identified,
//     RMS over all samples of the run (stuck ones included). The validation
//     trajectory is a random Fourier series per joint, scaled to the URDF
//     limits and chosen, from the reference alone, to keep every joint moving.
// Writes the logs (hqp_identify's CSV format), the identified YAML and the
// validation torques for a plot like the paper's Fig. 7 into --out-dir.
// Prints on how many joints the target (validation RMS below 1 N·m and
// 5× below CAD) is met. Exit code 0 when, on every joint, the friction is
// recovered (F_c within 0.25 N·m, F_v within 0.5 N·m·s/rad), the identified model
// is better than CAD and below 1 N·m RMS on the samples where the joint moves (|q̇| ≥ --min-speed: eq. 7 does not model a stuck joint); 1 otherwise.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "ident/excitation_optimizer.hpp"
#include "ident/identification.hpp"
#include "ident/parameters_yaml.hpp"
#include "ident_walker3_fixed_model.hpp"
#include "identification/mujoco_rig.hpp"
#include <Eigen/LU>

#include "model/crba.hpp"

namespace {

namespace hm = hqp::model;
namespace hi = hqp::ident;
using Robot = walker3_fixed::Robot;

struct Noise {
  double q = 2e-4;    // encoder noise (rad)
  double tau = 0.3;   // torque (current) noise (N·m)
};

// PD + CAD feedforward at 1 kHz along `traj` for `periods` periods; returns the log.
hi::JointLog run(hqp::ident_demo::MujocoRig& rig, const hi::FourierTrajectory& traj, int periods,
                 const Noise& noise, double pd_hz, unsigned seed, double* worst_tracking,
                 Eigen::MatrixXd* clean_tau) {
  hm::Data<Robot> d;
  hm::RegressorMatrix<Robot> Y;
  // Feedforward: CAD inverse dynamics plus the URDF's nominal friction by eq. 7
  // at the desired velocity (the paper's joint controller, eqs. 5 and 7).
  const hm::ParameterVector<Robot> cad = hm::nominalParameters<Robot>();
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  traj.evaluate(0.0, q, dq, ddq);
  // Gains from the CAD joint-space inertia along the reference, every tick:
  // bandwidth pd_hz, damping ratio 0.7, on the inertia a joint sees with the
  // others free, 1 / (M⁻¹)_jj ≤ M_jj (the diagonal of M overestimates it for
  // distal joints, and it changes with the knee angle): the explicit 1 ms loop
  // then keeps the same margin in every configuration.
  const double wn = 2.0 * 3.14159265358979 * pd_hz;
  Eigen::VectorXd kp(Robot::nj), kd(Robot::nj);
  const auto gains = [&](const Eigen::VectorXd& qref) {
    const typename hm::Data<Robot>::VectorQ qm = qref;
    hm::crba<Robot>(d, qm);
    const Eigen::MatrixXd Minv = Eigen::MatrixXd(d.M).inverse();
    for (int j = 0; j < Robot::nj; ++j) {
      const double m_eff = 1.0 / Minv(j, j);
      kp[j] = wn * wn * m_eff;
      kd[j] = 2.0 * 0.7 * wn * m_eff;
    }
  };
  rig.reset(q);
  const int N = static_cast<int>(std::lround(traj.period() * periods * 1000.0));
  std::mt19937 rng(seed);
  std::normal_distribution<double> nq(0.0, noise.q), nt(0.0, noise.tau);
  hi::JointLog log;
  log.joints = hi::jointNames<Robot>();
  log.time.resize(N);
  log.q.resize(N, Robot::nj);
  log.tau.resize(N, Robot::nj);
  clean_tau->resize(N, Robot::nj);
  *worst_tracking = 0.0;
  for (int k = 0; k < N; ++k) {
    const double t = 1e-3 * k;
    traj.evaluate(t, q, dq, ddq);
    gains(q);
    typename hm::Data<Robot>::VectorV vq = q, vv = dq, va = ddq;
    hm::computeRegressor<Robot>(d, vq, vv, va, hm::JointVector<Robot>::Constant(0.01), Y);
    const Eigen::VectorXd qs = rig.q(), dqs = rig.dq();
    const Eigen::VectorXd tau =
        Y * cad + kp.cwiseProduct(q - qs) + kd.cwiseProduct(dq - dqs);
    *worst_tracking = std::max(*worst_tracking, (q - qs).cwiseAbs().maxCoeff());
    log.time[k] = t;
    clean_tau->row(k) = tau.transpose();
    for (int j = 0; j < Robot::nj; ++j) {
      log.q(k, j) = qs[j] + nq(rng);
      log.tau(k, j) = tau[j] + nt(rng);
    }
    rig.step(tau);
  }
  return log;
}

// A plot like the paper's Fig. 7 as SVG (no plotting library needed): one panel
// per joint of the left leg, measured torque (red), identified (blue), CAD (black).
void writeFig7Svg(const std::string& path, const Eigen::VectorXd& t, const Eigen::MatrixXd& measured,
                  const Eigen::MatrixXd& ident, const Eigen::MatrixXd& cad,
                  const std::vector<std::string>& joints) {
  std::ofstream out(path);
  const int W = 900, H = 180, pad = 50;
  const int panels = std::min<int>(6, static_cast<int>(joints.size()));
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H * panels + 30
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n"
      << "<text x='" << pad << "' y='18'>validation torques, left leg: measured (red), identified "
      << "(blue), CAD (black dashed)</text>\n";
  const double t0 = t[0], t1 = t[t.size() - 1];
  for (int j = 0; j < panels; ++j) {
    const double y0 = 30 + j * H;
    double lo = std::min({measured.col(j).minCoeff(), ident.col(j).minCoeff(), cad.col(j).minCoeff()});
    double hi = std::max({measured.col(j).maxCoeff(), ident.col(j).maxCoeff(), cad.col(j).maxCoeff()});
    if (hi - lo < 1e-9) hi = lo + 1.0;
    const auto X = [&](double x) { return pad + (W - 2 * pad) * (x - t0) / (t1 - t0); };
    const auto Y = [&](double y) { return y0 + 10 + (H - 40) * (hi - y) / (hi - lo); };
    out << "<rect x='" << pad << "' y='" << y0 + 10 << "' width='" << W - 2 * pad << "' height='"
        << H - 40 << "' fill='none' stroke='#999'/>\n";
    out << "<text x='" << pad + 5 << "' y='" << y0 + 24 << "'>" << joints[static_cast<std::size_t>(j)]
        << " (N m)</text>\n<text x='5' y='" << Y(hi) + 4 << "'>" << std::lround(hi)
        << "</text>\n<text x='5' y='" << Y(lo) + 4 << "'>" << std::lround(lo) << "</text>\n";
    const auto line = [&](const Eigen::MatrixXd& m, const char* style) {
      out << "<polyline fill='none' " << style << " points='";
      for (Eigen::Index k = 0; k < t.size(); ++k) out << X(t[k]) << "," << Y(m(k, j)) << " ";
      out << "'/>\n";
    };
    line(measured, "stroke='#d33' stroke-width='1'");
    line(ident, "stroke='#23c' stroke-width='1.2'");
    line(cad, "stroke='black' stroke-width='1' stroke-dasharray='4 3'");
  }
  out << "<text x='" << W / 2 << "' y='" << H * panels + 25 << "'>time (s)</text>\n</svg>\n";
}

// Scales each joint's motion about q0 (linear in its coefficients, rest at the
// ends kept) up or down to its tightest URDF limit (position, velocity,
// acceleration) on a dense grid: the validation then keeps every joint as far
// from rest as the limits allow, so that stiction, which eq. 7 cannot predict,
// takes little of it.
void scaleToLimits(hi::FourierTrajectory& traj, const hi::JointLimits& L, double margin) {
  const int n = traj.joints(), N = 4000;
  Eigen::VectorXd q(n), dq(n), ddq(n);
  Eigen::VectorXd up = Eigen::VectorXd::Zero(n), down = up, vmax = up, amax = up;
  for (int k = 0; k < N; ++k) {
    traj.evaluate(traj.period() * k / N, q, dq, ddq);
    for (int j = 0; j < n; ++j) {
      up[j] = std::max(up[j], q[j] - traj.q0(j));
      down[j] = std::max(down[j], traj.q0(j) - q[j]);
      vmax[j] = std::max(vmax[j], std::abs(dq[j]));
      amax[j] = std::max(amax[j], std::abs(ddq[j]));
    }
  }
  for (int j = 0; j < n; ++j) {
    double k = 1e9;
    const bool bounded = std::isfinite(L.q_min[j]) && std::isfinite(L.q_max[j]);
    if (bounded && up[j] + down[j] > 0.0) k = std::min(k, (L.q_max[j] - L.q_min[j]) / (up[j] + down[j]));
    if (vmax[j] > 0.0) k = std::min(k, L.dq_max[j] / vmax[j]);
    if (amax[j] > 0.0) k = std::min(k, L.ddq_max[j] / amax[j]);
    if (!(k < 1e9)) continue;
    // The scaled motion spans [q0 − k·down, q0 + k·up]: centre it in the range.
    if (bounded) traj.q0(j) = 0.5 * (L.q_min[j] + L.q_max[j]) - 0.5 * margin * k * (up[j] - down[j]);
    traj.scaleJoint(j, margin * k);
  }
}

// Per joint, the share of one period during which the reference stays within
// e0[j] of its last turning point (or of its start, at rest): a geared joint
// sticks there until the tracking error builds the breakaway torque, and eq. 7
// cannot predict a stuck joint's torque. A kinematic estimate from the
// reference alone (never from the rig's response).
Eigen::VectorXd stuckShare(const hi::FourierTrajectory& traj, const Eigen::VectorXd& e0) {
  const int n = traj.joints(), N = 10000;
  Eigen::VectorXd q(n), dq(n), ddq(n), share = Eigen::VectorXd::Zero(n);
  traj.evaluate(0.0, q, dq, ddq);
  Eigen::VectorXd turn = q, last_dq = dq;
  for (int k = 0; k < N; ++k) {
    traj.evaluate(traj.period() * k / N, q, dq, ddq);
    for (int j = 0; j < n; ++j) {
      if (dq[j] * last_dq[j] < 0.0) turn[j] = q[j];
      if (dq[j] != 0.0) last_dq[j] = dq[j];
      share[j] += std::abs(q[j] - turn[j]) < e0[j] ? 1.0 / N : 0.0;
    }
  }
  return share;
}

void writeLog(const std::string& path, const hi::JointLog& log) {
  std::ofstream out(path);
  out << "time";
  for (const std::string& j : log.joints) out << ",q_" << j;
  for (const std::string& j : log.joints) out << ",tau_" << j;
  out << "\n";
  char buf[40];
  for (Eigen::Index k = 0; k < log.time.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.3f", log.time[k]);
    out << buf;
    for (const Eigen::MatrixXd* m : {&log.q, &log.tau}) {
      for (Eigen::Index j = 0; j < m->cols(); ++j) {
        std::snprintf(buf, sizeof buf, ",%.9g", (*m)(k, j));
        out << buf;
      }
    }
    out << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Identification of Walker3 on a MuJoCo rig (paper §V-B), with a validation report."};
  std::string urdf = HQP_WALKER3_URDF, out_dir = ".";
  unsigned seed = 42;
  int evaluations = 3000, periods = 2;
  Noise noise;
  double pd_hz = 20.0;
  double friction_timeconst = 0.004;
  double val_fill = 0.95;
  int val_candidates = 50;
  hi::FitSettings fs;
  fs.min_speed = 0.05;
  app.add_option("--urdf", urdf, "Walker3 URDF")->capture_default_str();
  app.add_option("--out-dir", out_dir, "where the logs, YAML and torques go")->capture_default_str();
  app.add_option("--seed", seed, "seed of the plant's true parameters")->capture_default_str();
  app.add_option("--max-evals", evaluations, "excitation optimizer budget")->capture_default_str();
  app.add_option("--periods", periods, "excitation periods run on the rig")->capture_default_str();
  app.add_option("--q-noise", noise.q, "encoder noise std (rad)")->capture_default_str();
  app.add_option("--tau-noise", noise.tau, "torque noise std (N m)")->capture_default_str();
  app.add_option("--pd-hz", pd_hz, "PD bandwidth (Hz) from the CAD joint inertia")->capture_default_str();
  app.add_option("--cutoff", fs.cutoff_hz, "low-pass cutoff for q (Hz)")->capture_default_str();
  app.add_option("--min-speed", fs.min_speed, "rows slower than this are left out (rad/s)")
      ->capture_default_str();
  app.add_option("--friction-timeconst", friction_timeconst,
                 "time constant of MuJoCo's frictionloss constraint (s)")->capture_default_str();
  app.add_option("--validation-fill", val_fill,
                 "validation: scale each joint to this fraction of its tightest limit")
      ->capture_default_str();
  app.add_option("--validation-candidates", val_candidates,
                 "validation: random trajectories drawn, the one moving most is run")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> links;
  for (const hm::BodyDesc& b : Robot::bodies) links.emplace_back(b.name);
  const std::vector<std::string> joints = hi::jointNames<Robot>();
  hqp::ident_demo::MujocoRig rig(urdf, links, joints);
  rig.friction_timeconst = friction_timeconst;
  rig.perturb(seed);

  const hi::BaseParameters bp =
      hi::computeBaseParameters<Robot>(hm::JointVector<Robot>::Constant(fs.dq_star));
  hi::ExcitationSettings es;
  es.max_evaluations = evaluations;
  const hi::JointLimits limits = hi::jointLimitsFromModel<Robot>(10.0);
  hi::FourierTrajectory excitation(Robot::nj, es.fourier);
  const hi::ExcitationResult ex = hi::optimizeExcitation<Robot>(bp, limits, es, excitation);
  std::printf("base parameters: %d of %d\n", bp.rank, hm::RegressorSizes<Robot>::np);
  std::printf("excitation: condition number %.1f -> %.1f (%d evaluations)\n", ex.cond_initial,
              ex.cond_final, ex.evaluations);
  // Validation: a different Fourier trajectory (same 5 harmonics and period),
  // not optimized for conditioning but for motion. Per joint, of
  // `val_candidates` random draws (coefficients ~ N(0, l^p), p cycling through
  // −1…2; every second draw without the first harmonic), each scaled and
  // centred to the joint's tightest URDF limit, the one with the least
  // estimated stuck time (stuckShare) is kept. The breakaway tracking error of
  // a joint is what the PD needs beyond the feedforward's URDF friction to
  // reach the top of the rig's Coulomb range (5 N m): (5 − F_urdf) / k_p, with
  // k_p from the CAD inertia at mid-range (the gains of run()). A priori
  // figures only, not the plant's friction.
  hi::FourierTrajectory validation(Robot::nj, es.fourier);
  Eigen::VectorXd e_break(Robot::nj);
  {
    hm::Data<Robot> d;
    typename hm::Data<Robot>::VectorQ qm;
    for (int j = 0; j < Robot::nj; ++j) qm[j] = 0.5 * (limits.q_min[j] + limits.q_max[j]);
    hm::crba<Robot>(d, qm);
    const Eigen::MatrixXd Minv = Eigen::MatrixXd(d.M).inverse();
    const double wn = 2.0 * 3.14159265358979 * pd_hz;
    for (int j = 0; j < Robot::nj; ++j) {
      const double f_urdf = Robot::bodies[static_cast<std::size_t>(j)].friction;
      e_break[j] = std::max(0.005, (5.0 - f_urdf) * Minv(j, j) / (wn * wn));
    }
  }
  {
    const int L = es.fourier.harmonics, per = hi::FourierTrajectory::freePerJoint(es.fourier);
    Eigen::VectorXd best_x(validation.numFree());
    Eigen::VectorXd best = Eigen::VectorXd::Constant(Robot::nj, 2.0);
    for (int c = 0; c < val_candidates; ++c) {
      std::mt19937 rng(1000 + seed + static_cast<unsigned>(c));
      std::normal_distribution<double> normal(0.0, 1.0);
      const double p = -1.0 + (c / 2) % 4;
      Eigen::VectorXd x(validation.numFree());
      for (int j = 0; j < Robot::nj; ++j) {
        Eigen::VectorXd a(L - 1), b(L - 1), l(L - 1);
        for (int i = 0; i < L - 1; ++i) {
          l[i] = i + 2;
          a[i] = std::pow(l[i], p) * normal(rng);
          b[i] = std::pow(l[i], p) * normal(rng);
        }
        if (c % 2 == 1) {
          // Σ a_l = 0 and Σ l b_l = 0: the rest conditions leave the first harmonic at zero.
          a.array() -= a.mean();
          b -= (l.dot(b) / l.squaredNorm()) * l;
        }
        x[j * per] = 0.5 * (limits.q_min[j] + limits.q_max[j]);
        x.segment(j * per + 1, L - 1) = a;
        x.segment(j * per + L, L - 1) = b;
      }
      hi::FourierTrajectory cand(Robot::nj, es.fourier);
      cand.setFree(x);
      scaleToLimits(cand, limits, val_fill);
      const Eigen::VectorXd stuck = stuckShare(cand, e_break);
      for (int j = 0; j < Robot::nj; ++j) {
        if (stuck[j] < best[j]) {
          best[j] = stuck[j];
          best_x.segment(j * per, per) = cand.free().segment(j * per, per);
        }
      }
    }
    validation.setFree(best_x);
  }
  const Eigen::VectorXd stuck_val = stuckShare(validation, e_break);
  std::printf("validation: breakaway error (rad)\n ");
  for (int j = 0; j < Robot::nj; ++j) std::printf(" %s %.3f", joints[j].c_str(), e_break[j]);
  std::printf("\nvalidation: estimated stuck share of the reference (within the breakaway error of a turning point)\n ");
  for (int j = 0; j < Robot::nj; ++j) std::printf(" %s %.0f %%", joints[j].c_str(), 100 * stuck_val[j]);
  std::printf("\n");

  double track_fit = 0.0, track_val = 0.0;
  Eigen::MatrixXd fit_clean, val_clean;
  const hi::JointLog fit_log = run(rig, excitation, periods, noise, pd_hz, seed + 1, &track_fit, &fit_clean);
  const hi::JointLog val_log = run(rig, validation, 1, noise, pd_hz, seed + 2, &track_val, &val_clean);
  std::printf("rig: %d + 1 periods at 1 kHz, worst tracking error %.3f / %.3f rad\n", periods,
              track_fit, track_val);
  if (!(track_fit < 0.5) || !(track_val < 0.5)) {
    std::printf("FAIL: the rig did not track (unstable PD? lower --pd-hz)\n");
    return 1;
  }
  writeLog(out_dir + "/rig_excitation_log.csv", fit_log);
  writeLog(out_dir + "/rig_validation_log.csv", val_log);

  const hi::ConditionedLog c = hi::conditionLog(fit_log, fs);
  const hi::FitResult fit = hi::fitBaseParameters<Robot>(bp, c, fs);
  std::printf("\nfriction           Coulomb (N m)          viscous (N m s/rad)\n");
  std::printf("joint              true    ident   err    true    ident   err\n");
  for (int j = 0; j < Robot::nj; ++j) {
    // The plant's viscous law counts from 0, eq. 7's from the band edge q̇*:
    // F_c(eq. 7) = F_c + F_v q̇* for the same torques outside the band.
    const double c_true = rig.truth().coulomb[j] + rig.truth().viscous[j] * fs.dq_star;
    std::printf("%-16s %7.3f %7.3f %6.3f  %6.3f %7.3f %6.3f\n", joints[j].c_str(), c_true,
                fit.friction[j].coulomb, fit.friction[j].coulomb - c_true, rig.truth().viscous[j],
                fit.friction[j].viscous, fit.friction[j].viscous - rig.truth().viscous[j]);
  }
  {
    std::ofstream y(out_dir + "/rig_identified.yaml");
    hi::writeParametersYaml(y, "identified on the MuJoCo rig (hqp_identification_rig)", fit.friction,
                            fit.base);
  }

  // Validation: CAD and identified predictions against the measured (noisy)
  // torque and against the applied torque before the sensor noise.
  const hi::ConditionedLog v = hi::conditionLog(val_log, fs);
  hi::JointLog val_clean_log = val_log;
  val_clean_log.tau = val_clean;
  const hi::ConditionedLog vc = hi::conditionLog(val_clean_log, fs);
  const Eigen::MatrixXd ident = hi::predictTorques<Robot>(bp, fit.ls.beta, v.q, v.dq, v.ddq, fs.dq_star);
  hm::ParameterVector<Robot> cad = hm::nominalParameters<Robot>();
  cad.tail<hm::RegressorSizes<Robot>::n_friction>().setZero();
  const Eigen::VectorXd beta_cad = bp.K * cad;
  const Eigen::MatrixXd cadp = hi::predictTorques<Robot>(bp, beta_cad, v.q, v.dq, v.ddq, fs.dq_star);
  const auto rms = [](const Eigen::VectorXd& e) { return std::sqrt(e.squaredNorm() / e.size()); };
  std::printf("\nvalidation torque error (N m)   vs measured (noise %.2f)        |  vs applied (noise-free)\n",
              noise.tau);
  std::printf("joint             CAD rms CAD max  ID rms  ID max  ratio | CAD rms  ID rms  ID max  ratio"
              " | ID rms moving (share)\n");
  int target_met = 0;
  bool ok = true;
  for (int j = 0; j < Robot::nj; ++j) {
    const Eigen::VectorXd ec = cadp.col(j) - v.tau.col(j);
    const Eigen::VectorXd ei = ident.col(j) - v.tau.col(j);
    const Eigen::VectorXd ec0 = cadp.col(j) - vc.tau.col(j);
    const Eigen::VectorXd ei0 = ident.col(j) - vc.tau.col(j);
    // Samples where the joint moves (|q̇| ≥ min_speed): outside stiction.
    double ss = 0.0;
    int n_moving = 0;
    for (Eigen::Index k = 0; k < ei0.size(); ++k) {
      if (std::abs(v.dq(k, j)) < fs.min_speed) continue;
      ss += ei0[k] * ei0[k];
      ++n_moving;
    }
    const double moving = std::sqrt(ss / std::max(1, n_moving));
    const bool target = rms(ei0) < 1.0 && rms(ec0) >= 5.0 * rms(ei0);
    target_met += target ? 1 : 0;
    // CI criterion: friction recovered, the identified model better than CAD
    // everywhere and below 1 N m wherever eq. 7 applies (the joint moves).
    const double c_true = rig.truth().coulomb[j] + rig.truth().viscous[j] * fs.dq_star;
    ok = ok && std::abs(fit.friction[j].coulomb - c_true) < 0.25 &&
         std::abs(fit.friction[j].viscous - rig.truth().viscous[j]) < 0.5 &&
         rms(ec0) > rms(ei0) && moving < 1.0;
    std::printf("%-16s %7.3f %7.3f %7.3f %7.3f %6.1f | %7.3f %7.3f %7.3f %6.1f | %7.3f (%3.0f %%) %s\n",
                joints[j].c_str(), rms(ec), ec.cwiseAbs().maxCoeff(), rms(ei), ei.cwiseAbs().maxCoeff(),
                rms(ec) / rms(ei), rms(ec0), rms(ei0), ei0.cwiseAbs().maxCoeff(), rms(ec0) / rms(ei0),
                moving, 100.0 * n_moving / ei0.size(), target ? "" : "(target missed)");
  }
  writeFig7Svg(out_dir + "/rig_fig7.svg", v.time, v.tau, ident, cadp, joints);
  std::printf("\nissue target (RMS < 1 N m and 5x below CAD, vs applied torque) met on %d of %d joints\n",
              target_met, Robot::nj);
  {
    std::ofstream p(out_dir + "/rig_validation_torques.csv");
    hi::writeTorquePrediction(p, v.time, joints, v.tau, ident, cadp);
  }
  std::printf("%s: friction recovered (F_c within 0.25 N m, F_v within 0.5 N m s/rad), identified "
              "model better than CAD and < 1 N m RMS while moving, on %s joint\n",
              ok ? "PASS" : "FAIL", ok ? "every" : "not every");
  return ok ? 0 : 1;
}
