// Identification against MuJoCo 2.2 (noise-free): Walker3's legs on a fixed
// torso with masses ±15 % and CoMs moved by up to 2 cm (the "truth" the
// identification never sees), torques from MuJoCo's inverse dynamics plus the
// friction of eq. 7 with known F_c, F_v. The fit must return the friction to
// 1e-6 and predict MuJoCo's torques on a different trajectory to 1e-6 N·m
// (MuJoCo's principal-axis inertias agree with an exact model to ~1e-9
// relative, docs: mujoco-2.2-notes.md).
#include <gtest/gtest.h>

#include <cstdio>

#include "ident/excitation_optimizer.hpp"
#include "ident/identification.hpp"
#include "ident_walker3_fixed_model.hpp"
#include "identification/mujoco_rig.hpp"

namespace {

namespace hm = hqp::model;
namespace hi = hqp::ident;
using Robot = walker3_fixed::Robot;

std::vector<std::string> linkNames() {
  std::vector<std::string> l;
  for (const hm::BodyDesc& b : Robot::bodies) l.emplace_back(b.name);
  return l;
}

// Samples of `traj` with MuJoCo torques + eq. 7 friction of the rig's truth.
hi::ConditionedLog mujocoTorques(hqp::ident_demo::MujocoRig& rig, const hi::FourierTrajectory& traj,
                                 int N, double dq_star) {
  hi::ConditionedLog c;
  c.time.resize(N);
  c.q.resize(N, Robot::nj);
  c.dq.resize(N, Robot::nj);
  c.ddq.resize(N, Robot::nj);
  c.tau.resize(N, Robot::nj);
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  for (int k = 0; k < N; ++k) {
    const double t = traj.period() * (k + 0.5) / N;
    traj.evaluate(t, q, dq, ddq);
    Eigen::VectorXd tau = rig.inverseDynamics(q, dq, ddq);
    for (int j = 0; j < Robot::nj; ++j) {
      const hm::FrictionBasis phi = hm::frictionBasis(dq[j], dq_star);
      tau[j] += rig.truth().coulomb[j] * phi.coulomb + rig.truth().viscous[j] * phi.viscous;
    }
    c.time[k] = t;
    c.q.row(k) = q.transpose();
    c.dq.row(k) = dq.transpose();
    c.ddq.row(k) = ddq.transpose();
    c.tau.row(k) = tau.transpose();
  }
  return c;
}

TEST(IdentifyMujoco, RecoversFrictionAndPredictsTorquesExactly) {
  hqp::ident_demo::MujocoRig rig(HQP_WALKER3_URDF, linkNames(), hi::jointNames<Robot>());
  rig.perturb(42u);
  hi::FitSettings fs;
  fs.weighted = false;
  const hi::BaseParameters bp =
      hi::computeBaseParameters<Robot>(hm::JointVector<Robot>::Constant(fs.dq_star));
  hi::ExcitationSettings es;
  es.seed = 5;
  const hi::ExcitationProblem<Robot> problem(bp, hi::jointLimitsFromModel<Robot>(10.0), es);
  const hi::FourierTrajectory excitation = problem.randomStart();
  es.seed = 6;
  const hi::ExcitationProblem<Robot> other(bp, hi::jointLimitsFromModel<Robot>(10.0), es);
  const hi::FourierTrajectory validation = other.randomStart();

  const hi::ConditionedLog fit_log = mujocoTorques(rig, excitation, 400, fs.dq_star);
  const hi::FitResult fit = hi::fitBaseParameters<Robot>(bp, fit_log, fs);
  for (int j = 0; j < Robot::nj; ++j) {
    EXPECT_NEAR(fit.friction[j].coulomb, rig.truth().coulomb[j], 1e-6) << j;
    EXPECT_NEAR(fit.friction[j].viscous, rig.truth().viscous[j], 1e-6) << j;
  }
  const hi::ConditionedLog val = mujocoTorques(rig, validation, 200, fs.dq_star);
  const Eigen::MatrixXd pred = hi::predictTorques<Robot>(bp, fit.ls.beta, val.q, val.dq, val.ddq, fs.dq_star);
  const double err = (pred - val.tau).cwiseAbs().maxCoeff();
  std::printf("[ mujoco ] noise-free: max validation torque error %.2e N m (torques up to %.1f N m)\n",
              err, val.tau.cwiseAbs().maxCoeff());
  EXPECT_LT(err, 1e-6);
  // The CAD model is far off (so the test can tell).
  const hm::ParameterVector<Robot> cad = hm::nominalParameters<Robot>();
  Eigen::VectorXd beta_cad = bp.K * cad;
  const Eigen::MatrixXd pred_cad = hi::predictTorques<Robot>(bp, beta_cad, val.q, val.dq, val.ddq, fs.dq_star);
  EXPECT_GT((pred_cad - val.tau).cwiseAbs().maxCoeff(), 0.5);
}

}  // namespace
