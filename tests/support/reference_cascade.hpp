#pragma once
// Independent references for the hierarchy (tests only; dynamic-size Eigen, shares no code
// with include/hqp):
//  - pseudoInverseCascade: the closed-form recursive cascade for equality-only levels,
//      x_1 = A_1⁺ b_1,  N_1 = I − A_1⁺ A_1,
//      x_p = x_{p−1} + (A_p N_{p−1})⁺ (b_p − A_p x_{p−1}),
//      N_p = N_{p−1} − (A_p N_{p−1})⁺ (A_p N_{p−1});
//  - bruteForceCascade: each level solved by enumeration (brute_force_qp.hpp) in the full
//    variable x, with the higher levels' optimal task values imposed as explicit equalities
//    A_k x = A_k x_k* (k < p; A_k x* is unique at a least-squares optimum) and all
//    constraints of levels ≤ p. A level whose constraints cannot be met is handled as
//    HqpWbc documents: its own constraints are dropped for it and every lower level.

#include <Eigen/Dense>

#include <algorithm>
#include <limits>
#include <vector>

#include "support/brute_force_qp.hpp"

namespace hqp::testing {

struct RefLevel {
  Eigen::MatrixXd A;      // stacked tasks (rows x n); rows pre-scaled by √weight if any
  Eigen::VectorXd b;
  Eigen::MatrixXd D;      // stacked constraints (may have 0 rows)
  Eigen::VectorXd lower;
  Eigen::VectorXd upper;
};

struct RefCascade {
  Eigen::VectorXd x;                 // final solution
  std::vector<double> residual;      // ‖A_p x − b_p‖² per level, at the final x
  std::vector<bool> dropped;         // level's own constraints were infeasible and dropped
  std::vector<int> rank;             // rank of A_p N_{p−1} (pseudo-inverse cascade only)
};

// Pseudo-inverse with singular values ≤ tol · (largest row norm of `scale_of`) cut.
inline Eigen::MatrixXd pinvCut(const Eigen::MatrixXd& M, double cut, int* rank = nullptr) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  Eigen::VectorXd sinv = Eigen::VectorXd::Zero(s.size());
  int k = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i)
    if (s(i) > cut) {
      sinv(i) = 1.0 / s(i);
      ++k;
    }
  if (rank) *rank = k;
  return svd.matrixV() * sinv.asDiagonal() * svd.matrixU().transpose();
}

// Equality-only cascade (constraints ignored). Singular values of A_p N_{p−1} below
// tol · max row norm of A_p count as zero.
inline RefCascade pseudoInverseCascade(const std::vector<RefLevel>& levels, int n,
                                       double tol = 1e-9) {
  RefCascade out;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd N = Eigen::MatrixXd::Identity(n, n);
  for (const RefLevel& L : levels) {
    const Eigen::MatrixXd AN = L.A * N;
    const double scale = L.A.rows() > 0 ? L.A.rowwise().norm().maxCoeff() : 0.0;
    int rank = 0;
    const Eigen::MatrixXd P = pinvCut(AN, tol * scale, &rank);
    x = x + P * (L.b - L.A * x);
    N = N - P * AN;
    out.rank.push_back(rank);
  }
  out.x = x;
  for (const RefLevel& L : levels) out.residual.push_back((L.A * x - L.b).squaredNorm());
  out.dropped.assign(levels.size(), false);
  return out;
}

// Minimal least-squares violation of `D x` against [lower, upper] over the set
// {E x = e, lo ≤ C x ≤ up}: min ‖D x − w‖² over (x, w) with lower ≤ w ≤ upper, by brute force.
// Returns d* = D x at the optimum (unique) and the violation Σ (d* − clamp(d*))².
inline bool bruteForceMinViolation(const Eigen::MatrixXd& D, const Eigen::VectorXd& lower,
                                   const Eigen::VectorXd& upper, const Eigen::MatrixXd& E,
                                   const Eigen::VectorXd& e, const Eigen::MatrixXd& C,
                                   const Eigen::VectorXd& lo, const Eigen::VectorXd& up,
                                   Eigen::VectorXd& dstar, double& violation) {
  const Eigen::Index n = D.cols(), m = D.rows(), mc = C.rows();
  Eigen::MatrixXd As(m, n + m);
  As << D, -Eigen::MatrixXd::Identity(m, m);
  Eigen::MatrixXd Es = Eigen::MatrixXd::Zero(E.rows(), n + m);
  Es.leftCols(n) = E;
  Eigen::MatrixXd Cs = Eigen::MatrixXd::Zero(mc + m, n + m);
  Cs.topLeftCorner(mc, n) = C;
  Cs.bottomRightCorner(m, m).setIdentity();
  Eigen::VectorXd ls(mc + m), us(mc + m);
  ls << lo, lower;
  us << up, upper;
  const BruteForceResult r = bruteForceQp(As, Eigen::VectorXd::Zero(m), Es, e, Cs, ls, us);
  if (!r.feasible) return false;
  dstar = D * r.x.head(n);
  violation = 0.0;
  for (Eigen::Index i = 0; i < m; ++i) {
    const double v = std::max(0.0, std::max(lower(i) - dstar(i), dstar(i) - upper(i)));
    violation += v * v;
  }
  return true;
}

// Strict cascade with inequalities by brute-force enumeration (small problems only).
// slack[p]: when level p's constraints are infeasible, relax them minimally (least-squares
// violation first, then the task) instead of dropping them.
inline RefCascade bruteForceCascade(const std::vector<RefLevel>& levels, int n,
                                    double feas_tol = 1e-9,
                                    const std::vector<bool>& slack = {},
                                    std::vector<double>* violation = nullptr) {
  RefCascade out;
  if (violation) violation->assign(levels.size(), 0.0);
  Eigen::MatrixXd E(0, n);
  Eigen::VectorXd e(0);
  Eigen::MatrixXd C(0, n);
  Eigen::VectorXd lo(0), up(0);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  for (size_t p = 0; p < levels.size(); ++p) {
    const RefLevel& L = levels[p];
    const Eigen::Index m = L.D.rows();
    Eigen::MatrixXd C2(C.rows() + m, n);
    Eigen::VectorXd lo2(C.rows() + m), up2(C.rows() + m);
    C2 << C, L.D;
    lo2 << lo, L.lower;
    up2 << up, L.upper;
    BruteForceResult r = bruteForceQp(L.A, L.b, E, e, C2, lo2, up2, feas_tol);
    bool dropped = false;
    Eigen::VectorXd dstar;
    double v = 0.0;
    if (!r.feasible && p < slack.size() && slack[p] &&
        bruteForceMinViolation(L.D, L.lower, L.upper, E, e, C, lo, up, dstar, v)) {
      // Relax the level's own rows to contain d*: exactly the minimal-violation points.
      lo2.tail(m) = L.lower.cwiseMin(dstar);
      up2.tail(m) = L.upper.cwiseMax(dstar);
      r = bruteForceQp(L.A, L.b, E, e, C2, lo2, up2, 1e-8);
      if (violation) (*violation)[p] = v;
      C = C2;
      lo = lo2;
      up = up2;
    } else if (!r.feasible) {
      dropped = true;  // drop this level's own rows (HqpWbc's policy without slacks)
      r = bruteForceQp(L.A, L.b, E, e, C, lo, up, feas_tol);
    } else {
      C = C2;
      lo = lo2;
      up = up2;
    }
    out.dropped.push_back(dropped);
    if (r.feasible) x = r.x;  // (higher levels are always feasible: x_{p−1}* is)
    // Lock this level's task value for the lower levels.
    const Eigen::VectorXd ax = L.A * x;
    Eigen::MatrixXd E2(E.rows() + L.A.rows(), n);
    Eigen::VectorXd e2(E.rows() + L.A.rows());
    E2 << E, L.A;
    e2 << e, ax;
    E = E2;
    e = e2;
  }
  out.x = x;
  for (const RefLevel& L : levels) out.residual.push_back((L.A * x - L.b).squaredNorm());
  return out;
}

}  // namespace hqp::testing
