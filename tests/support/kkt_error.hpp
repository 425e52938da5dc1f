#pragma once
// KKT residuals of an ActiveSetQp-like solver's answer, computed from its x and multipliers
// alone against the problem's data (tests only).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include "support/brute_force_qp.hpp"

namespace hqp::testing {

struct KktError {
  double stationarity = 0, primal = 0, dual = 0, complementarity = 0;
  double at_bound = 0;  // each active row's distance to its bound, per unit row
  double largest() const { return std::max({stationarity, primal, dual, complementarity}); }
};

template <class Qp, class = void>
struct HasEqualityMultipliers : std::false_type {};
template <class Qp>
struct HasEqualityMultipliers<Qp, std::void_t<decltype(std::declval<const Qp&>().equalityMultipliers())>>
    : std::true_type {};

// Each scaled: stationarity Aᵀ(Ax − b) + Eᵀλ + Σ ±μ c, dual (−μ) and complementarity
// |μ|·|slack| relative to the largest gradient and multiplier term; primal per unit row.
// Problem: any struct with A, b, E, e, C, lower, upper. A solver without equality multipliers
// (the dual method) is checked on problems without E rows (else stationarity is infinite).
template <class Qp, class Problem>
KktError kkt(const Qp& qp, const Problem& p) {
  const Eigen::VectorXd x = qp.x();
  const Eigen::VectorXd g = p.A.transpose() * (p.A * x - p.b);
  Eigen::VectorXd s = g;
  double scale = 1.0 + g.cwiseAbs().maxCoeff();
  KktError k;
  if (p.E.rows() > 0) {
    if constexpr (HasEqualityMultipliers<Qp>::value) {
      const Eigen::VectorXd t = p.E.transpose() * qp.equalityMultipliers();
      s += t;
      scale = std::max(scale, t.cwiseAbs().maxCoeff());
    } else {
      k.stationarity = std::numeric_limits<double>::infinity();
    }
  }
  for (int a = 0; a < qp.numActive(); ++a) {
    const int j = qp.activeRow(a);
    const double mu = qp.multiplier(a);
    const Eigen::VectorXd t = (qp.activeAtUpper(a) ? mu : -mu) * p.C.row(j).transpose();
    s += t;
    scale = std::max(scale, t.cwiseAbs().maxCoeff());
    k.dual = std::max(k.dual, -mu);
    const double bound = qp.activeAtUpper(a) ? p.upper(j) : p.lower(j);
    const double slack = std::abs(p.C.row(j).dot(x) - bound);
    k.complementarity = std::max(k.complementarity, std::abs(mu) * slack);
    k.at_bound = std::max(k.at_bound, slack / std::max(p.C.row(j).norm(), 1e-300));
  }
  k.stationarity = std::max(k.stationarity, s.cwiseAbs().maxCoeff() / scale);
  k.dual /= scale;
  k.complementarity /= scale;
  if (p.E.rows() > 0) {
    const Eigen::VectorXd re = p.E * x - p.e;
    for (int i = 0; i < re.size(); ++i)
      k.primal = std::max(k.primal, std::abs(re(i)) / std::max(p.E.row(i).norm(), 1e-300));
  }
  const Eigen::VectorXd cx = p.C * x;
  for (int j = 0; j < cx.size(); ++j) {
    const double nrm = std::max(p.C.row(j).norm(), 1e-300);
    if (std::isfinite(p.lower(j))) k.primal = std::max(k.primal, (p.lower(j) - cx(j)) / nrm);
    if (std::isfinite(p.upper(j))) k.primal = std::max(k.primal, (cx(j) - p.upper(j)) / nrm);
  }
  return k;
}

}  // namespace hqp::testing
