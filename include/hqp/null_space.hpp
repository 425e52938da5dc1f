#pragma once
// Null space of a (projected) task matrix M = Â_p = A_p Z_{p−1} (eq. 4), fixed capacity.
//
// Rank-revealing factorization of the transpose, Mᵀ Π = Q R (Householder QR with column
// pivoting), i.e. M = Π Rᵀ Qᵀ, the orthogonal half of a complete orthogonal decomposition:
// with k = rank, the first k columns of Q span the row space of M and the last n − k span
// null(M), orthonormally. In the rotated coordinates u = Q u', M Q = [Π R₁ᵀ  0]: the task
// only sees the first k coordinates, the rest is the null space handed to lower levels.
// Eigen's ColPivHouseholderQR on max-size matrices works in its members' storage and its
// Householder sequence applies with a fixed-size workspace, so nothing here allocates
// (checked by the no-malloc tests).

#include <Eigen/Core>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>

#include "hqp/hqp_types.hpp"

namespace hqp {

// M has at most MaxRows rows and MaxCols columns.
template <int MaxRows, int MaxCols>
class NullSpace {
 public:
  using Factor = MaxMatrix<capacity(MaxCols), capacity(MaxRows)>;  // storage of Mᵀ
  using Decomposition = Eigen::ColPivHouseholderQR<Factor>;

  NullSpace() = default;

  // Factorizes M (rows x cols). A pivot |R_ii| ≤ threshold (absolute) ends the rank: the
  // remaining directions count as null space.
  template <class Derived>
  void compute(const Eigen::MatrixBase<Derived>& M, double threshold) {
    rows_ = static_cast<int>(M.rows());
    cols_ = static_cast<int>(M.cols());
    rank_ = 0;
    if (rows_ == 0 || cols_ == 0) return;
    qr_.compute(M.transpose());
    const auto& R = qr_.matrixQR();
    const int kmax = std::min(rows_, cols_);
    while (rank_ < kmax && std::abs(R(rank_, rank_)) > threshold) ++rank_;
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
    if (rows_ == 0 || cols_ == 0) return;
    qr_.householderQ().applyThisOnTheRight(Y);
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
    const auto& R = qr_.matrixQR();
    const auto& perm = qr_.colsPermutation().indices();
    for (int l = 0; l < rows_; ++l) {
      const int jmax = std::min(l + 1, rank_);
      for (int j = 0; j < jmax; ++j) MQ(perm(l), j) = R(j, l);
    }
  }

  const Decomposition& decomposition() const { return qr_; }

 private:
  Decomposition qr_;
  int rows_ = 0;
  int cols_ = 0;
  int rank_ = 0;
};

}  // namespace hqp
