// The identification pipeline (include/ident) on the legs of Walker3 on a
// fixed torso: Fourier excitation, filtering and differentiation, least
// squares on synthetic data, the excitation optimizer, log parsing and YAML.
// References: finite differences and closed forms (Fourier, Butterworth
// magnitude, derivatives of a sine), known parameters (synthetic torques from
// the regressor, itself checked against the RNEA in test_ident_regressor),
// yaml-cpp for reading back the YAML.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "ident/excitation_optimizer.hpp"
#include "ident/fourier_trajectory.hpp"
#include "ident/identification.hpp"
#include "ident_walker3_fixed_model.hpp"

#if __has_include("tasks/controller_config_yaml.hpp")
#include "tasks/controller_config_yaml.hpp"
#endif

namespace {

namespace hm = hqp::model;
namespace hi = hqp::ident;
using Robot = walker3_fixed::Robot;
using Sizes = hm::RegressorSizes<Robot>;
constexpr double kPi = 3.14159265358979323846;

hi::FourierTrajectory randomTrajectory(unsigned seed, double amplitude) {
  hi::FourierTrajectory traj(Robot::nj, hi::FourierSettings{});
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, amplitude);
  Eigen::VectorXd x(traj.numFree());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = n(rng);
  traj.setFree(x);
  return traj;
}

// ---------------------------------------------------------------- Fourier
TEST(Fourier, DerivativesMatchFiniteDifferences) {
  const hi::FourierTrajectory traj = randomTrajectory(5u, 0.3);
  EXPECT_DOUBLE_EQ(traj.period(), 10.0);  // 0.1 Hz
  EXPECT_EQ(hi::FourierTrajectory::freePerJoint(traj.settings()), 9);  // 5 harmonics
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  Eigen::VectorXd qp(Robot::nj), dqp(Robot::nj), ddqp(Robot::nj);
  Eigen::VectorXd qm(Robot::nj), dqm(Robot::nj), ddqm(Robot::nj);
  const double h = 1e-5;
  for (double t : {0.3, 1.7, 4.2, 6.66, 9.1}) {
    traj.evaluate(t, q, dq, ddq);
    traj.evaluate(t + h, qp, dqp, ddqp);
    traj.evaluate(t - h, qm, dqm, ddqm);
    EXPECT_LE(((qp - qm) / (2 * h) - dq).norm(), 1e-7 * (1 + dq.norm())) << t;
    EXPECT_LE(((dqp - dqm) / (2 * h) - ddq).norm(), 1e-7 * (1 + ddq.norm())) << t;
  }
}

TEST(Fourier, RestAtStartAndEnd) {
  const hi::FourierTrajectory traj = randomTrajectory(6u, 0.5);
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  for (double t : {0.0, traj.period(), 3.0 * traj.period()}) {
    traj.evaluate(t, q, dq, ddq);
    for (int j = 0; j < Robot::nj; ++j) {
      EXPECT_NEAR(q[j], traj.q0(j), 1e-12);
      EXPECT_NEAR(dq[j], 0.0, 1e-12);
      EXPECT_NEAR(ddq[j], 0.0, 1e-12);
    }
  }
  // The series really uses all harmonics (not trivially at rest everywhere).
  traj.evaluate(2.5, q, dq, ddq);
  EXPECT_GT(dq.norm(), 0.1);
}

// ---------------------------------------------------------------- filtering
// Amplitude of a steady sine after filtfilt vs the closed form |H(f)|² of the
// bilinear Butterworth: 1 / (1 + (tan(π f/fs) / tan(π fc/fs))^(2N)).
TEST(Filtering, ButterworthMagnitudeAndZeroPhase) {
  const double fs = 1000.0, fc = 5.0;
  for (int order : {2, 3, 4}) {
    const hi::ButterworthLowPass lp(order, fc, fs);
    for (double f : {1.0, 5.0, 10.0}) {
      const int N = 20000;
      Eigen::VectorXd x(N);
      for (int k = 0; k < N; ++k) x[k] = std::sin(2 * kPi * f * k / fs);
      const Eigen::VectorXd y = lp.filtfilt(x);
      const double ratio = std::tan(kPi * f / fs) / std::tan(kPi * fc / fs);
      const double gain = 1.0 / (1.0 + std::pow(ratio, 2.0 * order));
      // Middle part: compare with gain · x (same phase: zero-phase filter).
      const Eigen::VectorXd mid = y.segment(N / 4, N / 2) - gain * x.segment(N / 4, N / 2);
      EXPECT_LE(mid.cwiseAbs().maxCoeff(), 2e-3) << "order " << order << " f " << f << " gain " << gain;
    }
  }
}

TEST(Filtering, DerivativesOfANoisySine) {
  const double fs = 1000.0, dt = 1.0 / fs, f = 0.4, A = 0.8;
  const int N = 10000;
  std::mt19937 rng(3u);
  std::normal_distribution<double> noise(0.0, 1e-4);  // encoder-like noise (rad)
  Eigen::VectorXd x(N), clean_dx(N), clean_ddx(N);
  const double w = 2 * kPi * f;
  for (int k = 0; k < N; ++k) {
    const double t = k * dt;
    x[k] = A * std::sin(w * t) + noise(rng);
    clean_dx[k] = A * w * std::cos(w * t);
    clean_ddx[k] = -A * w * w * std::sin(w * t);
  }
  // Central differences alone on the exact sine: O(dt²) error.
  Eigen::VectorXd exact(N);
  for (int k = 0; k < N; ++k) exact[k] = A * std::sin(w * k * dt);
  EXPECT_LE((hi::centralDifference(exact, dt) - clean_dx).cwiseAbs().maxCoeff(),
            A * w * w * w * dt * dt);
  const hi::ButterworthLowPass lp(4, 5.0, fs);
  const Eigen::VectorXd xf = lp.filtfilt(x);
  const Eigen::VectorXd dx = hi::centralDifference(xf, dt);
  const Eigen::VectorXd ddx = hi::centralDifference(dx, dt);
  const int e = 500;  // away from the ends
  EXPECT_LE((dx - clean_dx).segment(e, N - 2 * e).cwiseAbs().maxCoeff(), 0.01 * A * w);
  EXPECT_LE((ddx - clean_ddx).segment(e, N - 2 * e).cwiseAbs().maxCoeff(), 0.05 * A * w * w);
  // Raw differences of the noisy signal are far worse (the reason to filter).
  const Eigen::VectorXd ddx_raw = hi::centralDifference(hi::centralDifference(x, dt), dt);
  EXPECT_GT((ddx_raw - clean_ddx).segment(e, N - 2 * e).cwiseAbs().maxCoeff(), A * w * w);
}

TEST(Filtering, RejectsBadArguments) {
  EXPECT_THROW(hi::ButterworthLowPass(4, 600.0, 1000.0), std::invalid_argument);
  EXPECT_THROW(hi::ButterworthLowPass(0, 5.0, 1000.0), std::invalid_argument);
  EXPECT_THROW(hi::centralDifference(Eigen::VectorXd::Zero(2), 0.001), std::invalid_argument);
}

// Decimation with the torque averaged over the window centred on each kept
// sample: exact for a linear signal (the symmetric window has no lag), and
// white noise shrinks by √(window) (closed forms).
TEST(ConditionLog, AveragesTorqueOverTheDecimationWindow) {
  const int N = 20000;
  hi::JointLog log;
  log.joints = {"a", "b"};
  log.time.resize(N);
  log.q = Eigen::MatrixXd::Zero(N, 2);
  log.tau.resize(N, 2);
  std::mt19937 rng(5u);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int k = 0; k < N; ++k) {
    log.time[k] = 1e-3 * k;
    log.tau(k, 0) = 2.0 + 3.0 * log.time[k];  // linear
    log.tau(k, 1) = noise(rng);                // white, σ = 1
  }
  hi::FitSettings fs;
  fs.decimation = 10;  // window of 11 samples
  fs.average_torque = true;
  const hi::ConditionedLog c = hi::conditionLog(log, fs);
  ASSERT_GT(c.time.size(), 1000);
  for (Eigen::Index i = 0; i < c.time.size(); ++i) {
    ASSERT_NEAR(c.tau(i, 0), 2.0 + 3.0 * c.time[i], 1e-9) << i;
  }
  const double sd = std::sqrt(c.tau.col(1).squaredNorm() / static_cast<double>(c.tau.rows()));
  EXPECT_NEAR(sd, 1.0 / std::sqrt(11.0), 0.03);
  fs.average_torque = false;
  const hi::ConditionedLog raw = hi::conditionLog(log, fs);
  EXPECT_NEAR(std::sqrt(raw.tau.col(1).squaredNorm() / static_cast<double>(raw.tau.rows())), 1.0, 0.05);
}

// ---------------------------------------------------------------- least squares
struct Synthetic {
  hi::ConditionedLog log;
  Eigen::VectorXd pi;
};

// Random "true" π: CAD values perturbed by ±30 % plus friction in the
// realistic range (Coulomb 1-5 N·m, viscous 0.2-2 N·m·s/rad).
Eigen::VectorXd randomTruth(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd pi = hm::nominalParameters<Robot>();
  for (int k = 0; k < Sizes::n_inertial; ++k) pi[k] *= 1.0 + 0.3 * u(rng);
  for (int j = 0; j < Robot::nj; ++j) {
    pi[Sizes::frictionColumn(j)] = 3.0 + 2.0 * u(rng);
    pi[Sizes::frictionColumn(j) + 1] = 1.1 + 0.9 * u(rng);
  }
  return pi;
}

// Samples of the trajectory with torques Y π (exact derivatives), q̇* per joint.
Synthetic synthesize(const hi::FourierTrajectory& traj, const Eigen::VectorXd& pi, int N,
                     const hm::JointVector<Robot>& dq_star) {
  Synthetic s;
  s.pi = pi;
  s.log.time.resize(N);
  s.log.q.resize(N, Robot::nj);
  s.log.dq.resize(N, Robot::nj);
  s.log.ddq.resize(N, Robot::nj);
  s.log.tau.resize(N, Robot::nj);
  hm::Data<Robot> d;
  hm::RegressorMatrix<Robot> Y;
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  for (int k = 0; k < N; ++k) {
    const double t = traj.period() * k / N;
    traj.evaluate(t, q, dq, ddq);
    hm::computeRegressor<Robot>(d, q, dq, ddq, dq_star, Y);
    s.log.time[k] = t;
    s.log.q.row(k) = q.transpose();
    s.log.dq.row(k) = dq.transpose();
    s.log.ddq.row(k) = ddq.transpose();
    s.log.tau.row(k) = (Y * pi).transpose();
  }
  return s;
}
Synthetic synthesize(const hi::FourierTrajectory& traj, const Eigen::VectorXd& pi, int N,
                     double dq_star) {
  return synthesize(traj, pi, N, hm::JointVector<Robot>::Constant(dq_star));
}

class LeastSquares : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    bp_ = new hi::BaseParameters(
        hi::computeBaseParameters<Robot>(hm::JointVector<Robot>::Constant(0.01)));
    // The optimized excitation (a short budget) is shared by the tests below.
    hi::ExcitationSettings es;
    es.max_evaluations = 600;
    es.regressor_samples = 60;
    es.constraint_samples = 200;
    limits_ = new hi::JointLimits(hi::jointLimitsFromModel<Robot>(10.0));
    traj_ = new hi::FourierTrajectory(Robot::nj, es.fourier);
    excitation_ = new hi::ExcitationResult(hi::optimizeExcitation<Robot>(*bp_, *limits_, es, *traj_));
  }
  static void TearDownTestSuite() {
    delete bp_;
    delete traj_;
    delete limits_;
    delete excitation_;
  }
  static hi::BaseParameters* bp_;
  static hi::FourierTrajectory* traj_;
  static hi::JointLimits* limits_;
  static hi::ExcitationResult* excitation_;
};
hi::BaseParameters* LeastSquares::bp_ = nullptr;
hi::FourierTrajectory* LeastSquares::traj_ = nullptr;
hi::JointLimits* LeastSquares::limits_ = nullptr;
hi::ExcitationResult* LeastSquares::excitation_ = nullptr;

TEST_F(LeastSquares, ExactFromNoiseFreeTorques) {
  std::mt19937 rng(17u);
  hi::FitSettings fs;
  for (int trial = 0; trial < 3; ++trial) {
    const Synthetic s = synthesize(*traj_, randomTruth(rng), 400, fs.dq_star);
    for (bool weighted : {false, true}) {
      fs.weighted = weighted;
      const hi::FitResult r = hi::fitBaseParameters<Robot>(*bp_, s.log, fs);
      const Eigen::VectorXd beta_true = bp_->K * s.pi;
      EXPECT_LE((r.ls.beta - beta_true).cwiseAbs().maxCoeff(),
                1e-6 * (1.0 + beta_true.cwiseAbs().maxCoeff()))
          << "cond " << r.ls.condition;
      for (int j = 0; j < Robot::nj; ++j) {
        EXPECT_NEAR(r.friction[j].coulomb, s.pi[Sizes::frictionColumn(j)], 1e-6);
        EXPECT_NEAR(r.friction[j].viscous, s.pi[Sizes::frictionColumn(j) + 1], 1e-6);
      }
    }
  }
}

// q̇* of eq. 7 per joint from the slow rows: torques made with a different,
// known q̇* per joint (0.004…0.045 rad/s), fitted from q̇* = 0.01 for all. Rows
// faster than min_speed fix F_v and F_c − F_v q̇* exactly, the slow rows pick
// q̇* on a log grid (steps of 6.7 %), and F_c follows.
TEST_F(LeastSquares, EstimatesDqStarPerJoint) {
  std::mt19937 rng(31u);
  const Eigen::VectorXd pi = randomTruth(rng);
  hm::JointVector<Robot> dq_true;
  for (int j = 0; j < Robot::nj; ++j) dq_true[j] = 0.004 * std::pow(0.045 / 0.004, j / (Robot::nj - 1.0));
  const Synthetic s = synthesize(*traj_, pi, 4000, dq_true);
  hi::FitSettings fs;
  fs.min_speed = 0.05;
  fs.fit_dq_star = true;
  const hi::FitResult r = hi::fitBaseParameters<Robot>(*bp_, s.log, fs);
  for (int j = 0; j < Robot::nj; ++j) {
    EXPECT_NEAR(r.friction[j].dq_star, dq_true[j], 0.07 * dq_true[j]) << r.friction[j].joint;
    EXPECT_NEAR(r.friction[j].viscous, pi[Sizes::frictionColumn(j) + 1], 1e-6) << r.friction[j].joint;
    // eq. 7 outside the band: F_c − F_v q̇* is what the data fix.
    EXPECT_NEAR(r.friction[j].coulomb - r.friction[j].viscous * r.friction[j].dq_star,
                pi[Sizes::frictionColumn(j)] - pi[Sizes::frictionColumn(j) + 1] * dq_true[j], 1e-6);
  }
  // Without the estimate, q̇* stays at the given value.
  fs.fit_dq_star = false;
  const hi::FitResult r0 = hi::fitBaseParameters<Robot>(*bp_, s.log, fs);
  for (int j = 0; j < Robot::nj; ++j) EXPECT_EQ(r0.friction[j].dq_star, fs.dq_star);
}

// The whole chain from a 1 kHz log: q with encoder noise, τ with sensor noise,
// zero-phase low-pass and differences, decimation, weighted LS.
TEST_F(LeastSquares, NoisyLogThroughTheWholePipeline) {
  std::mt19937 rng(23u);
  hi::FitSettings fs;
  fs.min_speed = 0.0;  // synthetic torques follow eq. 7 at every speed: keep every row
  const Eigen::VectorXd pi = randomTruth(rng);
  const int N = 20000;  // two periods at 1 kHz
  hi::FourierTrajectory traj = *traj_;
  hm::Data<Robot> d;
  hm::RegressorMatrix<Robot> Y;
  hi::JointLog log;
  log.time.resize(N);
  log.q.resize(N, Robot::nj);
  log.tau.resize(N, Robot::nj);
  std::normal_distribution<double> q_noise(0.0, 2e-4), tau_noise(0.0, 0.5);
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  for (int k = 0; k < N; ++k) {
    const double t = 1e-3 * k;
    traj.evaluate(t, q, dq, ddq);
    hm::computeRegressor<Robot>(d, q, dq, ddq, hm::JointVector<Robot>::Constant(fs.dq_star), Y);
    const Eigen::VectorXd tau = Y * pi;
    log.time[k] = t;
    for (int j = 0; j < Robot::nj; ++j) {
      log.q(k, j) = q[j] + q_noise(rng);
      log.tau(k, j) = tau[j] + tau_noise(rng);
    }
  }
  const hi::ConditionedLog c = hi::conditionLog(log, fs);
  const hi::FitResult r = hi::fitBaseParameters<Robot>(*bp_, c, fs);
  double worst_c = 0.0, worst_v = 0.0;
  for (int j = 0; j < Robot::nj; ++j) {
    worst_c = std::max(worst_c, std::abs(r.friction[j].coulomb - pi[Sizes::frictionColumn(j)]));
    worst_v = std::max(worst_v, std::abs(r.friction[j].viscous - pi[Sizes::frictionColumn(j) + 1]));
  }
  for (int j = 0; j < Robot::nj; ++j) {
    const int kc = bp_->pureIndex(Sizes::frictionColumn(j));
    std::printf("  %-14s Fc %.3f (true %.3f, std %.3f)  Fv %.3f (true %.3f, std %.3f)\n",
                r.friction[j].joint.c_str(), r.friction[j].coulomb, pi[Sizes::frictionColumn(j)],
                r.ls.beta_std[kc], r.friction[j].viscous, pi[Sizes::frictionColumn(j) + 1],
                r.ls.beta_std[kc + 1]);
  }
  std::printf("[ noisy fit ] worst Coulomb error %.3f N m, worst viscous error %.3f N m s/rad, "
              "residual RMS %.3f..%.3f N m, cond %.1f\n",
              worst_c, worst_v, r.ls.joint_rms.minCoeff(), r.ls.joint_rms.maxCoeff(),
              r.ls.condition);
  // Coulomb friction is well excited (every reversal); viscous friction only by
  // the joint speeds the position limits allow (≤ ~1 rad/s at 0.1 Hz), so its
  // errors are larger but must be consistent with the estimated standard
  // deviation (torque noise is white, so the LS variance formula holds).
  EXPECT_LT(worst_c, 0.1);
  EXPECT_LT(worst_v, 1.0);
  for (int j = 0; j < Robot::nj; ++j) {
    const int kc = bp_->pureIndex(Sizes::frictionColumn(j));
    EXPECT_LT(std::abs(r.friction[j].coulomb - pi[Sizes::frictionColumn(j)]),
              4.0 * r.ls.beta_std[kc] + 0.02);
    EXPECT_LT(std::abs(r.friction[j].viscous - pi[Sizes::frictionColumn(j) + 1]),
              4.0 * r.ls.beta_std[kc + 1] + 0.02);
  }
  // Residual ≈ the torque noise (0.5 N·m): the model explains everything else.
  EXPECT_LT(r.ls.joint_rms.maxCoeff(), 0.6);
  // Prediction on the clean torques of a different trajectory.
  const hi::FourierTrajectory other = randomTrajectory(77u, 0.05);
  const Synthetic v = synthesize(other, pi, 200, fs.dq_star);
  const Eigen::MatrixXd pred =
      hi::predictTorques<Robot>(*bp_, r.ls.beta, v.log.q, v.log.dq, v.log.ddq, fs.dq_star);
  const double rms = std::sqrt((pred - v.log.tau).squaredNorm() / static_cast<double>(pred.size()));
  std::printf("[ noisy fit ] validation torque RMS error %.3f N m\n", rms);
  EXPECT_LT(rms, 0.3);
}

TEST_F(LeastSquares, RejectsUnexcitedData) {
  hi::ConditionedLog c;
  const int N = 200;
  c.time = Eigen::VectorXd::LinSpaced(N, 0.0, 1.0);
  c.q = Eigen::MatrixXd::Constant(N, Robot::nj, 0.2);
  c.dq = Eigen::MatrixXd::Zero(N, Robot::nj);
  c.ddq = Eigen::MatrixXd::Zero(N, Robot::nj);
  c.tau = Eigen::MatrixXd::Zero(N, Robot::nj);
  EXPECT_THROW(hi::fitBaseParameters<Robot>(*bp_, c, hi::FitSettings{}), std::runtime_error);
}

// ---------------------------------------------------------------- excitation
TEST_F(LeastSquares, ExcitationOptimizationLowersTheConditionNumber) {
  const hi::ExcitationResult& r = *excitation_;
  const hi::FourierTrajectory& traj = *traj_;
  const hi::JointLimits& limits = *limits_;
  std::printf("[ excitation ] condition number %.1f -> %.1f after %d evaluations (%s)\n",
              r.cond_initial, r.cond_final, r.evaluations, r.status.c_str());
  EXPECT_LT(r.cond_final, 0.5 * r.cond_initial);
  EXPECT_LE(r.max_violation, 0.0);
  // Limits hold on a grid finer than the optimizer's, and the ends are at rest.
  const int N = 2000;
  Eigen::VectorXd q(Robot::nj), dq(Robot::nj), ddq(Robot::nj);
  for (int k = 0; k <= N; ++k) {
    traj.evaluate(traj.period() * k / N, q, dq, ddq);
    for (int j = 0; j < Robot::nj; ++j) {
      ASSERT_LE(q[j], limits.q_max[j] + 1e-3) << j;
      ASSERT_GE(q[j], limits.q_min[j] - 1e-3) << j;
      ASSERT_LE(std::abs(dq[j]), limits.dq_max[j] * 1.01) << j;
      ASSERT_LE(std::abs(ddq[j]), limits.ddq_max[j] * 1.01) << j;
      if (k == 0 || k == N) {
        ASSERT_NEAR(dq[j], 0.0, 1e-12);
        ASSERT_NEAR(ddq[j], 0.0, 1e-12);
      }
    }
  }
}

// ---------------------------------------------------------------- log and YAML
std::string validHeader() {
  std::string h = "time";
  for (const std::string& j : hi::jointNames<Robot>()) h += ",q_" + j;
  for (const std::string& j : hi::jointNames<Robot>()) h += ",tau_" + j;
  return h;
}

std::string validRow(double t, const std::string& override_cell = "") {
  std::string r = std::to_string(t);
  for (int k = 0; k < 2 * Robot::nj; ++k) r += (k == 3 && !override_cell.empty()) ? "," + override_cell : ",0.1";
  return r;
}

std::string readError(const std::string& text) {
  std::istringstream in(text);
  try {
    hi::readJointLog(in, hi::jointNames<Robot>(), "test.csv");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(JointLogCsv, ReadsAValidLog) {
  std::string text = "# comment\n" + validHeader() + ",extra\n";
  for (int k = 0; k < 20; ++k) text += validRow(0.001 * k) + ",7\n";
  std::istringstream in(text);
  const hi::JointLog log = hi::readJointLog(in, hi::jointNames<Robot>());
  EXPECT_EQ(log.time.size(), 20);
  EXPECT_NEAR(log.dt(), 0.001, 1e-12);
  EXPECT_DOUBLE_EQ(log.q(5, 2), 0.1);
}

TEST(JointLogCsv, MalformedInputGivesAClearError) {
  std::string rows;
  for (int k = 0; k < 20; ++k) rows += validRow(0.001 * k) + "\n";
  // A missing column is named.
  std::string header = validHeader();
  header.replace(header.find(",tau_l_knee"), std::string(",tau_l_knee").size(), ",tau_x");
  EXPECT_NE(readError(header + "\n" + rows).find("missing column(s): tau_l_knee"), std::string::npos)
      << readError(header + "\n" + rows);
  EXPECT_NE(readError("q_a,q_b\n1,2\n").find("missing column(s): time"), std::string::npos);
  // NaN, text, wrong field count, non-uniform time, too short, empty.
  std::string nan_rows = rows + validRow(0.020, "nan") + "\n";
  EXPECT_NE(readError(validHeader() + "\n" + nan_rows).find("line 22, column 'q_l_knee': non-finite"),
            std::string::npos)
      << readError(validHeader() + "\n" + nan_rows);
  EXPECT_NE(readError(validHeader() + "\n" + rows + validRow(0.020, "abc") + "\n").find("not a number"),
            std::string::npos);
  EXPECT_NE(readError(validHeader() + "\n" + rows + "0.02,1,2\n").find("3 fields, the header has 25"),
            std::string::npos);
  EXPECT_NE(readError(validHeader() + "\n" + rows + validRow(0.5) + "\n").find("non-uniform sampling"),
            std::string::npos);
  EXPECT_NE(readError(validHeader() + "\n" + validRow(0.0) + "\n").find("only 1 samples"),
            std::string::npos);
  EXPECT_NE(readError("").find("empty file"), std::string::npos);
}

TEST(ParametersYaml, RoundTripsThroughYamlCpp) {
  std::vector<hi::IdentifiedFriction> f = {{"l_knee", 4.25, 1.5, 0.01}, {"r_hip_yaw", 1.0 / 3.0, 0.2, 0.02}};
  std::vector<hi::IdentifiedBaseParameter> b = {{1.5, 0.01, "l_knee_link.m + 0.3 \"x\""}};
  std::ostringstream out;
  hi::writeParametersYaml(out, "test", f, b);
  const YAML::Node root = YAML::Load(out.str());
  ASSERT_TRUE(root["friction"].IsMap());
  EXPECT_EQ(root["friction"]["l_knee"]["coulomb"].as<double>(), 4.25);
  EXPECT_EQ(root["friction"]["l_knee"]["viscous"].as<double>(), 1.5);
  EXPECT_EQ(root["friction"]["r_hip_yaw"]["coulomb"].as<double>(), 1.0 / 3.0);
  EXPECT_EQ(root["friction"]["r_hip_yaw"]["dq_star"].as<double>(), 0.02);
  EXPECT_EQ(root["base_parameters"][0]["definition"].as<std::string>(), "l_knee_link.m + 0.3 \"x\"");
}

// The controller's configuration keeps the friction per joint as one-line flow
// maps under joint_control.joints; only coulomb/viscous change.
TEST(ParametersYaml, UpdatesTheControllerConfiguration) {
  const std::string text =
      "# header comment\n"
      "controller:\n  dt: 0.001\n"
      "joint_control:\n  leak_time: 0.5\n  # per joint\n  joints:\n"
      "    l_knee:   {torque_constant: 10, coulomb: 5, viscous: 2, dq_star: 0.05, k_f: 0.8}  # ratio 100\n"
      "    r_hip_yaw: {coulomb: 2, viscous: 0.5, dq_star: 0.02}\n"
      "safe_mode:\n  damping: 5\n  joints: {l_knee: {coulomb: 9}}\n";
  const std::vector<std::string> joints = {"l_knee", "r_hip_yaw"};
  const std::vector<double> dq_star = hi::controllerYamlDqStar(text, joints);
  EXPECT_EQ(dq_star, (std::vector<double>{0.05, 0.02}));
  std::vector<std::string> warnings;
  const std::string out = hi::controllerYamlWithFriction(
      text, {{"l_knee", 4.25, 1.5, 0.05}, {"r_hip_yaw", 1.125, -0.01, 0.02}}, &warnings);
  const YAML::Node root = YAML::Load(out);
  EXPECT_EQ(root["joint_control"]["joints"]["l_knee"]["coulomb"].as<double>(), 4.25);
  EXPECT_EQ(root["joint_control"]["joints"]["l_knee"]["viscous"].as<double>(), 1.5);
  EXPECT_EQ(root["joint_control"]["joints"]["l_knee"]["torque_constant"].as<double>(), 10.0);
  EXPECT_EQ(root["joint_control"]["joints"]["l_knee"]["k_f"].as<double>(), 0.8);
  EXPECT_EQ(root["joint_control"]["joints"]["r_hip_yaw"]["coulomb"].as<double>(), 1.125);
  EXPECT_EQ(root["joint_control"]["joints"]["r_hip_yaw"]["viscous"].as<double>(), 0.0);  // clamped
  EXPECT_EQ(warnings.size(), 1u);
  EXPECT_EQ(root["safe_mode"]["joints"]["l_knee"]["coulomb"].as<double>(), 9.0);  // other block untouched
  EXPECT_NE(out.find("# ratio 100"), std::string::npos);  // comments kept
  // dq_star is kept unless asked for (an estimated q̇*, --fit-dq-star).
  EXPECT_EQ(root["joint_control"]["joints"]["l_knee"]["dq_star"].as<double>(), 0.05);
  const YAML::Node with_dq = YAML::Load(hi::controllerYamlWithFriction(
      text, {{"l_knee", 4.25, 1.5, 0.0125}, {"r_hip_yaw", 1.125, 0.5, 0.03}}, nullptr, true));
  EXPECT_EQ(with_dq["joint_control"]["joints"]["l_knee"]["dq_star"].as<double>(), 0.0125);
  EXPECT_EQ(with_dq["joint_control"]["joints"]["r_hip_yaw"]["dq_star"].as<double>(), 0.03);
  EXPECT_EQ(with_dq["joint_control"]["joints"]["l_knee"]["k_f"].as<double>(), 0.8);
  EXPECT_THROW(hi::controllerYamlWithFriction(text, {{"l_ankle_roll", 1, 1, 0.05}}), std::runtime_error);
  EXPECT_THROW(hi::controllerYamlDqStar("controller:\n  dt: 1\n", joints), std::runtime_error);
#ifdef HQP_CONTROLLER_YAML
  // The real Walker3 configuration, when it exists.
  std::ifstream in(HQP_CONTROLLER_YAML);
  if (in) {
    std::stringstream ss;
    ss << in.rdbuf();
    const std::vector<std::string> names = hi::jointNames<Robot>();
    EXPECT_EQ(hi::controllerYamlDqStar(ss.str(), names).size(), names.size());
    std::vector<hi::IdentifiedFriction> f;
    for (const std::string& n : names) f.push_back({n, 3.5, 0.25, 0.05});
    const YAML::Node r = YAML::Load(hi::controllerYamlWithFriction(ss.str(), f));
    for (const std::string& n : names) {
      EXPECT_EQ(r["joint_control"]["joints"][n]["coulomb"].as<double>(), 3.5) << n;
      EXPECT_EQ(r["joint_control"]["joints"][n]["viscous"].as<double>(), 0.25) << n;
    }
#if __has_include("tasks/controller_config_yaml.hpp")
    // The controller's own strict loader reads the result.
    const std::string path = ::testing::TempDir() + "/identified_controller.yaml";
    std::ofstream(path) << hi::controllerYamlWithFriction(ss.str(), f);
    const auto config = hqp::tasks::loadControllerConfig<Robot>(path);
    for (int j = 0; j < Robot::nj; ++j) {
      EXPECT_EQ(config.joint.friction[static_cast<std::size_t>(j)].coulomb, 3.5);
      EXPECT_EQ(config.joint.friction[static_cast<std::size_t>(j)].viscous, 0.25);
    }
#endif
  }
#endif
}

}  // namespace
