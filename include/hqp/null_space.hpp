#pragma once
// Null space of a (projected) task matrix M = Â_p = A_p Z_{p−1} (eq. 4), fixed capacity.
//
// Rank-revealing factorization of the transpose, Mᵀ Π = Q R (Householder QR with column
// pivoting), i.e. M = Π Rᵀ Qᵀ, the orthogonal half of a complete orthogonal decomposition:
// with k = rank, the first k columns of Q span the row space of M and the last n − k span
// null(M), orthonormally. In the rotated coordinates u = Q u', M Q = [Π R₁ᵀ  0]: the task
// only sees the first k coordinates, the rest is the null space handed to lower levels.
// The factorization is written here on max-size storage (Eigen's ColPivHouseholderQR was
// a third of the hierarchy's linear algebra at these sizes): the pivot is the largest
// remaining column norm (downdated, recomputed exactly where the downdate cancels and
// before any rank decision), and it stops at the first pivot ≤ threshold, so Q is
// the product of the k reflectors of the row space. Nothing allocates (no-malloc tests).

#include <Eigen/Core>
#include <Eigen/Householder>

#include <algorithm>
#include <cmath>
#include <utility>

#include "hqp/detail/householder_strips.hpp"
#include "hqp/hqp_types.hpp"

namespace hqp {

// M has at most MaxRows rows and MaxCols columns.
template <int MaxRows, int MaxCols>
class NullSpace {
 public:
  using Factor = MaxMatrix<capacity(MaxCols), capacity(MaxRows)>;  // storage of Mᵀ
  using Coeffs = MaxVector<capacity(MaxRows)>;

  NullSpace() = default;

  // Factorizes M (rows x cols). A pivot |R_ii| ≤ threshold (absolute) ends the rank: the
  // remaining directions count as null space.
  template <class Derived>
  void compute(const Eigen::MatrixBase<Derived>& M, double threshold) {
    rows_ = static_cast<int>(M.rows());
    cols_ = static_cast<int>(M.cols());
    rank_ = 0;
    if (rows_ == 0 || cols_ == 0) return;
    qr_ = M.transpose();  // cols_ x rows_
    tau_.setZero(std::min(rows_, cols_));
    perm_.resize(rows_);
    for (int j = 0; j < rows_; ++j) perm_(j) = j;
    const int kmax = std::min(rows_, cols_);
    // Squared column norms of the remaining rows, downdated by R(i, j)² after each step and
    // recomputed exactly when the downdate has cancelled most of the last exact value (the
    // LAPACK xGEQP3 safeguard). The pivot's own norm is always recomputed exactly, and when
    // it is at or below the threshold all remaining norms are recomputed before the rank is
    // decided: the stop rule stays exactly "largest remaining norm ≤ threshold".
    // Columns of qr_ as unaligned maps (the same reductions and updates as the column
    // blocks, without their construction on every call; dot and norm sum in Eigen's order).
    using Col = Eigen::Map<Eigen::VectorXd>;
    double* const a = qr_.data();
    const Eigen::Index ld = qr_.outerStride();
    const auto seg = [a, ld](int j, int from, int len) { return Col(a + j * ld + from, len); };
    for (int j = 0; j < rows_; ++j) {
      cn_(j) = seg(j, 0, cols_).squaredNorm();
      cref_(j) = cn_(j);
    }
    for (int i = 0; i < kmax; ++i) {
      const int len = cols_ - i;
      int jmax = i;
      for (int j = i + 1; j < rows_; ++j)
        if (cn_(j) > cn_(jmax)) jmax = j;
      double best = seg(jmax, i, len).squaredNorm();
      if (!(std::sqrt(best) > threshold)) {
        for (int j = i; j < rows_; ++j) {
          const double nj = seg(j, i, len).squaredNorm();
          if (nj > best) {
            best = nj;
            jmax = j;
          }
        }
        if (!(std::sqrt(best) > threshold)) break;  // |R_ii| would be ≤ threshold: rank = i
      }
      if (jmax != i) {
        std::swap_ranges(a + i * ld, a + i * ld + cols_, a + jmax * ld);
        std::swap(perm_(i), perm_(jmax));
        std::swap(cn_(i), cn_(jmax));
        std::swap(cref_(i), cref_(jmax));
      }
      double* const c = a + i * ld + i;
      double tau = 0.0, beta = 0.0;
      Col(c, len).makeHouseholderInPlace(tau, beta);
      c[0] = beta;
      tau_(i) = tau;
      // H_i on the remaining columns, one dot + axpy per column: at these sizes (≤ 30 x 15)
      // Eigen's general block update is dominated by its call overhead.
      if (tau != 0.0 && len > 1) {
        const Col v(c + 1, len - 1);
        for (int j = i + 1; j < rows_; ++j) {
          double* const x = a + j * ld + i;
          Col xt(x + 1, len - 1);
          const double t = tau * (x[0] + v.dot(xt));
          x[0] -= t;
          xt -= t * v;
          const double nj = cn_(j) - x[0] * x[0];
          if (nj <= 1e-4 * cref_(j)) {
            cn_(j) = xt.squaredNorm();
            cref_(j) = cn_(j);
          } else {
            cn_(j) = nj;
          }
        }
      } else {
        for (int j = i + 1; j < rows_; ++j) {
          const double x0 = a[j * ld + i];
          cn_(j) = std::max(cn_(j) - x0 * x0, 0.0);
        }
      }
      rank_ = i + 1;
    }
  }

  // Scale-aware variant: threshold = tol · (largest row norm of M), so that tol is relative.
  // (HqpWbc scales by the unprojected task instead, see hqp_wbc.hpp.)
  template <class Derived>
  void computeRelative(const Eigen::MatrixBase<Derived>& M, double tol) {
    const double scale = M.rows() > 0 && M.cols() > 0 ? M.rowwise().norm().maxCoeff() : 0.0;
    compute(M, tol * scale);
  }

  int rank() const { return rank_; }
  int cols() const { return cols_; }
  int dim() const { return cols_ - rank_; }  // dimension of null(M)

  // Y ← Y Q for Y with cols() columns: afterwards Y.leftCols(rank()) maps onto the row
  // space of M and Y.rightCols(dim()) onto null(M). With Y = Z_{p−1}, Y.rightCols(dim())
  // is Z_p = Z_{p−1} null(Â_p) of eq. (4).
  template <class Dest>
  void applyQOnTheRight(Dest& Y) const {
    if (rank_ == 0) return;
    constexpr int MaxR = Dest::MaxRowsAtCompileTime;
    if constexpr (MaxR == Eigen::Dynamic || (Dest::Flags & Eigen::RowMajorBit) != 0) {
      Eigen::householderSequence(qr_, tau_).setLength(rank_).applyThisOnTheRight(Y);
    } else {
      // Y H_0 ⋯ H_{k−1} on strips of 8 rows (detail/householder_strips.hpp).
      detail::reflectRowStrips<capacity(MaxCols)>(Y, static_cast<int>(Y.rows()), cols_, qr_, tau_,
                                                  0, rank_);
    }
  }

  // Y ← Y Qᵀ for Y with cols() columns, 8 rows at a time (a column-major Y of fixed capacity).
  template <class Dest>
  void applyQTransposeOnTheRight(Dest& Y) const {
    if (rank_ == 0) return;
    detail::reflectRowStrips<capacity(MaxCols), true>(Y, static_cast<int>(Y.rows()), cols_, qr_,
                                                      tau_, 0, rank_);
  }

  // y ← Q y for a vector y of size cols() (e.g. u = Q u' back from the rotated coordinates).
  template <class Vec>
  void applyQOnTheLeft(Vec& y) const {
    for (int i = rank_ - 1; i >= 0; --i) reflect(i, y);
  }

  // y ← Qᵀ y (into the rotated coordinates u' = Qᵀ u).
  template <class Vec>
  void applyQTransposeOnTheLeft(Vec& y) const {
    for (int i = 0; i < rank_; ++i) reflect(i, y);
  }

  // Orthonormal basis Z of null(M) (cols x dim).
  template <class Dest>
  void basis(Dest& Z) const {
    Z.setIdentity(cols_, cols_);
    applyQOnTheRight(Z);
    const Eigen::Index d = dim();
    Z.leftCols(d) = Z.rightCols(d).eval();
    Z.conservativeResize(cols_, d);
  }

  // N = Z Zᵀ = I − M⁺ M (cols x cols), the projector of the paper's eq. (4).
  template <class Dest>
  void projector(Dest& N) const {
    MaxMatrix<capacity(MaxCols), capacity(MaxCols)> Z;
    basis(Z);
    N.noalias() = Z * Z.transpose();
  }

  // M Q truncated to rank k (rows x cols): (M Q)(π(l), j) = R(j, l) for j ≤ min(l, k − 1),
  // zero elsewhere (π = column permutation of the factorization of Mᵀ).
  template <class Dest>
  void rotatedMatrix(Dest& MQ) const {
    MQ.setZero(rows_, cols_);
    if (rank_ == 0) return;
    for (int l = 0; l < rows_; ++l) {
      const int jmax = std::min(l + 1, rank_);
      for (int j = 0; j < jmax; ++j) MQ(perm_(l), j) = qr_(j, l);
    }
  }

  // Mᵀ Π = Q R in place: R on and above the diagonal (first rank() rows), reflectors below.
  const Factor& matrixQR() const { return qr_; }
  int permutation(int l) const { return perm_(l); }  // column l of Mᵀ Π is row Π(l) of M

 private:
  // y ← H_i y with the i-th stored reflector H_i = I − τ_i v_i v_iᵀ (v_i = [1; qr_ below i]).
  template <class Vec>
  void reflect(int i, Vec& y) const {
    const double tau = tau_(i);
    const int len = cols_ - i;
    if (tau == 0.0 || len < 2) return;
    const Eigen::Map<const Eigen::VectorXd> v(qr_.data() + i * qr_.outerStride() + i + 1, len - 1);
    if constexpr (Vec::InnerStrideAtCompileTime == 1) {  // maps: no block construction
      Eigen::Map<Eigen::VectorXd> yt(y.data() + i + 1, len - 1);
      const double t = tau * (y(i) + v.dot(yt));
      y(i) -= t;
      yt -= t * v;
    } else {
      const double t = tau * (y(i) + v.dot(y.segment(i + 1, len - 1)));
      y(i) -= t;
      y.segment(i + 1, len - 1) -= t * v;
    }
  }

  Factor qr_;
  Coeffs tau_;
  Eigen::Matrix<double, capacity(MaxRows), 1> cn_, cref_;  // column norms² (pivot search)
  Eigen::Matrix<int, Eigen::Dynamic, 1, 0, capacity(MaxRows), 1> perm_;
  int rows_ = 0;
  int cols_ = 0;
  int rank_ = 0;
};

}  // namespace hqp
