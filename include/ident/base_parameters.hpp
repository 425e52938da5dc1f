#pragma once
// Base (identifiable) parameters of the regressor of model/regressor.hpp.
// Some columns of Y are zero or linear combinations of others at every state
// (e.g. a first joint about the vertical sees no mass), so only r = rank(W)
// combinations β = K π can be identified. A QR decomposition with column
// pivoting of the regressor stacked over random states, W P = Q [R1 R2],
// gives them numerically (Gautier 1991): the pivoted columns W1 are
// independent, W2 = W1 R1⁻¹ R2, hence W π = W1 (π1 + R1⁻¹ R2 π2) = W1 β.
// Offline code: allocates and throws.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>

#include "model/regressor.hpp"

namespace hqp::ident {

struct BaseParameters {
  int n_full = 0;                // np: entries of π
  int rank = 0;                  // r: number of base parameters
  std::vector<int> independent;  // r columns of Y kept, ascending: Y_B = Y(:, independent)
  Eigen::MatrixXd K;             // r × np: β = K π, and Y π = Y_B K π for every state

  // Y_B (rows × r) from Y (rows × np).
  template <class Derived>
  Eigen::MatrixXd reduce(const Eigen::MatrixBase<Derived>& Y) const {
    Eigen::MatrixXd YB(Y.rows(), rank);
    for (int k = 0; k < rank; ++k) YB.col(k) = Y.col(independent[static_cast<std::size_t>(k)]);
    return YB;
  }
  // Index k of the base parameter that is exactly π(column), or −1 when that
  // column is not a base parameter on its own (it is combined with others).
  int pureIndex(int column) const {
    for (int k = 0; k < rank; ++k) {
      if (independent[static_cast<std::size_t>(k)] != column) continue;
      for (int c = 0; c < n_full; ++c) {
        if (c != column && K(k, c) != 0.0) return -1;
      }
      return k;
    }
    return -1;
  }
};

// Base parameters from a stacked regressor W (rows × np). Columns whose
// pivot |R_kk| is below rel_tol |R_00| are dependent; coefficients of K below
// 1e-9 are set to zero (round-off of exact structural relations).
inline BaseParameters baseParametersFromStack(const Eigen::MatrixXd& W, double rel_tol = 1e-8) {
  if (W.rows() < W.cols()) {
    throw std::invalid_argument("baseParametersFromStack: need at least as many rows (" +
                                std::to_string(W.rows()) + ") as parameters (" +
                                std::to_string(W.cols()) + ")");
  }
  // Scale columns to unit norm so that the threshold does not depend on units
  // (masses vs inertias vs friction). Columns that are zero up to round-off
  // (norm below 1e-10 of the largest; structurally zero, e.g. a product of
  // inertia that no joint sees) are set to zero, not scaled up into noise.
  const int n = static_cast<int>(W.cols());
  Eigen::VectorXd scale(n);
  Eigen::MatrixXd Ws = W;
  const double largest = W.colwise().norm().maxCoeff();
  for (int c = 0; c < n; ++c) {
    const double s = W.col(c).norm();
    if (s > 1e-10 * largest) {
      scale[c] = s;
      Ws.col(c) /= s;
    } else {
      scale[c] = 1.0;
      Ws.col(c).setZero();
    }
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Ws);
  const Eigen::MatrixXd R = qr.matrixR().topRows(n).triangularView<Eigen::Upper>();
  const double r00 = std::abs(R(0, 0));
  int r = 0;
  while (r < n && std::abs(R(r, r)) > rel_tol * r00) ++r;
  const Eigen::VectorXi perm = qr.colsPermutation().indices();
  // β_rel = R1⁻¹ R2 in scaled columns; unscale: π1 + diag(1/s1) β_rel diag(s2) π2.
  Eigen::MatrixXd beta = R.topLeftCorner(r, r).triangularView<Eigen::Upper>().solve(
      R.topRightCorner(r, n - r));
  BaseParameters bp;
  bp.n_full = n;
  bp.rank = r;
  std::vector<int> order(static_cast<std::size_t>(r));
  for (int k = 0; k < r; ++k) order[static_cast<std::size_t>(k)] = k;
  std::sort(order.begin(), order.end(), [&](int x, int y) { return perm[x] < perm[y]; });
  bp.K = Eigen::MatrixXd::Zero(r, n);
  for (int row = 0; row < r; ++row) {
    const int k = order[static_cast<std::size_t>(row)];
    bp.independent.push_back(perm[k]);
    bp.K(row, perm[k]) = 1.0;
    for (int c = 0; c < n - r; ++c) {
      const double value = beta(k, c) * scale[perm[r + c]] / scale[perm[k]];
      if (std::abs(value) > 1e-9) bp.K(row, perm[r + c]) = value;
    }
  }
  return bp;
}

// Random states for the numerical rank: joint positions uniform within the
// limits (±π where unbounded), rates and accelerations normal. A floating base
// gets a random pose and twist.
template <class Robot>
struct RandomStateSampler {
  using VectorQ = typename model::Data<Robot>::VectorQ;
  using VectorV = typename model::Data<Robot>::VectorV;
  std::mt19937 rng;
  explicit RandomStateSampler(unsigned seed) : rng(seed) {}
  void sample(VectorQ& q, VectorV& v, VectorV& a) {
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    constexpr int first = Robot::floating_base ? 1 : 0;
    int iq = 0;
    if constexpr (Robot::floating_base) {
      Eigen::Vector4d quat(normal(rng), normal(rng), normal(rng), normal(rng));
      quat.normalize();
      q.template head<3>() = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
      q.template segment<4>(3) = quat;
      iq = 7;
    }
    for (int j = 0; j < Robot::nj; ++j) {
      const model::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(j + first)];
      constexpr double kPi = 3.14159265358979323846;
      const double lo = std::isfinite(b.lower) ? b.lower : -kPi;
      const double hi = std::isfinite(b.upper) ? b.upper : kPi;
      q[iq + j] = lo + (hi - lo) * unit(rng);
    }
    for (int k = 0; k < Robot::nv; ++k) {
      v[k] = normal(rng);
      a[k] = normal(rng);
    }
  }
};

// Y stacked over `samples` random states (samples·nv × np).
template <class Robot>
Eigen::MatrixXd stackRandomRegressors(int samples, unsigned seed,
                                      const model::JointVector<Robot>& dq_star) {
  using Sizes = model::RegressorSizes<Robot>;
  model::Data<Robot> d;
  RandomStateSampler<Robot> sampler(seed);
  typename model::Data<Robot>::VectorQ q;
  typename model::Data<Robot>::VectorV v, a;
  model::RegressorMatrix<Robot> Y;
  Eigen::MatrixXd W(static_cast<Eigen::Index>(samples) * Robot::nv, Sizes::np);
  for (int s = 0; s < samples; ++s) {
    sampler.sample(q, v, a);
    model::computeRegressor<Robot>(d, q, v, a, dq_star, Y);
    W.middleRows(static_cast<Eigen::Index>(s) * Robot::nv, Robot::nv) = Y;
  }
  return W;
}

// Base parameters of Robot from random states (enough rows: 4 np / nv + 10 samples).
template <class Robot>
BaseParameters computeBaseParameters(const model::JointVector<Robot>& dq_star,
                                     unsigned seed = 7u) {
  using Sizes = model::RegressorSizes<Robot>;
  const int samples = 4 * Sizes::np / Robot::nv + 10;
  return baseParametersFromStack(stackRandomRegressors<Robot>(samples, seed, dq_star));
}

// Names of the entries of π: "<link>.m", ".mx", ".my", ".mz", ".Ixx", ".Iyy",
// ".Izz", ".Ixy", ".Ixz", ".Iyz" per body, "<joint>.Fc", ".Fv" per joint.
template <class Robot>
std::vector<std::string> parameterNames() {
  static const char* const kInertial[10] = {"m",   "mx",  "my",  "mz",  "Ixx",
                                            "Iyy", "Izz", "Ixy", "Ixz", "Iyz"};
  constexpr int first = Robot::floating_base ? 1 : 0;
  std::vector<std::string> names;
  for (int i = 0; i < Robot::nb; ++i) {
    for (const char* p : kInertial) {
      names.push_back(std::string(Robot::bodies[static_cast<std::size_t>(i)].name) + "." + p);
    }
  }
  for (int j = 0; j < Robot::nj; ++j) {
    const std::string joint = Robot::bodies[static_cast<std::size_t>(j + first)].joint;
    names.push_back(joint + ".Fc");
    names.push_back(joint + ".Fv");
  }
  return names;
}

// Human-readable base parameter k: "l_knee_link.Izz + 0.09 l_ankle_link.m + ...".
inline std::string describeBaseParameter(const BaseParameters& bp, int k,
                                         const std::vector<std::string>& names) {
  std::string s = names[static_cast<std::size_t>(bp.independent[static_cast<std::size_t>(k)])];
  for (int c = 0; c < bp.n_full; ++c) {
    const double value = bp.K(k, c);
    if (c == bp.independent[static_cast<std::size_t>(k)] || value == 0.0) continue;
    char buf[64];
    std::snprintf(buf, sizeof buf, " %c %.6g ", value < 0.0 ? '-' : '+', std::abs(value));
    s += buf + names[static_cast<std::size_t>(c)];
  }
  return s;
}

}  // namespace hqp::ident
