#pragma once
// The identification pipeline of §V-B for a robot on a fixed rig (the model
// generated WITHOUT FLOATING_BASE, i.e. the root link, e.g. the torso, bolted
// to the world):
//   measured q → zero-phase low-pass → q̇, q̈ by central differences →
//   decimation → stacked base regressor W_B → (weighted) LS β against τ.
// τ is NOT low-passed by default: LS averages zero-mean noise anyway, and a
// low-pass would smear the Coulomb step at velocity reversals while the
// regressor, computed from q̇, keeps it sharp — a bias on F_c. The filter is
// zero-phase, so q, q̇, q̈ stay aligned in time with the raw τ.
// The identified β predicts τ = Y_B(q, q̇, q̈) β; the friction parameters of a
// joint are base parameters on their own and go to the controller's YAML.
// Offline code: allocates and throws.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ident/base_parameters.hpp"
#include "ident/filtering.hpp"
#include "ident/joint_log.hpp"
#include "ident/least_squares.hpp"
#include "ident/parameters_yaml.hpp"
#include "model/regressor.hpp"

namespace hqp::ident {

template <class Robot>
std::vector<std::string> jointNames() {
  constexpr int first = Robot::floating_base ? 1 : 0;
  std::vector<std::string> names;
  for (int j = 0; j < Robot::nj; ++j) {
    names.emplace_back(Robot::bodies[static_cast<std::size_t>(j + first)].joint);
  }
  return names;
}

// W_B (N·nj × r) for joint trajectories given as N × nj matrices.
template <class Robot>
Eigen::MatrixXd stackBaseRegressor(const BaseParameters& bp, const Eigen::MatrixXd& q,
                                   const Eigen::MatrixXd& dq, const Eigen::MatrixXd& ddq,
                                   const model::JointVector<Robot>& dq_star) {
  static_assert(!Robot::floating_base,
                "identification from joint torques needs a fixed-base model of the rig "
                "(generate the robot without FLOATING_BASE)");
  constexpr int nj = Robot::nj;
  const Eigen::Index N = q.rows();
  if (q.cols() != nj || dq.cols() != nj || ddq.cols() != nj || dq.rows() != N || ddq.rows() != N) {
    throw std::invalid_argument("stackBaseRegressor: trajectories must be N x " +
                                std::to_string(nj));
  }
  model::Data<Robot> d;
  model::RegressorMatrix<Robot> Y;
  typename model::Data<Robot>::VectorQ qk;
  typename model::Data<Robot>::VectorV vk, ak;
  Eigen::MatrixXd W(N * nj, bp.rank);
  for (Eigen::Index k = 0; k < N; ++k) {
    qk = q.row(k).transpose();
    vk = dq.row(k).transpose();
    ak = ddq.row(k).transpose();
    model::computeRegressor<Robot>(d, qk, vk, ak, dq_star, Y);
    for (int c = 0; c < bp.rank; ++c) {
      W.block(k * nj, c, nj, 1) = Y.col(bp.independent[static_cast<std::size_t>(c)]);
    }
  }
  return W;
}

struct FitSettings {
  int filter_order = 4;      // Butterworth order (applied forward and backward)
  double cutoff_hz = 5.0;    // low-pass cutoff for q and τ
  int decimation = 10;       // keep every n-th filtered sample in the LS
  double trim_s = 0.5;       // drop this much at both ends (filter and difference edges)
  bool weighted = true;      // per-joint weighting by the OLS residual
  bool filter_torque = false;  // low-pass τ as well (see below)
  // τ of each kept sample = mean of the raw τ over the decimation window
  // centred on it (2·⌊decimation/2⌋ + 1 samples): the decimated rows then use
  // every measured sample, which divides white torque noise by ~√decimation,
  // while the short symmetric window adds no lag and blurs a Coulomb step over
  // ±decimation/2 samples only (one kept row per reversal).
  bool average_torque = false;
  double dq_star = 0.01;     // q̇* of eq. 7 (rad/s), same for every joint …
  std::vector<double> dq_star_joint;  // … unless given per joint (e.g. the controller's)
  // Rows of joints slower than this are left out of the fit (0: keep all):
  // near rest a geared joint sticks, and its friction torque is then anything
  // within ±F_c, which no function of q̇ (eq. 7 included) describes.
  double min_speed = 0.05;   // rad/s
  // Estimate q̇* of eq. 7 per joint (fitDqStar below) instead of taking it as given.
  bool fit_dq_star = false;
  double dq_star_min = 0.001;  // search range of q̇* (rad/s); the upper end is min_speed
};

// q̇* per joint from the settings.
template <class Robot>
model::JointVector<Robot> dqStar(const FitSettings& s) {
  if (s.dq_star_joint.empty()) return model::JointVector<Robot>::Constant(s.dq_star);
  if (static_cast<int>(s.dq_star_joint.size()) != Robot::nj) {
    throw std::invalid_argument("FitSettings: dq_star_joint needs one value per joint");
  }
  model::JointVector<Robot> v;
  for (int j = 0; j < Robot::nj; ++j) v[j] = s.dq_star_joint[static_cast<std::size_t>(j)];
  return v;
}

// Filtered and differentiated samples (N × nj each) after trimming and decimation.
struct ConditionedLog {
  Eigen::VectorXd time;
  Eigen::MatrixXd q, dq, ddq, tau;
};

inline ConditionedLog conditionLog(const JointLog& log, const FitSettings& s) {
  const double dt = log.dt();
  const ButterworthLowPass lp(s.filter_order, s.cutoff_hz, 1.0 / dt);
  const Eigen::Index N = log.time.size();
  const Eigen::Index n = log.q.cols();
  Eigen::MatrixXd qf(N, n), dqf(N, n), ddqf(N, n), tauf(N, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    qf.col(j) = lp.filtfilt(log.q.col(j));
    dqf.col(j) = centralDifference(qf.col(j), dt);
    ddqf.col(j) = centralDifference(dqf.col(j), dt);
    tauf.col(j) = s.filter_torque ? Eigen::VectorXd(lp.filtfilt(log.tau.col(j)))
                                  : Eigen::VectorXd(log.tau.col(j));
  }
  const Eigen::Index trim = static_cast<Eigen::Index>(s.trim_s / dt);
  const int dec = s.decimation < 1 ? 1 : s.decimation;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = trim; k < N - trim; k += dec) keep.push_back(k);
  ConditionedLog c;
  const Eigen::Index M = static_cast<Eigen::Index>(keep.size());
  c.time.resize(M);
  c.q.resize(M, n);
  c.dq.resize(M, n);
  c.ddq.resize(M, n);
  c.tau.resize(M, n);
  for (Eigen::Index i = 0; i < M; ++i) {
    const Eigen::Index k = keep[static_cast<std::size_t>(i)];
    c.time[i] = log.time[k];
    c.q.row(i) = qf.row(k);
    c.dq.row(i) = dqf.row(k);
    c.ddq.row(i) = ddqf.row(k);
    if (s.average_torque && dec > 1) {
      const Eigen::Index h = std::min<Eigen::Index>({dec / 2, k, N - 1 - k});
      c.tau.row(i) = tauf.middleRows(k - h, 2 * h + 1).colwise().mean();
    } else {
      c.tau.row(i) = tauf.row(k);
    }
  }
  return c;
}

// Row-major stacking of an N × nj torque matrix into the order of W_B.
inline Eigen::VectorXd stackTorques(const Eigen::MatrixXd& tau) {
  Eigen::VectorXd y(tau.size());
  for (Eigen::Index k = 0; k < tau.rows(); ++k) y.segment(k * tau.cols(), tau.cols()) = tau.row(k).transpose();
  return y;
}

// Predicted torques (N × nj) with base parameters β.
template <class Robot>
Eigen::MatrixXd predictTorques(const BaseParameters& bp, const Eigen::VectorXd& beta,
                               const Eigen::MatrixXd& q, const Eigen::MatrixXd& dq,
                               const Eigen::MatrixXd& ddq, const model::JointVector<Robot>& dq_star) {
  const Eigen::VectorXd y = stackBaseRegressor<Robot>(bp, q, dq, ddq, dq_star) * beta;
  Eigen::MatrixXd tau(q.rows(), Robot::nj);
  for (Eigen::Index k = 0; k < q.rows(); ++k) tau.row(k) = y.segment(k * Robot::nj, Robot::nj).transpose();
  return tau;
}
template <class Robot>
Eigen::MatrixXd predictTorques(const BaseParameters& bp, const Eigen::VectorXd& beta,
                               const Eigen::MatrixXd& q, const Eigen::MatrixXd& dq,
                               const Eigen::MatrixXd& ddq, double dq_star) {
  return predictTorques<Robot>(bp, beta, q, dq, ddq, model::JointVector<Robot>::Constant(dq_star));
}

struct FitResult {
  LeastSquaresResult ls;
  std::vector<IdentifiedFriction> friction;      // per joint, from the base parameters
  std::vector<IdentifiedBaseParameter> base;     // every base parameter with its definition
};

// q̇* of eq. 7 per joint from the slow rows the fit leaves out (|q̇| < min_speed).
// A geared joint does not switch its Coulomb torque at q̇ = 0 but over a small
// band of speeds (pre-sliding, creep of a soft stiction); eq. 7 models this band
// as a ramp of half-width q̇*, a user value in the paper. For q̇* ≤ min_speed
// every fitted row lies outside the band, where eq. 7 reads
// (F_c − F_v q̇*) sign(q̇) + F_v q̇: changing q̇* only re-labels F_c and leaves the
// fit itself unchanged. So, per joint, with the fitted torques of every other
// term held, q̇* is the value on a log grid over [dq_star_min, min_speed] that
// minimizes the squared residual of that joint's slow rows (friction acts on its
// own joint only), and F_c is moved to keep F_c − F_v q̇*. Joints with fewer than
// 20 slow rows keep the given q̇*.
template <class Robot>
void fitDqStar(const BaseParameters& bp, const ConditionedLog& c, const FitSettings& s, FitResult& r) {
  using Sizes = model::RegressorSizes<Robot>;
  const model::JointVector<Robot> dq0 = dqStar<Robot>(s);
  if (!(s.min_speed > s.dq_star_min) || !(s.dq_star_min > 0.0)) {
    throw std::invalid_argument("fitDqStar: needs 0 < dq_star_min < min_speed");
  }
  const Eigen::MatrixXd pred = predictTorques<Robot>(bp, r.ls.beta, c.q, c.dq, c.ddq, dq0);
  constexpr int grid = 60;
  for (int j = 0; j < Robot::nj; ++j) {
    const int kc = bp.pureIndex(Sizes::frictionColumn(j));
    const int kv = bp.pureIndex(Sizes::frictionColumn(j) + 1);
    const double fc = r.ls.beta[kc], fv = r.ls.beta[kv];
    const double fc0 = fc - fv * dq0[j];  // F_c − F_v q̇*: what the fitted rows determine
    std::vector<Eigen::Index> slow;
    for (Eigen::Index k = 0; k < c.dq.rows(); ++k) {
      if (std::abs(c.dq(k, j)) < s.min_speed) slow.push_back(k);
    }
    if (slow.size() < 20) continue;
    double best = -1.0, best_sse = 0.0;
    for (int g = 0; g <= grid; ++g) {
      const double ds = s.dq_star_min * std::pow(s.min_speed / s.dq_star_min, static_cast<double>(g) / grid);
      double sse = 0.0;
      for (const Eigen::Index k : slow) {
        const double v = c.dq(k, j);
        const model::FrictionBasis old_phi = model::frictionBasis(v, dq0[j]);
        const model::FrictionBasis phi = model::frictionBasis(v, ds);
        const double e = c.tau(k, j) - pred(k, j) + fc * old_phi.coulomb + fv * old_phi.viscous -
                         (fc0 + fv * ds) * phi.coulomb - fv * phi.viscous;
        sse += e * e;
      }
      if (best < 0.0 || sse < best_sse) {
        best = ds;
        best_sse = sse;
      }
    }
    r.ls.beta[kc] = fc0 + fv * best;
    r.friction[static_cast<std::size_t>(j)].coulomb = r.ls.beta[kc];
    r.friction[static_cast<std::size_t>(j)].dq_star = best;
    r.base[static_cast<std::size_t>(kc)].value = r.ls.beta[kc];
  }
}

// q̇* per joint of a fit (the given one, or the estimated one with fit_dq_star).
template <class Robot>
model::JointVector<Robot> dqStar(const FitResult& r) {
  model::JointVector<Robot> v;
  for (int j = 0; j < Robot::nj; ++j) v[j] = r.friction[static_cast<std::size_t>(j)].dq_star;
  return v;
}


// Base parameters from conditioned samples.
template <class Robot>
FitResult fitBaseParameters(const BaseParameters& bp, const ConditionedLog& c,
                            const FitSettings& s) {
  using Sizes = model::RegressorSizes<Robot>;
  const model::JointVector<Robot> dq_star = dqStar<Robot>(s);
  FitResult r;
  {
    const Eigen::MatrixXd W = stackBaseRegressor<Robot>(bp, c.q, c.dq, c.ddq, dq_star);
    std::vector<bool> use;
    if (s.min_speed > 0.0) {
      for (Eigen::Index k = 0; k < c.dq.rows(); ++k) {
        for (int j = 0; j < Robot::nj; ++j) use.push_back(std::abs(c.dq(k, j)) >= s.min_speed);
      }
    }
    r.ls = solveLeastSquares(W, stackTorques(c.tau), Robot::nj, s.weighted, use);
  }
  const std::vector<std::string> names = parameterNames<Robot>();
  const std::vector<std::string> joints = jointNames<Robot>();
  for (int k = 0; k < bp.rank; ++k) {
    r.base.push_back({r.ls.beta[k], r.ls.beta_std[k], describeBaseParameter(bp, k, names)});
  }
  for (int j = 0; j < Robot::nj; ++j) {
    const int kc = bp.pureIndex(Sizes::frictionColumn(j));
    const int kv = bp.pureIndex(Sizes::frictionColumn(j) + 1);
    if (kc < 0 || kv < 0) {
      throw std::runtime_error("friction of joint " + joints[static_cast<std::size_t>(j)] +
                               " is not identifiable on its own");
    }
    r.friction.push_back({joints[static_cast<std::size_t>(j)], r.ls.beta[kc], r.ls.beta[kv], dq_star[j]});
  }
  if (s.fit_dq_star) fitDqStar<Robot>(bp, c, s, r);
  return r;
}

}  // namespace hqp::ident
