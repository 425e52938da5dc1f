#pragma once
// Minimum-norm least squares  p = M⁺ r  for the active-set QP, with Householder
// reflections on compile-time max-size storage (never allocates; Eigen 3.4's
// CompleteOrthogonalDecomposition allocates in solve()).
// Fast paths (one unpivoted QR, used when it shows full rank):
//   tall, m ≥ c:  M = Q [R; 0]        ⇒ p = R⁻¹ (Qᵀ r)(0:c)              2 m c² flops
//   wide, m < c:  Mᵀ = V [R; 0]       ⇒ p = V [R⁻ᵀ r; 0]  (exact, min-norm) 2 c m² flops
// Otherwise (rank-deficient or nearly so) a complete orthogonal decomposition:
//   1. M P = Q [R11 R12; 0 0]    (QR with column pivoting, rank r revealed on |R(i,i)|)
//   2. [R11 R12]ᵀ = U [L; 0]     (unpivoted QR of the r wide rows)
//   ⇒  M = Q [Lᵀ 0; 0 0] Uᵀ Pᵀ and  p = P U [L⁻ᵀ (Qᵀ r)(0:r); 0].

#include <Eigen/Core>
#include <Eigen/Householder>

#include <cmath>

namespace hqp::detail {

// Workspace for M of at most MaxM × MaxC.
template <int MaxM, int MaxC>
struct QpMinNormWorkspace {
  static constexpr int MaxD = MaxM < MaxC ? MaxM : MaxC;
  static constexpr int MaxT = MaxM > MaxC ? MaxM : MaxC;
  Eigen::Matrix<double, MaxC, MaxM> T;      // Mᵀ, or [R11 R12]ᵀ, and its QR
  Eigen::Matrix<double, MaxM, MaxC> S;      // copy of M for the pivoted fallback
  Eigen::Matrix<double, MaxM, 1> rs;        // copy of r for the fallback
  Eigen::Matrix<double, MaxD, 1> tau1;      // reflectors of step 1
  Eigen::Matrix<double, MaxD, 1> tau2;      // reflectors of step 2
  Eigen::Matrix<int, MaxC, 1> perm;         // column permutation P (perm(i) = original column)
  Eigen::Matrix<double, MaxC, 1> colnorm2;  // squared norms of the remaining columns
  Eigen::Matrix<double, MaxT, 1> w;         // solution in the rotated basis
  Eigen::Matrix<double, MaxT, 1> work;      // Householder application scratch
};

// Reflector H = I − τ [1; v][1; v]ᵀ applied as one dot product and one axpy per column
// (X ← H X, X column-major) or per row (X ← X H, X row-major). At the sizes of the QP
// (≤ 31 long) Eigen's general applyHouseholderOn* is dominated by its call overhead.
template <class Vec, class Mat>
inline void reflectColumns(const Vec& v, double tau, Mat&& X) {
  if (tau == 0.0) return;
  const Eigen::Index len = X.rows();
  for (Eigen::Index j = 0; j < X.cols(); ++j) {
    auto x = X.col(j);
    const double t = tau * (x(0) + v.dot(x.tail(len - 1)));
    x(0) -= t;
    x.tail(len - 1) -= t * v;
  }
}
template <class Vec, class Mat>
inline void reflectRows(const Vec& v, double tau, Mat&& X) {
  if (tau == 0.0) return;
  const Eigen::Index len = X.cols();
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    auto x = X.row(i);
    const double t = tau * (x(0) + x.tail(len - 1).dot(v.transpose()));
    x(0) -= t;
    x.tail(len - 1) -= t * v.transpose();
  }
}

// Householder QR in place of the leading rows × cols block of X (rows ≥ cols),
// reflectors below the diagonal, R on and above it. Returns false as soon as a
// diagonal entry |R(i,i)| ≤ abs_tol (rank-deficient: use the pivoted path).
template <class Mat, class VecTau, class VecWork>
inline bool qpHouseholderQr(Mat& X, int rows, int cols, double abs_tol, VecTau& tau,
                            VecWork& work) {
  for (int i = 0; i < cols; ++i) {
    double beta = 0.0;
    auto col = X.col(i).segment(i, rows - i);
    col.makeHouseholderInPlace(tau(i), beta);
    X(i, i) = beta;
    if (!(std::abs(beta) > abs_tol)) return false;
    if (i + 1 < cols && rows - i > 1)
      reflectColumns(X.col(i).segment(i + 1, rows - i - 1), tau(i),
                     X.block(i, i + 1, rows - i, cols - i - 1));
  }
  static_cast<void>(work);
  return true;
}

// y(i:rows) ← H_i y(i:rows) for the reflector stored in column i of X.
template <class Mat, class Vec>
inline void qpApplyReflector(const Mat& X, int i, int rows, double tau, Vec& y) {
  if (tau == 0.0) return;
  const double s = tau * (y(i) + X.col(i).segment(i + 1, rows - i - 1).dot(
                                     y.segment(i + 1, rows - i - 1)));
  y(i) -= s;
  y.segment(i + 1, rows - i - 1) -= s * X.col(i).segment(i + 1, rows - i - 1);
}

// The minimum-norm solution of M p = r (M: k × c, k ≤ c, full row rank) from the QR of Mᵀ
// held in T (qpHouseholderQr(T, c, k, ·, tau, ·)): Rᵀ z = r, then p = Q [z; 0] (c entries).
template <class Mat, class VecTau, class VecR, class VecP>
inline void qpMinNormFromTransposedQr(const Mat& T, int c, int k, const VecTau& tau,
                                      const VecR& r, VecP& p) {
  for (int i = 0; i < k; ++i) p(i) = (r(i) - T.col(i).head(i).dot(p.head(i))) / T(i, i);
  p.segment(k, c - k).setZero();
  for (int i = k - 1; i >= 0; --i) qpApplyReflector(T, i, c, tau(i), p);
}

// Complete orthogonal decomposition path (any rank). M, r overwritten.
template <int MaxM, int MaxC, class MatM, class VecR, class VecP>
inline int qpMinNormPivoted(MatM& M, int m, int c, VecR& r, VecP& p, double abs_tol,
                            QpMinNormWorkspace<MaxM, MaxC>& ws) {
  for (int j = 0; j < c; ++j) {
    ws.perm(j) = j;
    ws.colnorm2(j) = M.col(j).head(m).squaredNorm();
  }
  const int dmax = m < c ? m : c;
  const double tol2 = abs_tol * abs_tol;
  int rank = 0;
  for (int i = 0; i < dmax; ++i) {
    int jmax = i;
    for (int j = i + 1; j < c; ++j)
      if (ws.colnorm2(j) > ws.colnorm2(jmax)) jmax = j;
    ws.colnorm2(jmax) = M.col(jmax).segment(i, m - i).squaredNorm();  // refresh the downdate
    if (!(ws.colnorm2(jmax) > tol2)) break;
    if (jmax != i) {
      M.col(i).head(m).swap(M.col(jmax).head(m));
      const int tp = ws.perm(i);
      ws.perm(i) = ws.perm(jmax);
      ws.perm(jmax) = tp;
      const double tn = ws.colnorm2(i);
      ws.colnorm2(i) = ws.colnorm2(jmax);
      ws.colnorm2(jmax) = tn;
    }
    double beta = 0.0;
    auto col = M.col(i).segment(i, m - i);
    col.makeHouseholderInPlace(ws.tau1(i), beta);
    M(i, i) = beta;
    if (i + 1 < c)
      M.block(i, i + 1, m - i, c - i - 1)
          .applyHouseholderOnTheLeft(M.col(i).segment(i + 1, m - i - 1), ws.tau1(i),
                                     ws.work.data());
    for (int j = i + 1; j < c; ++j) {
      ws.colnorm2(j) -= M(i, j) * M(i, j);
      if (ws.colnorm2(j) < 0.0) ws.colnorm2(j) = 0.0;
    }
    qpApplyReflector(M, i, m, ws.tau1(i), r);
    rank = i + 1;
  }
  p.head(c).setZero();
  if (rank == 0) return 0;
  if (rank == c) {  // full column rank: R11 w = y
    ws.w.head(rank) = r.head(rank);
    for (int i = rank - 1; i >= 0; --i) {  // by columns (M is column-major)
      ws.w(i) /= M(i, i);
      ws.w.head(i) -= ws.w(i) * M.col(i).head(i);
    }
  } else {
    // T = [R11 R12]ᵀ (c × rank) = U [L; 0]; Lᵀ z = y; w = U [z; 0].
    for (int i = 0; i < rank; ++i) {
      ws.T.col(i).head(i).setZero();
      ws.T.col(i).segment(i, c - i) = M.row(i).segment(i, c - i).transpose();
    }
    qpHouseholderQr(ws.T, c, rank, -1.0, ws.tau2, ws.work);
    qpMinNormFromTransposedQr(ws.T, c, rank, ws.tau2, r, ws.w);
  }
  for (int j = 0; j < c; ++j) p(ws.perm(j)) = ws.w(j);
  return rank;
}

// p = M⁺ r (minimum-norm least-squares solution) for M of size m × c; M and r are
// overwritten. Columns / diagonals ≤ abs_tol count as zero. Returns the rank.
template <int MaxM, int MaxC, class MatM, class VecR, class VecP>
inline int qpMinNormLeastSquares(MatM& M, int m, int c, VecR& r, VecP& p, double abs_tol,
                                 QpMinNormWorkspace<MaxM, MaxC>& ws) {
  if (m == 0 || c == 0) {
    p.head(c).setZero();
    return 0;
  }
  ws.rs.head(m) = r.head(m);
  if (m >= c) {
    ws.S.topLeftCorner(m, c) = M.topLeftCorner(m, c);
    if (qpHouseholderQr(M, m, c, abs_tol, ws.tau1, ws.work)) {
      for (int i = 0; i < c; ++i) qpApplyReflector(M, i, m, ws.tau1(i), r);
      p.head(c) = r.head(c);
      for (int i = c - 1; i >= 0; --i) {  // R p = (Qᵀ r)(0:c), by columns
        p(i) /= M(i, i);
        p.head(i) -= p(i) * M.col(i).head(i);
      }
      return c;
    }
    M.topLeftCorner(m, c) = ws.S.topLeftCorner(m, c);
  } else {
    ws.T.topLeftCorner(c, m) = M.topLeftCorner(m, c).transpose();
    if (qpHouseholderQr(ws.T, c, m, abs_tol, ws.tau2, ws.work)) {
      qpMinNormFromTransposedQr(ws.T, c, m, ws.tau2, r, ws.w);
      p.head(c) = ws.w.head(c);
      return m;
    }
  }
  r.head(m) = ws.rs.head(m);
  return qpMinNormPivoted(M, m, c, r, p, abs_tol, ws);
}

}  // namespace hqp::detail
