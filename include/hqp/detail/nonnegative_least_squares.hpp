#pragma once
// Non-negative least squares  min ‖E μ − f‖  s.t.  μ ≥ 0  (Lawson and Hanson, "Solving Least
// Squares Problems", 1974, ch. 23, algorithm NNLS) on compile-time capacities: no heap, every
// loop bounded by the sizes or the iteration cap. DualActiveSetQp::solveLeastDistance poses its
// QP this way when the dual method ends on nearly dependent rows.
// The residual f − E μ is the distance from f to the cone of E's columns: unique, and computed
// stably, even where μ is not unique (dependent columns). A column enters the passive set only
// if its part outside the span of the passive columns exceeds √ε of its norm and its
// coefficient in the new least-squares solution is positive (Lawson and Hanson's guard against
// rounding); otherwise it is set aside until the passive set changes. So the passive columns
// stay numerically independent and the least-squares solves on them meaningful.
// Each least-squares solve is a fresh Householder QR of the passive columns (at most `rows` of
// them; qp_min_norm_ls.hpp's kernel): this runs only on the rare fallback, so it is kept plain.

#include <Eigen/Core>

#include <cmath>
#include <limits>

#include "hqp/detail/qp_min_norm_ls.hpp"

namespace hqp::detail {

template <int MaxRows, int MaxCols>
class NonNegativeLeastSquares {
  static_assert(MaxRows > 0 && MaxCols > 0, "sizes");

 public:
  using MatrixE = Eigen::Matrix<double, MaxRows, MaxCols>;
  using VectorF = Eigen::Matrix<double, MaxRows, 1>;
  using VectorMu = Eigen::Matrix<double, MaxCols, 1>;

  // Iteration cap for a problem of cols columns: each column taken into the passive set costs
  // at least one step (61.9 on average, above 100 on 2 of 200 random QPs with 30 variables and
  // 60 rows, in the dual method's order-free route), so 3 per column, Lawson and Hanson's, or
  // the caller's max_iterations if larger.
  static int iterationCap(int max_iterations, int cols) {
    return max_iterations > 3 * cols ? max_iterations : 3 * cols;
  }

  // Problem data: the top-left rows × cols block of E() and the first rows entries of f().
  MatrixE& E() { return E_; }
  VectorF& f() { return f_; }

  // Returns false if the iteration cap (outer and inner steps together) is reached or a number
  // turns non-finite; mu() is then the last iterate (μ ≥ 0), not the solution.
  bool solve(int rows, int cols, int max_iterations,
             double dependent = std::sqrt(std::numeric_limits<double>::epsilon())) noexcept {
    rows_ = rows;
    np_ = 0;
    iterations_ = 0;
    if (rows <= 0 || rows > MaxRows || cols < 0 || cols > MaxCols) return false;
    int version = 0;  // passive-set changes; a set-aside column waits for the next one
    for (int j = 0; j < cols; ++j) {
      mu_(j) = 0.0;
      passive_(j) = 0;
      aside_(j) = -1;
      norm_(j) = E_.col(j).head(rows).norm();
    }
    res_.head(rows) = f_.head(rows);
    constexpr double kEps = std::numeric_limits<double>::epsilon();
    for (;;) {
      // Most positive Eᵀ(f − Eμ) per unit column among the columns at 0 (the steepest descent
      // of ½‖E μ − f‖² into μ ≥ 0); none above rounding: μ is optimal (the KKT conditions).
      const double rn = res_.head(rows).norm();
      int t = -1;
      double best = 0.0;
      for (int j = 0; j < cols; ++j) {
        if (passive_(j) || aside_(j) == version || !(norm_(j) > 0.0)) continue;
        const double g = E_.col(j).head(rows).dot(res_.head(rows)) / norm_(j);
        if (g > 64.0 * kEps * rn && g > best) best = g, t = j;
      }
      // A full passive set spans every row: what is left of the residual is rounding.
      if (t < 0 || np_ >= rows) return true;
      if (iterations_ >= max_iterations) return false;
      ++iterations_;
      P_(np_++) = t;
      passive_(t) = 1;
      if (!leastSquares() || !(std::abs(W_(np_ - 1, np_ - 1)) > dependent * norm_(t)) ||
          !(z_(np_ - 1) > 0.0)) {
        --np_;
        passive_(t) = 0;
        aside_(t) = version;
        continue;
      }
      ++version;
      // Inner loop: while a passive coefficient is ≤ 0, move from μ toward z as far as μ ≥ 0
      // allows and free the columns that reach 0.
      for (;;) {
        int hit = -1;
        double alpha = 1.0;
        for (int k = 0; k < np_; ++k) {
          if (z_(k) > 0.0) continue;
          const double mk = mu_(P_(k)), a = mk / (mk - z_(k));
          if (hit < 0 || a < alpha) alpha = a, hit = k;
        }
        if (hit < 0) break;
        if (iterations_ >= max_iterations) return false;
        ++iterations_;
        int kept = 0;
        for (int k = 0; k < np_; ++k) {
          const int j = P_(k);
          mu_(j) += alpha * (z_(k) - mu_(j));
          if (k == hit || !(mu_(j) > 0.0)) {
            mu_(j) = 0.0;
            passive_(j) = 0;
          } else {
            P_(kept++) = j;
          }
        }
        np_ = kept;
        ++version;
        if (!leastSquares()) return false;
      }
      for (int k = 0; k < np_; ++k) mu_(P_(k)) = z_(k);
      res_.head(rows) = f_.head(rows);
      for (int k = 0; k < np_; ++k) res_.head(rows) -= mu_(P_(k)) * E_.col(P_(k)).head(rows);
      if (!res_.head(rows).allFinite()) return false;
    }
  }

  const VectorMu& mu() const { return mu_; }
  const VectorF& residual() const { return res_; }  // f − E μ
  int numPassive() const { return np_; }
  int passive(int k) const { return P_(k); }
  int iterations() const { return iterations_; }

 private:
  // z = argmin ‖E_P z − f‖ over the passive columns in the order of P_ (Householder QR in W_,
  // R on and above the diagonal); false if some R_kk is 0 or a number is non-finite.
  bool leastSquares() {
    const int m = rows_, k = np_;
    if (k > m) return false;
    for (int c = 0; c < k; ++c) W_.col(c).head(m) = E_.col(P_(c)).head(m);
    w_.head(m) = f_.head(m);
    if (!qpHouseholderQr(W_, m, k, 0.0, tau_, tau_)) return false;
    for (int i = 0; i < k; ++i) qpApplyReflector(W_, i, m, tau_(i), w_);
    for (int i = k - 1; i >= 0; --i) {
      double s = w_(i);
      for (int c = i + 1; c < k; ++c) s -= W_(i, c) * z_(c);
      z_(i) = s / W_(i, i);
    }
    return z_.head(k).allFinite();
  }

  static constexpr int MaxP = MaxRows < MaxCols ? MaxRows : MaxCols;
  int rows_ = 0, np_ = 0, iterations_ = 0;
  MatrixE E_;
  VectorF f_, res_, w_;
  VectorMu mu_, norm_;
  Eigen::Matrix<int, MaxCols, 1> passive_, aside_;
  Eigen::Matrix<int, MaxP, 1> P_;
  Eigen::Matrix<double, MaxRows, MaxP> W_;
  Eigen::Matrix<double, MaxP, 1> z_, tau_;
};

}  // namespace hqp::detail
