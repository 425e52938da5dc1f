#pragma once
// Least-squares estimate of the base parameters (§V-B, "dynamic parameters
// optimization"): min_β || G (W_B β − τ) ||² with W_B the base regressor
// stacked over the samples (row k·n + j: sample k, joint j) and G an optional
// diagonal weighting per joint.
//
// Weighting (Gautier & Poignet 2001): a first ordinary LS gives the residual
// standard deviation σ_j of each joint; the rows of joint j are then scaled by
// 1/σ_j and the problem is solved again, so that a noisy joint does not
// dominate the others.
//
// Physical consistency (positive masses, positive-definite inertias satisfying
// the triangle inequality) is NOT enforced: base parameters are linear
// combinations of the link parameters, and constraining them needs a
// semidefinite program over the full parameters. The estimate is reported
// with its standard deviations so that poorly excited combinations are visible.
// Offline code: allocates and throws.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

namespace hqp::ident {

struct LeastSquaresResult {
  Eigen::VectorXd beta;        // base parameters (r)
  Eigen::VectorXd beta_std;    // standard deviations of beta (r), from the residual
  Eigen::VectorXd joint_rms;   // residual RMS per joint (n), of the final estimate
  Eigen::VectorXd joint_sigma; // σ_j used as weights (n); ones when unweighted
  double condition = 0.0;      // condition number of the (weighted) stacked regressor
};

// `use` (optional, one flag per row) leaves rows out, e.g. joints inside the
// stiction band where eq. 7 does not describe the friction torque.
inline LeastSquaresResult solveLeastSquares(const Eigen::MatrixXd& W, const Eigen::VectorXd& tau,
                                            int joints, bool weighted,
                                            const std::vector<bool>& use = {}) {
  const Eigen::Index rows = W.rows();
  const Eigen::Index r = W.cols();
  if (tau.size() != rows) throw std::invalid_argument("solveLeastSquares: W and tau disagree");
  if (joints < 1 || rows % joints != 0) {
    throw std::invalid_argument("solveLeastSquares: rows must be samples x joints");
  }
  if (!use.empty() && static_cast<Eigen::Index>(use.size()) != rows) {
    throw std::invalid_argument("solveLeastSquares: one flag per row in `use`");
  }
  const auto used = [&](Eigen::Index row) { return use.empty() || use[static_cast<std::size_t>(row)]; };
  Eigen::Index n_used = 0;
  for (Eigen::Index row = 0; row < rows; ++row) n_used += used(row) ? 1 : 0;
  if (n_used <= r) {  // a data problem (too short, or the joints hardly move), not a bug
    throw std::runtime_error("solveLeastSquares: " + std::to_string(n_used) +
                             " usable equations for " + std::to_string(r) + " unknowns");
  }
  if (!W.allFinite() || !tau.allFinite()) {
    throw std::invalid_argument("solveLeastSquares: non-finite regressor or torque");
  }
  const Eigen::Index samples = rows / joints;
  LeastSquaresResult res;
  res.joint_sigma = Eigen::VectorXd::Ones(joints);

  // Solves the problem weighted by 1/sigma; cov = (WᵀG²W)⁻¹.
  const auto solve = [&](const Eigen::VectorXd& sigma, Eigen::VectorXd& beta,
                         Eigen::MatrixXd& cov) {
    Eigen::MatrixXd Wg = W;
    Eigen::VectorXd yg = tau;
    for (Eigen::Index k = 0; k < samples; ++k) {
      for (int j = 0; j < joints; ++j) {
        const Eigen::Index row = k * joints + j;
        if (used(row)) {
          Wg.row(row) /= sigma[j];
          yg[row] /= sigma[j];
        } else {
          Wg.row(row).setZero();
          yg[row] = 0.0;
        }
      }
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Wg);
    if (qr.rank() < r) {
      throw std::runtime_error("solveLeastSquares: the data do not excite every base parameter (rank " +
                               std::to_string(qr.rank()) + " < " + std::to_string(r) +
                               "); use an excitation trajectory");
    }
    beta = qr.solve(yg);
    // W P = Q R, so (WᵀW)⁻¹ = P R⁻¹ R⁻ᵀ Pᵀ.
    const Eigen::MatrixXd R = qr.matrixR().topLeftCorner(r, r).triangularView<Eigen::Upper>();
    const Eigen::MatrixXd Rinv =
        R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(r, r));
    cov = qr.colsPermutation() * (Rinv * Rinv.transpose()) * qr.colsPermutation().transpose();
  };

  Eigen::MatrixXd cov;
  solve(res.joint_sigma, res.beta, cov);
  const auto jointRms = [&](const Eigen::VectorXd& beta) {
    const Eigen::VectorXd e = W * beta - tau;
    Eigen::VectorXd rms = Eigen::VectorXd::Zero(joints);
    Eigen::VectorXd count = Eigen::VectorXd::Zero(joints);
    for (Eigen::Index k = 0; k < samples; ++k) {
      for (int j = 0; j < joints; ++j) {
        if (!used(k * joints + j)) continue;
        rms[j] += e[k * joints + j] * e[k * joints + j];
        count[j] += 1.0;
      }
    }
    return Eigen::VectorXd(rms.cwiseQuotient(count.cwiseMax(1.0)).cwiseSqrt());
  };
  if (weighted) {
    Eigen::VectorXd sigma = jointRms(res.beta);
    const double floor = 1e-9 * (1.0 + sigma.maxCoeff());
    for (int j = 0; j < joints; ++j) sigma[j] = std::max(sigma[j], floor);
    res.joint_sigma = sigma;
    solve(res.joint_sigma, res.beta, cov);
  }
  res.joint_rms = jointRms(res.beta);
  // Residual variance of the (weighted) problem, then cov(β) = σ² (WᵀG²W)⁻¹.
  double ss = 0.0;
  const Eigen::VectorXd e = W * res.beta - tau;
  for (Eigen::Index k = 0; k < samples; ++k) {
    for (int j = 0; j < joints; ++j) {
      if (!used(k * joints + j)) continue;
      const double w = e[k * joints + j] / res.joint_sigma[j];
      ss += w * w;
    }
  }
  const double var = ss / static_cast<double>(n_used - r);
  res.beta_std = (var * cov.diagonal()).cwiseSqrt();
  // Exact condition number of the weighted regressor: sqrt of the ratio of the
  // extreme eigenvalues of the covariance (inverse Gram matrix).
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(cov, Eigen::EigenvaluesOnly);
  res.condition = std::sqrt(es.eigenvalues().maxCoeff() / es.eigenvalues().minCoeff());
  return res;
}

}  // namespace hqp::ident
