#pragma once
// KKT residuals of an ActiveSetQp-like solver's answer, computed from its x and multipliers
// alone against the problem's data (tests only).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "support/brute_force_qp.hpp"

namespace hqp::testing {

struct KktError {
  double stationarity = 0, primal = 0, dual = 0, complementarity = 0;
};

// Each scaled: stationarity Aᵀ(Ax − b) + Eᵀλ + Σ ±μ c relative to the gradient and multiplier
// terms, primal per unit row, dual (−μ) and complementarity |μ|·|slack| relative to that scale.
template <class Qp>
KktError kkt(const Qp& qp, const RandomQp& p) {
  const Eigen::VectorXd x = qp.x();
  const Eigen::VectorXd g = p.A.transpose() * (p.A * x - p.b);
  Eigen::VectorXd s = g;
  double scale = 1.0 + g.cwiseAbs().maxCoeff();
  if (p.E.rows() > 0) {
    const Eigen::VectorXd t = p.E.transpose() * qp.equalityMultipliers();
    s += t;
    scale = std::max(scale, t.cwiseAbs().maxCoeff());
  }
  KktError k;
  for (int a = 0; a < qp.numActive(); ++a) {
    const int j = qp.activeRow(a);
    const double mu = qp.multiplier(a);
    const Eigen::VectorXd t = (qp.activeAtUpper(a) ? mu : -mu) * p.C.row(j).transpose();
    s += t;
    scale = std::max(scale, t.cwiseAbs().maxCoeff());
    k.dual = std::max(k.dual, -mu);
    const double bound = qp.activeAtUpper(a) ? p.upper(j) : p.lower(j);
    k.complementarity =
        std::max(k.complementarity, std::abs(mu) * std::abs(p.C.row(j).dot(x) - bound) / scale);
  }
  k.stationarity = s.cwiseAbs().maxCoeff() / scale;
  if (p.E.rows() > 0) {
    const Eigen::VectorXd re = p.E * x - p.e;
    for (int i = 0; i < re.size(); ++i)
      k.primal = std::max(k.primal, std::abs(re(i)) / std::max(1.0, p.E.row(i).norm()));
  }
  const Eigen::VectorXd cx = p.C * x;
  for (int j = 0; j < cx.size(); ++j) {
    const double nrm = std::max(p.C.row(j).norm(), 1e-300);
    if (std::isfinite(p.lower(j))) k.primal = std::max(k.primal, (p.lower(j) - cx(j)) / nrm);
    if (std::isfinite(p.upper(j))) k.primal = std::max(k.primal, (cx(j) - p.upper(j)) / nrm);
  }
  k.dual /= scale;
  return k;
}

}  // namespace hqp::testing
