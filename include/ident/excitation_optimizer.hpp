#pragma once
// Optimal excitation trajectory of §V-B: the free Fourier coefficients
// (ident/fourier_trajectory.hpp, rest at start and end built in) minimize the
// condition number of the base regressor stacked over one period, subject to
// joint position, velocity and acceleration limits checked on a dense time grid.
//
// Method: NLopt's COBYLA (Powell 1994; NLOPT_LN_COBYLA). Why:
//  - the cost is not differentiable (the condition number is a ratio of
//    extreme singular values, which cross), and the limits are maxima over
//    time, so gradient methods such as SLSQP would need smoothed surrogates;
//  - COBYLA handles nonlinear inequality constraints natively (no penalty
//    tuning, unlike an augmented-Lagrangian wrapper) and needs no gradients;
//  - NLopt is maintained and packaged by Debian (libnlopt-cxx-dev).
// The cost is log10(cond) (same minimizer, better scaled for COBYLA's linear
// models). Constraints are normalized by the limit, ≤ 0 when satisfied.
// The start is a random guess scaled joint by joint into the limits, and the
// result is scaled into the limits again (NLopt allows a small violation), so
// the returned trajectory is always feasible on the grid.
// Fixed-base models only (ident/identification.hpp). Offline: allocates, throws.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlopt.hpp>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "ident/base_parameters.hpp"
#include "ident/fourier_trajectory.hpp"
#include "ident/identification.hpp"

namespace hqp::ident {

struct JointLimits {
  Eigen::VectorXd q_min, q_max;  // rad (±inf: unbounded)
  Eigen::VectorXd dq_max;        // rad/s
  Eigen::VectorXd ddq_max;       // rad/s²
};

// Limits of the generated model (URDF <limit>), shrunk by a position margin and
// a velocity scale. URDF has no acceleration limit: one value for every joint.
template <class Robot>
JointLimits jointLimitsFromModel(double ddq_max, double position_margin = 0.05,
                                 double velocity_scale = 1.0) {
  constexpr int first = Robot::floating_base ? 1 : 0;
  JointLimits L;
  L.q_min.resize(Robot::nj);
  L.q_max.resize(Robot::nj);
  L.dq_max.resize(Robot::nj);
  L.ddq_max = Eigen::VectorXd::Constant(Robot::nj, ddq_max);
  for (int j = 0; j < Robot::nj; ++j) {
    const model::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(j + first)];
    L.q_min[j] = b.lower + position_margin;
    L.q_max[j] = b.upper - position_margin;
    if (L.q_min[j] > L.q_max[j]) L.q_min[j] = L.q_max[j] = 0.5 * (b.lower + b.upper);
    L.dq_max[j] = velocity_scale * b.velocity;
  }
  return L;
}

struct ExcitationSettings {
  FourierSettings fourier;           // 5 harmonics, 0.1 Hz
  int regressor_samples = 100;       // samples per period in the condition number
  int constraint_samples = 500;      // samples per period for the limits
  int max_evaluations = 3000;        // NLopt budget
  double max_seconds = 120.0;        // NLopt budget
  double initial_step = 0.05;        // COBYLA's initial trust radius (rad, rad/s)
  double initial_amplitude = 0.5;    // std of the random start coefficients (rad/s)
  unsigned seed = 1;
  double dq_star = 0.01;             // q̇* of eq. 7 in the friction columns
};

struct ExcitationResult {
  double cond_initial = 0.0;  // condition number of the feasible random start
  double cond_final = 0.0;    // after optimization (and the final scaling)
  int evaluations = 0;
  std::string status;         // NLopt's result
  double max_violation = 0.0; // largest normalized constraint (≤ 0: feasible)
};

template <class Robot>
class ExcitationProblem {
 public:
  ExcitationProblem(const BaseParameters& bp, const JointLimits& limits,
                    const ExcitationSettings& s)
      : bp_(bp), L_(limits), s_(s),
        dq_star_(model::JointVector<Robot>::Constant(s.dq_star)) {
    if (L_.q_min.size() != Robot::nj || L_.q_max.size() != Robot::nj ||
        L_.dq_max.size() != Robot::nj || L_.ddq_max.size() != Robot::nj) {
      throw std::invalid_argument("ExcitationProblem: limits must have one entry per joint");
    }
  }

  // Samples (N × nj) of q, q̇, q̈ at N uniform times over one period.
  void sample(const FourierTrajectory& traj, int N, Eigen::MatrixXd& q, Eigen::MatrixXd& dq,
              Eigen::MatrixXd& ddq) const {
    q.resize(N, Robot::nj);
    dq.resize(N, Robot::nj);
    ddq.resize(N, Robot::nj);
    Eigen::VectorXd a(Robot::nj), b(Robot::nj), c(Robot::nj);
    for (int k = 0; k < N; ++k) {
      traj.evaluate(traj.period() * k / N, a, b, c);
      q.row(k) = a.transpose();
      dq.row(k) = b.transpose();
      ddq.row(k) = c.transpose();
    }
  }

  // Condition number of W_B over one period.
  double conditionNumber(const FourierTrajectory& traj) const {
    Eigen::MatrixXd q, dq, ddq;
    sample(traj, s_.regressor_samples, q, dq, ddq);
    const Eigen::MatrixXd W = stackBaseRegressor<Robot>(bp_, q, dq, ddq, dq_star_);
    Eigen::MatrixXd G(W.cols(), W.cols());
    G.setZero();
    G.selfadjointView<Eigen::Lower>().rankUpdate(W.transpose());
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(G, Eigen::EigenvaluesOnly);
    const double lo = es.eigenvalues().minCoeff();
    const double hi = es.eigenvalues().maxCoeff();
    if (!(lo > 0.0)) return std::numeric_limits<double>::infinity();
    return std::sqrt(hi / lo);
  }

  // 4 normalized constraints per joint (≤ 0 when satisfied): upper and lower
  // position, |q̇| and |q̈|.
  Eigen::VectorXd constraints(const FourierTrajectory& traj) const {
    Eigen::MatrixXd q, dq, ddq;
    sample(traj, s_.constraint_samples, q, dq, ddq);
    Eigen::VectorXd g(4 * Robot::nj);
    for (int j = 0; j < Robot::nj; ++j) {
      const double range = std::max(1e-6, std::isfinite(L_.q_max[j] - L_.q_min[j])
                                              ? L_.q_max[j] - L_.q_min[j]
                                              : 1.0);
      g[4 * j] = std::isfinite(L_.q_max[j]) ? (q.col(j).maxCoeff() - L_.q_max[j]) / range : -1.0;
      g[4 * j + 1] =
          std::isfinite(L_.q_min[j]) ? (L_.q_min[j] - q.col(j).minCoeff()) / range : -1.0;
      g[4 * j + 2] = dq.col(j).cwiseAbs().maxCoeff() / L_.dq_max[j] - 1.0;
      g[4 * j + 3] = ddq.col(j).cwiseAbs().maxCoeff() / L_.ddq_max[j] - 1.0;
    }
    return g;
  }

  // Moves q0 into the limits and scales each joint's motion about q0 so that
  // every limit holds on the grid (rest at the ends is kept: scaling is linear).
  void makeFeasible(FourierTrajectory& traj) const {
    Eigen::MatrixXd q, dq, ddq;
    for (int j = 0; j < Robot::nj; ++j) {
      traj.q0(j) = std::min(std::max(traj.q0(j), L_.q_min[j]), L_.q_max[j]);
    }
    sample(traj, s_.constraint_samples, q, dq, ddq);
    for (int j = 0; j < Robot::nj; ++j) {
      const double q0 = traj.q0(j);
      double k = 1.0;
      const double up = q.col(j).maxCoeff() - q0;
      const double down = q0 - q.col(j).minCoeff();
      if (up > 0.0 && std::isfinite(L_.q_max[j])) k = std::min(k, (L_.q_max[j] - q0) / up);
      if (down > 0.0 && std::isfinite(L_.q_min[j])) k = std::min(k, (q0 - L_.q_min[j]) / down);
      const double vmax = dq.col(j).cwiseAbs().maxCoeff();
      const double amax = ddq.col(j).cwiseAbs().maxCoeff();
      if (vmax > 0.0) k = std::min(k, L_.dq_max[j] / vmax);
      if (amax > 0.0) k = std::min(k, L_.ddq_max[j] / amax);
      if (k < 1.0) traj.scaleJoint(j, 0.999 * k);
    }
  }

  // Random coefficients (normal, std initial_amplitude), q0 at mid-range, made feasible.
  FourierTrajectory randomStart() const {
    FourierTrajectory traj(Robot::nj, s_.fourier);
    std::mt19937 rng(s_.seed);
    std::normal_distribution<double> normal(0.0, s_.initial_amplitude);
    Eigen::VectorXd x(traj.numFree());
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = normal(rng);
    traj.setFree(x);
    for (int j = 0; j < Robot::nj; ++j) {
      const bool bounded = std::isfinite(L_.q_min[j]) && std::isfinite(L_.q_max[j]);
      traj.q0(j) = bounded ? 0.5 * (L_.q_min[j] + L_.q_max[j]) : 0.0;
    }
    makeFeasible(traj);
    return traj;
  }

 private:
  const BaseParameters& bp_;
  JointLimits L_;
  ExcitationSettings s_;
  model::JointVector<Robot> dq_star_;
};

// Optimizes `traj` in place (start: ExcitationProblem::randomStart() when
// `traj` is all zeros, else its current coefficients made feasible).
template <class Robot>
ExcitationResult optimizeExcitation(const BaseParameters& bp, const JointLimits& limits,
                                    const ExcitationSettings& s, FourierTrajectory& traj) {
  const ExcitationProblem<Robot> problem(bp, limits, s);
  if (traj.free().isZero()) {
    traj = problem.randomStart();
  } else {
    problem.makeFeasible(traj);
  }
  ExcitationResult res;
  res.cond_initial = problem.conditionNumber(traj);

  struct Context {
    const ExcitationProblem<Robot>* problem;
    FourierTrajectory work;
    int evaluations;
  } ctx{&problem, traj, 0};
  nlopt::opt opt(nlopt::LN_COBYLA, static_cast<unsigned>(traj.numFree()));
  opt.set_min_objective(
      +[](unsigned n, const double* x, double*, void* data) {
        Context& c = *static_cast<Context*>(data);
        c.work.setFree(Eigen::Map<const Eigen::VectorXd>(x, static_cast<Eigen::Index>(n)));
        ++c.evaluations;
        const double cond = c.problem->conditionNumber(c.work);
        return std::isfinite(cond) ? std::log10(cond) : 1e3;
      },
      &ctx);
  const unsigned m = 4u * Robot::nj;
  opt.add_inequality_mconstraint(
      +[](unsigned, double* result, unsigned n, const double* x, double*, void* data) {
        Context& c = *static_cast<Context*>(data);
        c.work.setFree(Eigen::Map<const Eigen::VectorXd>(x, static_cast<Eigen::Index>(n)));
        const Eigen::VectorXd g = c.problem->constraints(c.work);
        for (Eigen::Index i = 0; i < g.size(); ++i) result[i] = g[i];
      },
      &ctx, std::vector<double>(m, 1e-4));
  opt.set_maxeval(s.max_evaluations);
  opt.set_maxtime(s.max_seconds);
  opt.set_xtol_rel(1e-6);
  opt.set_initial_step(s.initial_step);
  std::vector<double> x(traj.free().data(), traj.free().data() + traj.numFree());
  double f = 0.0;
  try {
    const nlopt::result r = opt.optimize(x, f);
    switch (r) {
      case nlopt::SUCCESS: res.status = "success"; break;
      case nlopt::STOPVAL_REACHED: res.status = "stopval reached"; break;
      case nlopt::FTOL_REACHED: res.status = "ftol reached"; break;
      case nlopt::XTOL_REACHED: res.status = "xtol reached"; break;
      case nlopt::MAXEVAL_REACHED: res.status = "evaluation budget reached"; break;
      case nlopt::MAXTIME_REACHED: res.status = "time budget reached"; break;
      default: res.status = "nlopt result " + std::to_string(static_cast<int>(r)); break;
    }
  } catch (const nlopt::roundoff_limited&) {
    res.status = "roundoff limited (best point kept)";
  }
  res.evaluations = ctx.evaluations;
  FourierTrajectory best = traj;
  best.setFree(Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())));
  problem.makeFeasible(best);
  const double cond = problem.conditionNumber(best);
  // Keep the start if the optimizer made nothing better.
  if (cond < res.cond_initial) traj = best;
  res.cond_final = problem.conditionNumber(traj);
  res.max_violation = problem.constraints(traj).maxCoeff();
  return res;
}

}  // namespace hqp::ident
