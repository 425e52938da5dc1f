#pragma once
// Dual active-set method (Goldfarb and Idnani, 1983) for a strictly convex least-squares QP:
//   min_x ½‖A x − b‖²   s.t.   lower ≤ C x ≤ upper,   A (r × n, r ≥ n) of full column rank.
// It starts at the unconstrained minimizer and adds the most violated row at a time, keeping
// the multipliers dual feasible (≥ 0); the primal iterate is feasible only at the end. When
// few rows end up active (the last level of the robot's hierarchy: 0–2 of 30) it costs one
// QR of A plus O(n² + m n) per active row, against the primal method's per-level set-up.
// It needs a Hessian AᵀA that is positive definite; HqpWbc uses it for a last level whose
// Â_p has full column rank and falls back to ActiveSetQp otherwise (docs/hqp.md).
// Factors (the paper's stable variant): A = Q_A [R; 0], Hessian AᵀA = RᵀR, J = R⁻¹ Q_J with
// Q_J orthogonal, and Jᵀ N = [R_a; 0] for the active normals N (R_a upper triangular). Both
// are updated with Givens rotations on adding and dropping a row.
// Real-time: no heap (compile-time capacities), no exceptions, iterations capped.

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "hqp/detail/nonnegative_least_squares.hpp"
#include "hqp/detail/qp_min_norm_ls.hpp"
#include "hqp/qp_settings.hpp"
#include "hqp/qp_status.hpp"

namespace hqp {

// A checked Farkas certificate of rows lower ≤ C x ≤ upper having no common point: rows j_k,
// each written n_k x ≥ β_k (n = c_j, β = lower_j at the lower side; n = −c_j, β = −upper_j at
// the upper side), weights y_k ≥ 0 with ρ = Σ y_k n_k ≈ 0 and Σ y_k β_k > 0. DualActiveSetQp
// records one where it returns Infeasible; proves() checks it against any rows with the same
// indexing, e.g. the same rows restricted to a subspace (C Z): the rows then conflict there
// too. Capacity: MaxRows entries.
template <int MaxRows>
struct FarkasCertificate {
  int count = 0;
  std::array<int, MaxRows> row{};
  std::array<bool, MaxRows> at_upper{};
  std::array<double, MaxRows> y{};

  // True if the rows C (n columns), lower, upper contradict by more than tol: with τ_k =
  // tol (‖n_k‖ + |β_k|), any x that meets every row to τ satisfies ρᵀx − Σ y β ≥ −Σ y τ, so
  // none exists with ‖x‖ ≤ X = tol / ε · (1 + max |β̂|) (beyond X no row value can be
  // computed to the tolerance in double precision) if Σ y β > Σ y τ + ‖ρ‖ X; ρ must be rounding
  // (‖ρ‖ ≤ 1e-12 Σ y ‖n‖), else the rows are only nearly dependent and a feasible point may lie
  // far out. rinv(j): 1 / ‖c_j‖ (1 for a zero row); z: scratch of n entries. Rows beyond m or
  // an infinite bound: false.
  template <class MatC, class VecL, class VecU, class RowInv, class Vec>
  bool proves(const MatC& C, const VecL& lower, const VecU& upper, int m, int n, double tol,
              const RowInv& rinv, Vec& z) const {
    if (count == 0) return false;
    z.head(n).setZero();
    double gap = 0.0, slack = 0.0, ysum = 0.0, bmax = 0.0;
    for (int k = 0; k < count; ++k) {
      const std::size_t ks = static_cast<std::size_t>(k);
      const int j = row[ks];
      if (j < 0 || j >= m) return false;
      const double b = at_upper[ks] ? -upper(j) : lower(j);
      if (!(std::abs(b) < std::numeric_limits<double>::infinity())) return false;
      const double yk = y[ks], ri = rinv(j);
      z.head(n) += (at_upper[ks] ? -yk : yk) * C.row(j).head(n).transpose();
      gap += yk * b;
      slack += yk * tol * (1.0 / ri + std::abs(b));
      ysum += yk / ri;
      bmax = std::max(bmax, std::abs(b) * ri);
    }
    const double rho = z.head(n).norm();
    const double X = tol / std::numeric_limits<double>::epsilon() * (1.0 + bmax);
    return rho <= 1e-12 * ysum && gap > slack + rho * X;
  }
};

template <int MaxN, int MaxRows, int MaxIneq>
class DualActiveSetQp {
  static_assert(MaxN > 0 && MaxRows >= MaxN && MaxIneq > 0, "sizes");

 public:
  using VectorX = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, MaxN, 1>;

  // Relative floor of factorize()'s min_sigma: σ_min(A) must exceed kMinSigmaFloor · ‖A‖_F
  // whatever the caller asks. Below it (cond(A) ≳ 1e9) the method's rounding errors grow
  // with cond(A)² and it can report Infeasible for a feasible problem or return a point
  // that violates a row; the final check of solve() catches the latter, this the former.
  static constexpr double kMinSigmaFloor = 1e-9;

 private:
  // Every input as a map: the column-major data the callers hold (a matrix, a block of
  // one, or a single row) without a copy; checked at compile time.
  using ColumnsMap = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  using VectorMap = Eigen::Map<const Eigen::VectorXd>;
  template <class Mat>
  static ColumnsMap mapColumns(const Mat& M) noexcept {
    static_assert((Mat::Flags & Eigen::DirectAccessBit) != 0, "a matrix or a block of one");
    if constexpr (Mat::RowsAtCompileTime == 1) {  // one row: its entries' stride
      return ColumnsMap(M.data(), 1, M.cols(), Eigen::OuterStride<>(M.innerStride()));
    } else {
      static_assert(!(Mat::Flags & Eigen::RowMajorBit) && Mat::InnerStrideAtCompileTime == 1,
                    "column-major, inner stride 1");
      return ColumnsMap(M.data(), M.rows(), M.cols(), Eigen::OuterStride<>(M.outerStride()));
    }
  }
  template <class Vec>
  static VectorMap mapVector(const Vec& v) noexcept {
    static_assert((Vec::Flags & Eigen::DirectAccessBit) && Vec::InnerStrideAtCompileTime == 1,
                  "a contiguous vector");
    return VectorMap(v.data(), v.size());
  }

 public:
  // Factorizes A (rows r ≥ n, n columns) and forms the unconstrained minimizer R⁻¹ (Q_Aᵀ b).
  // Returns false, and nothing is valid (solve() then returns InvalidInput), unless A and b
  // are finite and 1/‖R⁻¹‖_F > max(min_sigma, kMinSigmaFloor · ‖A‖_F), a lower bound of
  // σ_min(A): the objective is then strictly convex by at least that margin.
  template <class MatA, class VecB>
  bool factorize(const MatA& A, const VecB& b, int r, int n, double min_sigma) noexcept {
    return factorizeMapped(mapColumns(A), mapVector(b), r, n, min_sigma);
  }

  // factorize() for the block-diagonal objective A = [A₁ 0; 0 diag(d)], b = [b₁; 0], formed
  // here from A₁ (the first k columns of A1's top rt rows), b₁ (b1's top rt entries) and d
  // (n − k entries, n = k + d.size()): the dual start's stacked objective. The same R, J and
  // minimizer as factorize() on that stacked matrix (its Householder steps on the zero blocks
  // only move zeros; a zero's sign may differ), for the QR of A₁ alone and a two-row step on
  // each column of diag(d). False (nothing valid) if k < 0, rt < k or A1, b1 are smaller than
  // stated, besides factorize()'s own refusals.
  template <class MatA, class VecB, class VecD>
  bool factorizeBlockDiagonal(const MatA& A1, const VecB& b1, int rt, int k, const VecD& d,
                              double min_sigma) noexcept {
    const int m = static_cast<int>(d.size()), n = k + m, r = rt + m;
    n_ = n;
    factorized_ = false;
    if (k < 0 || rt < k || A1.rows() < rt || A1.cols() < k || b1.size() < rt) return false;
    if (n <= 0 || n > MaxN || r > MaxRows) return false;
    // F_ = [A₁ 0; 0 D], each entry written once (A₁ is rt x k, D is m x m diagonal).
    F_.topLeftCorner(rt, k) = A1.topLeftCorner(rt, k);
    F_.block(0, k, rt, m).setZero();
    F_.block(rt, 0, m, n).setZero();
    for (int i = 0; i < m; ++i) F_(rt + i, k + i) = d(i);
    c_.head(r).setZero();
    c_.head(rt) = b1.head(rt);
    return factorizeStored(r, n, min_sigma, k);
  }

 private:
  // factorize() on A and b as maps: the method's code is compiled once per solver type,
  // whatever block or matrix type the caller holds its data in (docs/hqp.md, "One copy of
  // the dual method's code").
  bool factorizeMapped(const ColumnsMap& A, const VectorMap& b, int r, int n,
                       double min_sigma) noexcept {
    n_ = n;
    factorized_ = false;
    if (n <= 0 || n > MaxN || r < n || r > MaxRows) return false;
    F_.topLeftCorner(r, n) = A.topLeftCorner(r, n);
    c_.head(r) = b.head(r);
    return factorizeStored(r, n, min_sigma, n);
  }

  // The factorization of F_ (r x n) and c_ as stored. k < n: F_ = [A₁ 0; 0 D] as
  // factorizeBlockDiagonal() forms it, rt = r − (n − k) rows of A₁.
  bool factorizeStored(int r, int n, double min_sigma, int k) noexcept {
    const double anorm = F_.topLeftCorner(r, n).norm();
    if (!std::isfinite(anorm) || !c_.head(r).allFinite()) return false;
    min_sigma = std::max(min_sigma, kMinSigmaFloor * anorm);
    // Householder QR, column by column on raw columns (at ≤ 15 x 9, Eigen's block
    // expressions cost more than the flops): H_i = I − τ [1; v][1; v]ᵀ, v below the diagonal.
    // With k < n only A₁'s rows and columns (and c) take part: the rest of them is zero.
    const int rt = r - (n - k);
    for (int i = 0; i < k; ++i) {
      double* v = &F_(0, i);
      double tail = 0.0;
      for (int l = i + 1; l < rt; ++l) tail += v[l] * v[l];
      const double a = v[i];
      double tau = 0.0, beta = a;
      if (tail > 0.0) {
        beta = -std::copysign(std::sqrt(a * a + tail), a);
        tau = (beta - a) / beta;
        const double inv = 1.0 / (a - beta);
        for (int l = i + 1; l < rt; ++l) v[l] *= inv;
      }
      if (!(beta != 0.0) || !std::isfinite(beta)) return false;
      v[i] = beta;
      if (tau == 0.0) continue;
      // Columns i+1 .. k−1, then c (j = k), two at a time: their dot products are independent
      // chains (each summed in its own order, so the result does not change).
      int j = i + 1;
      for (; j + 1 <= k; j += 2) {
        double* x = &F_(0, j);
        double* y = j + 1 < k ? &F_(0, j + 1) : c_.data();
        double t = x[i], s = y[i];
        for (int l = i + 1; l < rt; ++l) {
          t += v[l] * x[l];
          s += v[l] * y[l];
        }
        t *= tau;
        s *= tau;
        x[i] -= t;
        y[i] -= s;
        for (int l = i + 1; l < rt; ++l) {
          x[l] -= t * v[l];
          y[l] -= s * v[l];
        }
      }
      if (j <= k) {
        double* x = j < k ? &F_(0, j) : c_.data();
        double t = x[i];
        for (int l = i + 1; l < rt; ++l) t += v[l] * x[l];
        t *= tau;
        x[i] -= t;
        for (int l = i + 1; l < rt; ++l) x[l] -= t * v[l];
      }
    }
    // D's columns: column i holds d at row s = rt + i − k alone, and c there is still 0, so
    // its step touches rows i and s of c only (none if s = i: τ = 0).
    for (int i = k; i < n; ++i) {
      double* v = &F_(0, i);
      const int s = rt + i - k;
      const double a = v[i];
      if (s == i) {
        if (!(a != 0.0) || !std::isfinite(a)) return false;
        continue;
      }
      const double beta = -std::copysign(std::sqrt(a * a + v[s] * v[s]), a);
      if (!(beta != 0.0) || !std::isfinite(beta)) return false;
      const double tau = (beta - a) / beta;
      v[s] *= 1.0 / (a - beta);
      v[i] = beta;
      const double t = (c_(i) + v[s] * c_(s)) * tau;
      c_(i) -= t;
      c_(s) -= t * v[s];
    }
    // J = R⁻¹ from R J = I, every column at once: row i of J (all columns, padded to whole
    // vectors) is divided by R_ii, then taken off the rows above. Column j sees the steps of a
    // back substitution of e_j in the same order (the steps i > j only move zeros), so each
    // entry is bit for bit that of solving the columns one by one; the lower part is set to 0.
    Jr_.topRows(n).setZero();
    for (int i = 0; i < n; ++i) Jr_(i, i) = 1.0;
    for (int i = n - 1; i >= 0; --i) {
      Jr_.row(i) /= F_(i, i);
      if (i < k)  // rows above D's columns: F_(l, i) = 0 there
        for (int l = 0; l < i; ++l) Jr_.row(l) -= F_(l, i) * Jr_.row(i);
    }
    J_.topLeftCorner(n, n) = Jr_.topLeftCorner(n, n).template triangularView<Eigen::Upper>();
    // ‖R⁻¹‖_F² over the upper triangle (the rest is zero). Summed by hand: GCC's loop analysis
    // of Eigen's block reduction at -O3 warned of an access past a MaxN-column matrix.
    double jn2 = 0.0;
    for (int j = 0; j < n; ++j) {
      const double* x = &J_(0, j);
      for (int i = 0; i <= j; ++i) jn2 += x[i] * x[i];
    }
    if (!(jn2 < kInf) || !(jn2 * min_sigma * min_sigma < 1.0)) return false;
    x0_.noalias() = J_.topLeftCorner(n, n) * c_.head(n);  // R⁻¹ (Q_Aᵀ b)(0:n)
    factorized_ = x0_.allFinite();
    return factorized_;
  }

 public:
  // The least-distance objective ½‖x‖² (A = I, b = 0) on n variables: what factorize() would
  // compute for it (R = I, J = I, unconstrained minimizer 0) without its O(n³) steps.
  bool factorizeIdentity(int n) noexcept {
    n_ = n;
    factorized_ = n > 0 && n <= MaxN;
    if (!factorized_) return false;
    F_.topLeftCorner(n, n).setIdentity();
    c_.head(n).setZero();
    Jr_.topRows(n).setZero();
    for (int i = 0; i < n; ++i) Jr_(i, i) = 1.0;
    J_.topLeftCorner(n, n).setIdentity();
    x0_.setZero(n);
    return true;
  }

  // Solves with the constraint rows C (m × n, n of factorize()) and their bounds (±inf for an
  // absent side). Status: Optimal (checked: every row holds to feasibility_tol · (1 + |ĉ x|)
  // scaled to a unit row, and the stationarity residual is at rounding level); Infeasible (a
  // row with lower > upper, or a violated row dependent on the active rows with no
  // multiplier that can give way); IterationLimit; NumericalFailure (non-finite numbers, or
  // the final check failed); InvalidInput (no successful factorize(), NaN / ±inf in C, a
  // bound of +inf as lower or −inf as upper, a magnitude above max_magnitude). x() is only
  // the solution when Optimal. Warm start: the rows prefer[0..count) (e.g. the previous active set)
  // are added first while one of them is violated; any order of violated rows is valid for the
  // method, this one avoids adding rows that are dropped again.
  template <class MatC, class VecL, class VecU>
  QpStatus solve(const MatC& C, const VecL& lower, const VecU& upper, int m,
                 const QpSettings& settings, const int* prefer = nullptr,
                 int prefer_count = 0) noexcept {
    return solveMapped(mapColumns(C), mapVector(lower), mapVector(upper), m, settings, prefer,
                       prefer_count);
  }

 private:
  QpStatus solveMapped(const ColumnsMap& C, const VectorMap& lower, const VectorMap& upper,
                       int m, const QpSettings& settings, const int* prefer = nullptr,
                       int prefer_count = 0) noexcept {
    const int n = n_;
    const QpStatus in = start(C, lower, upper, m, settings);
    if (in != QpStatus::Optimal) return in;
    for (int k = 0; k < prefer_count; ++k)
      if (prefer[k] >= 0 && prefer[k] < m) prefer_(prefer[k]) = 1;
    cx_.head(m).noalias() = C.topLeftCorner(m, n) * x_;
    for (;;) {
      // Step 1: the most violated row side (violation scaled to a unit-norm row).
      int p = -1;
      bool up = false;
      for (int pass = prefer_count > 0 ? 0 : 1; pass < 2 && p < 0; ++pass) {
        double worst = settings.feasibility_tol;
        for (int j = 0; j < m; ++j) {
          if (active_(j) || (pass == 0 && !prefer_(j))) continue;
          const double vl = (lower(j) - cx_(j)) * rinv_(j), vu = (cx_(j) - upper(j)) * rinv_(j);
          if (vl > worst) worst = vl, p = j, up = false;
          if (vu > worst) worst = vu, p = j, up = true;
        }
      }
      if (p < 0) return verified(C, lower, upper, m, settings);
      const double sgn = up ? -1.0 : 1.0;  // normal n_p = sgn · C_p, n_pᵀ x ≥ sgn · bound
      np_.head(n) = sgn * C.row(p).head(n).transpose();
      double s = sgn * cx_(p) - (up ? -upper(p) : lower(p));  // < 0: violated
      double uplus = 0.0;                                       // multiplier of n_p
      // Step 2: move toward n_p until it holds, dropping rows whose multiplier reaches 0.
      for (;;) {
        if (iterations_ >= settings.max_iterations) return QpStatus::IterationLimit;
        d_.head(n).noalias() = J_.topLeftCorner(n, n).transpose() * np_.head(n);
        const double dz2 = d_.segment(q_, n - q_).squaredNorm();  // = n_pᵀ z
        // Dual direction r = R_a⁻¹ d(0:q) (back substitution by columns).
        r_.head(q_) = d_.head(q_);
        for (int i = q_ - 1; i >= 0; --i) {
          r_(i) /= Ra_(i, i);
          r_.head(i) -= r_(i) * Ra_.col(i).head(i);
        }
        double t1 = kInf;
        int drop = -1;
        for (int i = 0; i < q_; ++i) {
          if (r_(i) > 0.0 && u_(i) / r_(i) < t1) {
            t1 = u_(i) / r_(i);
            drop = i;
          }
        }
        // n_p in the span of the active normals (no primal step, z = 0) if its part outside
        // that span is at most √ε of it: a step along so small a z adds a row nearly dependent
        // on the active ones, whose multipliers (~1/σ_min) are then noise. A bound of 1e-12
        // instead of √ε let multipliers of 1e16 through, and an "Optimal" 4.9 times above
        // the optimum on a stress instance (docs/hqp-tuning.md, "The last level on nearly
        // dependent rows").
        constexpr double kDependent = std::numeric_limits<double>::epsilon();
        const bool primal = dz2 > kDependent * d_.head(n).squaredNorm() && dz2 > 0.0;
        const double t2 = primal ? -s / dz2 : kInf;
        if (drop < 0 && !primal) {
          // n_p = Σ r_k n_k with every r_k ≤ 0. Infeasible only if the bounds contradict by
          // more than the tolerance (a checked Farkas certificate); otherwise the violation
          // is rounding of a (nearly) duplicate row: the row is held by the active rows.
          if (certifiedInfeasible(C, lower, upper, m, p, up, settings)) return QpStatus::Infeasible;
          for (int k = 0; k < q_; ++k) u_(k) += uplus * r_(k);  // n_p's multiplier moves to them
          if (uplus > 0.0 && (u_.head(q_).array() < 0.0).any()) return QpStatus::NumericalFailure;
          active_(p) = 2;
          ++held_;
          break;
        }
        const double t = t2 <= t1 ? t2 : t1;
        if (primal) {
          z_.head(n).noalias() = J_.block(0, q_, n, n - q_) * d_.segment(q_, n - q_);
          x_ += t * z_.head(n);
          cx_.head(m).noalias() += t * (C.topLeftCorner(m, n) * z_.head(n));
          s += t * dz2;
        }
        u_.head(q_) -= t * r_.head(q_);
        uplus += t;
        ++iterations_;
        if (primal && t2 <= t1) {
          addActive(p, up, uplus);
          break;
        }
        dropActive(drop);
      }
    }
  }

 public:
  // The same QP by routes that do not depend on an order of the rows, for when solve() ends
  // on nearly dependent rows (NumericalFailure) in the orders the caller tried. Least distance
  // (leastDistance below: the NNLS residual that defines its point is stable where the
  // multipliers are not), and where its point misses the final check, the dual method in the
  // order of its active set, which is the optimum's in the cases seen (its point can miss by
  // rounding magnified through R⁻¹). The NNLS threshold for a nearly dependent column is √ε
  // (a well-conditioned passive set), then 1e-12 (√ε can set aside a row the optimum needs,
  // left 1e-8 beyond its bound). Statuses and results as solve(); not Optimal means no route
  // passed the final check (an infeasible problem ends NumericalFailure here).
  template <class MatC, class VecL, class VecU>
  QpStatus solveOrderFree(const MatC& C, const VecL& lower, const VecU& upper, int m,
                          const QpSettings& settings) noexcept {
    return solveOrderFreeMapped(mapColumns(C), mapVector(lower), mapVector(upper), m, settings);
  }

 private:
  QpStatus solveOrderFreeMapped(const ColumnsMap& C, const VectorMap& lower,
                                const VectorMap& upper, int m,
                                const QpSettings& settings) noexcept {
    QpStatus s = QpStatus::NumericalFailure;
    int its = 0;
    for (const double dependent : {std::sqrt(std::numeric_limits<double>::epsilon()), 1e-12}) {
      s = leastDistance(C, lower, upper, m, settings, dependent);
      its += iterations_;
      if (s == QpStatus::Optimal || s == QpStatus::InvalidInput) break;
      if (q_ == 0) continue;
      const int cnt = q_;
      for (int k = 0; k < cnt; ++k) order_(k) = row_(k);
      // J = R⁻¹ as factorize() left it (the caller's solve() rotated it; F_, Jr_, x0_ hold).
      J_.topLeftCorner(n_, n_) = Jr_.topLeftCorner(n_, n_).template triangularView<Eigen::Upper>();
      s = solveMapped(C, lower, upper, m, settings, order_.data(), cnt);
      its += iterations_;
      if (s == QpStatus::Optimal) break;
    }
    iterations_ = its;
    return s;
  }

 public:
  // Warm start from a primal solver's working set (ActiveSetQp's numActive/activeRow,
  // variables/hasWorkingSet): if it belongs to a problem of n variables, its first rows (at
  // most MaxN) are written to rows, to be passed to solve() as prefer. Returns their count.
  template <class WorkingSet, class Rows>
  static int preferredRows(const WorkingSet& ws, int n, Rows& rows) {
    if (!ws.hasWorkingSet() || ws.variables() != n) return 0;
    const int count = std::min(ws.numActive(), static_cast<int>(rows.size()));
    for (int a = 0; a < count; ++a) rows[static_cast<std::size_t>(a)] = ws.activeRow(a);
    return count;
  }

  const VectorX& x() const { return x_; }
  const VectorX& unconstrainedMinimizer() const { return x0_; }
  // 1 / ‖row‖ (1 for a zero row): the scale of every violation and tolerance the method applies
  // to a row; a certificate checked elsewhere on the same rows (proves' rinv) must use it too.
  template <class Row>
  static double inverseRowNorm(const Row& row) {
    const double nrm = row.norm();
    return nrm > 0.0 ? 1.0 / nrm : 1.0;
  }
  using Certificate = FarkasCertificate<MaxN + 1>;
  // After solve() returned Infeasible on a dependent violated row: the checked certificate
  // (the violated row first, then the active rows); count 0 after any other outcome.
  const Certificate& certificate() const { return cert_; }
  // Tolerance of the stationarity check before Optimal (relative to the terms' magnitude).
  static constexpr double kStationarityTol = 1e-8;
  // Relative duality gap accepted where stationarity holds only to the multipliers' size.
  static constexpr double kGapTol = 1e-6;
  int iterations() const { return iterations_; }
  int numActive() const { return q_; }
  int activeRow(int k) const { return row_(k); }
  bool activeAtUpper(int k) const { return upper_(k) != 0; }
  // μ_k ≥ 0 with Aᵀ(A x − b) + Σ_upper μ_k c_k − Σ_lower μ_k c_k = 0 (as ActiveSetQp).
  double multiplier(int k) const { return u_(k); }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static double hyp(double a, double b) { return std::sqrt(a * a + b * b); }

  // Common start of solve() and leastDistance(): x at the unconstrained minimizer, no
  // active row; the input contract, then empty intervals (scaled to unit rows, as every
  // violation). Optimal means "go on".
  template <class MatC, class VecL, class VecU>
  QpStatus start(const MatC& C, const VecL& lower, const VecU& upper, int m,
                 const QpSettings& settings) {
    const int n = n_;
    q_ = 0;
    held_ = 0;
    iterations_ = 0;
    cert_.count = 0;
    if (!factorized_ || m < 0 || m > MaxIneq) {
      x_.setZero(n > 0 ? n : 0);
      return QpStatus::InvalidInput;
    }
    x_ = x0_;
    if (!detail::withinMagnitude(C.topLeftCorner(m, n), settings.max_magnitude)) {
      x_.setZero(n);
      return QpStatus::InvalidInput;
    }
    for (int j = 0; j < m; ++j)
      if (!detail::boundsValid(lower(j), upper(j), settings.max_magnitude)) {
        x_.setZero(n);
        return QpStatus::InvalidInput;
      }
    for (int j = 0; j < m; ++j) {
      rinv_(j) = inverseRowNorm(C.row(j).head(n));
      active_(j) = 0;
      prefer_(j) = 0;
      if ((lower(j) - upper(j)) * rinv_(j) > settings.feasibility_tol) return QpStatus::Infeasible;
    }
    m_ = m;
    return QpStatus::Optimal;
  }

  // One least-distance solve for solveOrderFree(): least distance programming (Lawson and
  // Hanson, 1974, ch. 23). With w = R (x − x0) the objective is ½‖w‖² + const and each finite
  // row side a half-space ĝᵀw ≥ ĥ (ĝ = ±R⁻ᵀcᵀ scaled to unit norm); the optimum is the point
  // of their intersection nearest to 0, w = −r(0:n) / r(n) from the residual r = f − E μ of
  // the non-negative least squares with E = [Ĝᵀ; ĥᵀ], f = e_n (r(n) = 0: infeasible). That
  // residual is unique and stable where the multipliers are not, which is where the dual
  // method's choices turn to noise. `dependent`: the NNLS threshold for a nearly dependent
  // column. Ends with verified(), as solve().
  template <class MatC, class VecL, class VecU>
  QpStatus leastDistance(const MatC& C, const VecL& lower, const VecU& upper, int m,
                         const QpSettings& settings, double dependent) {
    const int n = n_;
    const QpStatus in = start(C, lower, upper, m, settings);
    if (in != QpStatus::Optimal) return in;
    auto& E = ldp_.E();
    const auto Rinv = Jr_.topLeftCorner(n, n);  // upper triangular, zero below (factorize)
    int cols = 0;
    for (int j = 0; j < m; ++j) {
      np_.head(n).noalias() = Rinv.transpose() * C.row(j).head(n).transpose();  // R⁻ᵀ cᵀ
      const double gn = np_.head(n).norm(), cx0 = C.row(j).head(n).dot(x0_);
      for (int side = 0; side < 2; ++side) {
        const bool up = side == 1;
        const double bound = up ? upper(j) : lower(j);
        if (!(std::abs(bound) < kInf)) continue;
        const double sgn = up ? -1.0 : 1.0, h = sgn * (bound - cx0);
        if (!(gn > 0.0)) {  // a zero row: 0 ≥ h must hold
          if (h * rinv_(j) > settings.feasibility_tol) return QpStatus::Infeasible;
          continue;
        }
        E.col(cols).head(n) = (sgn / gn) * np_.head(n);
        E(n, cols) = h / gn;
        ldp_scale_(cols) = gn;
        ldp_row_(cols) = up ? -1 - j : j;
        ++cols;
      }
    }
    ldp_.f().head(n + 1).setZero();
    ldp_.f()(n) = 1.0;
    const int cap = decltype(ldp_)::iterationCap(settings.max_iterations, cols);
    const bool done = ldp_.solve(n + 1, cols, cap, dependent);
    iterations_ = ldp_.iterations();
    if (!done) return iterations_ >= cap ? QpStatus::IterationLimit : QpStatus::NumericalFailure;
    const auto& r = ldp_.residual();
    // r(n) = 1 − ĥᵀμ: 0 when f lies in the cone (no feasible point); at rounding level the
    // distance cannot be trusted either way, and the caller's general path decides.
    if (!(r(n) > std::sqrt(std::numeric_limits<double>::epsilon())))
      return QpStatus::NumericalFailure;
    z_.head(n) = -r.head(n) / r(n);  // w
    x_ = x0_;
    x_.noalias() += Rinv * z_.head(n);
    // The passive columns are the active row sides: w = Ĝᵀμ / r(n), so ĝ's multiplier is
    // μ / r(n), the row's that divided by gn (the row was divided by it).
    addPassiveRows([&](double mu, int col) { return mu / r(n) / ldp_scale_(col); });
    return verified(C, lower, upper, m, settings);
  }

  // The NNLS's passive columns (row sides coded in ldp_row_) appended to the active set, the
  // multiplier of column col as multiplier(μ_col, col).
  template <class Multiplier>
  void addPassiveRows(Multiplier&& multiplier) {
    for (int k = 0; k < ldp_.numPassive() && q_ < MaxN; ++k) {
      const int col = ldp_.passive(k), code = ldp_row_(col);
      const int j = code < 0 ? -1 - code : code;
      row_(q_) = j;
      upper_(q_) = code < 0 ? 1 : 0;
      u_(q_) = multiplier(ldp_.mu()(col), col);
      active_(j) = 1;
      ++q_;
    }
  }

  // Rotation (a, b) → (ρ, 0) applied to columns i, i + 1 of J: J ← J Gᵀ.
  void rotateJ(int i, double c, double s) {
    for (int l = 0; l < n_; ++l) {
      const double a = J_(l, i), b = J_(l, i + 1);
      J_(l, i) = c * a + s * b;
      J_(l, i + 1) = -s * a + c * b;
    }
  }

  // d_ = Jᵀ n_p is set: rotations zero d(q + 1:) bottom-up; d(0:q) becomes R_a's new column.
  void addActive(int p, bool up, double mult) {
    for (int j = n_ - 1; j > q_; --j) {
      const double a = d_(j - 1), b = d_(j);
      if (b == 0.0) continue;
      const double rho = hyp(a, b);
      d_(j - 1) = rho;
      d_(j) = 0.0;
      rotateJ(j - 1, a / rho, b / rho);
    }
    Ra_.col(q_).head(q_ + 1) = d_.head(q_ + 1);
    row_(q_) = p;
    upper_(q_) = up ? 1 : 0;
    u_(q_) = mult;
    active_(p) = 1;
    ++q_;
  }

  // Removes active row k: R_a loses column k, rotations restore the triangle (and turn J).
  void dropActive(int k) {
    active_(row_(k)) = 0;
    if (held_ > 0) {  // rows held by the active set are free again
      for (int j = 0; j < m_; ++j)
        if (active_(j) == 2) active_(j) = 0;
      held_ = 0;
    }
    for (int j = k; j < q_ - 1; ++j) {
      Ra_.col(j).head(j + 2) = Ra_.col(j + 1).head(j + 2);
      row_(j) = row_(j + 1);
      upper_(j) = upper_(j + 1);
      u_(j) = u_(j + 1);
    }
    --q_;
    for (int j = k; j < q_; ++j) {
      const double a = Ra_(j, j), b = Ra_(j + 1, j);
      if (b == 0.0) continue;
      const double rho = hyp(a, b);
      const double c = a / rho, s = b / rho;
      for (int l = j; l < q_; ++l) {
        const double x = Ra_(j, l), y = Ra_(j + 1, l);
        Ra_(j, l) = c * x + s * y;
        Ra_(j + 1, l) = -s * x + c * y;
      }
      rotateJ(j, c, s);
    }
  }

  // Farkas check for a violated row p (side up) dependent on the active rows, n_p = Σ r_k n_k
  // with r = r_ ≤ 0: the certificate y = (1, −r) on (p, the active rows), checked by
  // FarkasCertificate::proves and kept as certificate() if it holds.
  template <class MatC, class VecL, class VecU>
  bool certifiedInfeasible(const MatC& C, const VecL& lower, const VecU& upper, int m, int p,
                           bool up, const QpSettings& settings) {
    cert_.row[0] = p;
    cert_.at_upper[0] = up;
    cert_.y[0] = 1.0;
    for (int k = 0; k < q_; ++k) {
      const std::size_t ks = static_cast<std::size_t>(k + 1);
      cert_.row[ks] = row_(k);
      cert_.at_upper[ks] = upper_(k) != 0;
      cert_.y[ks] = -r_(k);
    }
    cert_.count = q_ + 1;
    const bool holds = cert_.proves(C, lower, upper, m, n_, settings.feasibility_tol,
                                    [this](int j) { return rinv_(j); }, z_);
    if (!holds) cert_.count = 0;
    return holds;
  }

  // The final check's rows, with cx_ = C x: every row (both sides, active rows included)
  // within tol · (1 + |ĉ x|) scaled to a unit row, and the active rows that close to their
  // bound (complementarity: a nearly singular active set blows the multipliers up (1e30) and
  // x far out, where an "active" row ends up off its bound).
  template <class MatC, class VecL, class VecU>
  bool rowsHold(const MatC& C, const VecL& lower, const VecU& upper, int m, double tol) {
    cx_.head(m).noalias() = C.topLeftCorner(m, n_) * x_;
    for (int j = 0; j < m; ++j) {
      const double v = cx_(j) * rinv_(j), t = tol * (1.0 + std::abs(v));
      if (!((lower(j) * rinv_(j) - v) <= t) || !((v - upper(j) * rinv_(j)) <= t)) return false;
    }
    for (int k = 0; k < q_; ++k) {
      const int j = row_(k);
      const double v = cx_(j) * rinv_(j), bnd = (upper_(k) ? upper(j) : lower(j)) * rinv_(j);
      if (!(std::abs(v - bnd) <= tol * (1.0 + std::abs(v)))) return false;
    }
    return true;
  }

  // One step of iterative refinement where rowsHold failed (cx_ = C x): on a nearly dependent
  // active set a row held by the others (or an active one) can end a few tol off its bound,
  // the rounding of the active rows magnified by their ~1/σ_min combination (1e-8 on a unit
  // row of a stress instance, tol 1e-9). The residuals e of the active rows and of the rows
  // off their bounds by more than tol / 10 (at the crossed side), computed in x, are taken
  // out by the smallest correction in w = R (x − x0): Ĝ δw = e with ĝ = R⁻ᵀcᵀ, the
  // minimum-norm least-squares solution by a rank-revealing (pivoted) decomposition, so that a
  // dependent row's residual is shared rather than forced; x += R⁻¹ δw. The gradient moves by
  // Rᵀδw, in the span of those rows: verified() still checks stationarity and the gap. False
  // if more than 2n rows need it (x unchanged).
  template <class MatC, class VecL, class VecU>
  bool refine(const MatC& C, const VecL& lower, const VecU& upper, int m, double tol) {
    const int n = n_;
    const auto Rinv = Jr_.topLeftCorner(n, n);  // upper triangular, zero below (factorize)
    int rows = 0;
    const auto add = [&](int j, double bound) {
      if (rows >= 2 * n) return false;
      np_.head(n).noalias() = Rinv.transpose() * C.row(j).head(n).transpose();  // R⁻ᵀcᵀ
      const double gn = np_.head(n).norm();
      if (!(gn > 0.0)) return true;  // a zero row: nothing to correct
      Gr_.row(rows).head(n) = np_.head(n).transpose() / gn;
      er_(rows) = (bound - cx_(j)) / gn;
      ++rows;
      return true;
    };
    for (int k = 0; k < q_; ++k)
      if (!add(row_(k), upper_(k) ? upper(row_(k)) : lower(row_(k)))) return false;
    for (int j = 0; j < m; ++j) {
      if (active_(j) == 1) continue;
      const double v = cx_(j) * rinv_(j), t = 0.1 * tol * (1.0 + std::abs(v));
      const bool lo = lower(j) * rinv_(j) - v > t, up = v - upper(j) * rinv_(j) > t;
      if ((lo || up) && !add(j, lo ? lower(j) : upper(j))) return false;
    }
    if (rows == 0) return false;
    detail::qpMinNormPivoted(Gr_, rows, n, er_, z_, 1e-12, refine_ws_);
    x_.noalias() += Rinv * z_.head(n);
    return x_.allFinite();
  }

  // The final check before Optimal, O(m n + n² + q n): x finite, the rows as rowsHold checks
  // them (after up to two refine() steps where they fail), and the stationarity residual
  // RᵀR x − Rᵀ(Q_Aᵀ b) + Σ ±u_k c_k = Aᵀ(A x − b) + Σ ±u_k c_k at rounding level relative to
  // the gradient's terms, or else relative to its terms with the multipliers' and a duality
  // gap of at most kGapTol; where the active rows' multipliers fail that, multipliers fitted
  // afresh on the rows at their bounds (refitted()). Rounding with a nearly singular A shows
  // up here rather than as a wrong Optimal.
  template <class MatC, class VecL, class VecU>
  QpStatus verified(const MatC& C, const VecL& lower, const VecU& upper, int m,
                    const QpSettings& settings) {
    if (!x_.allFinite() || !feasible(C, lower, upper, m, settings.feasibility_tol))
      return QpStatus::NumericalFailure;
    double allowed = 0.0;
    if (certified(C, lower, upper, allowed)) return QpStatus::Optimal;
    return refitted(C, lower, upper, m, settings, allowed);
  }

  // The rows as rowsHold checks them, after up to two refine() steps where they fail.
  template <class MatC, class VecL, class VecU>
  bool feasible(const MatC& C, const VecL& lower, const VecU& upper, int m, double tol) {
    bool held = rowsHold(C, lower, upper, m, tol);
    for (int pass = 0; pass < 2 && !held; ++pass)
      held = refine(C, lower, upper, m, tol) && rowsHold(C, lower, upper, m, tol);
    return held;
  }

  // verified()'s optimality test of x with the active rows' multipliers u_ (rows hold; cx_ =
  // C x). Leaves z_ = R x − c (the gradient whitened: R⁻ᵀ g); allowed = the gap it accepts.
  template <class MatC, class VecL, class VecU>
  bool certified(const MatC& C, const VecL& lower, const VecU& upper, double& allowed) {
    const int n = n_;
    // g = Rᵀ(R x − c), R upper triangular in F_.
    const auto R = F_.topLeftCorner(n, n).template triangularView<Eigen::Upper>();
    z_.head(n).noalias() = R * x_;
    double scale = z_.head(n).cwiseAbs().maxCoeff() + c_.head(n).cwiseAbs().maxCoeff();
    const double fs = z_.head(n).norm() + c_.head(n).norm();  // ‖R x‖ + ‖c‖: the objective's scale
    z_.head(n) -= c_.head(n);
    r_.head(n).noalias() = R.transpose() * z_.head(n);
    double rn = 0.0;  // ‖R‖₁
    for (int j = 0; j < n; ++j) rn = std::max(rn, F_.col(j).head(j + 1).cwiseAbs().sum());
    scale *= rn;
    const double gscale = scale;  // the gradient's own terms
    for (int k = 0; k < q_; ++k) {
      const double mu = upper_(k) ? u_(k) : -u_(k);
      r_.head(n) += mu * C.row(row_(k)).head(n).transpose();
      scale += std::abs(u_(k)) * C.row(row_(k)).head(n).cwiseAbs().maxCoeff();
    }
    const double res = r_.head(n).cwiseAbs().maxCoeff();
    allowed = kGapTol * 0.5 * fs * fs;
    if (res <= kStationarityTol * gscale) return true;
    if (!(res <= kStationarityTol * scale)) return false;
    // Stationary only relative to the multipliers' terms. On nearly dependent active rows
    // they grow like 1/σ_min, x drifts off the optimum, and that test alone passed an
    // "Optimal" 2× above the optimum on a stress instance (docs/hqp.md, "The dual method's
    // final check"). The duality gap of (x, u) bounds f(x) − f* whatever the
    // multipliers' size (weak duality, u ≥ 0): ½‖R⁻ᵀr‖² (r = the Lagrangian's gradient at x,
    // above) + Σ u_k |slack_k|.
    R.transpose().solveInPlace(r_.head(n));
    double gap = 0.5 * r_.head(n).squaredNorm();
    for (int k = 0; k < q_; ++k) {
      const int j = row_(k);
      gap += u_(k) * std::abs(cx_(j) - (upper_(k) ? upper(j) : lower(j)));
    }
    return gap <= allowed;
  }

  // Where the active rows' multipliers fail certified(): on nearly dependent active rows they
  // are ~1/σ_min noise (1e6 times the gradient on a reformulated stress instance, a gap 670
  // times the allowed one) although x may lie at the optimum's vertex but for a row not yet
  // taken. Multipliers fitted afresh: μ ≥ 0 minimizing ‖z − Σ μ_j R⁻ᵀn_j‖ (z = R⁻ᵀg, n_j = ±c_j
  // the normal of a row side within `slack` of its bound, scaled as rowsHold) by the NNLS,
  // whose residual is stable where μ is not; its passive rows (numerically independent) become
  // the active set, x is moved onto their bounds (feasible()), and certified() judges the result
  // (weak duality bounds f(x) − f* by the gap for any μ ≥ 0, so no other test is needed). The
  // slack 1e-6 first, then 1e-2 (a row of the optimum's vertex 1e-3 off at x). NumericalFailure,
  // x and the active set as on entry (the order-free route and the hierarchy read the set after
  // a failure), if neither passes.
  template <class MatC, class VecL, class VecU>
  QpStatus refitted(const MatC& C, const VecL& lower, const VecU& upper, int m,
                    const QpSettings& settings, double allowed) {
    const int n = n_;
    const auto Rinv = Jr_.topLeftCorner(n, n);  // upper triangular, zero below (factorize)
    auto& E = ldp_.E();
    xs_ = x_;
    const int qs = q_;
    rows_s_.head(qs) = row_.head(qs);
    upper_s_.head(qs) = upper_.head(qs);
    u_s_.head(qs) = u_.head(qs);
    active_s_.head(m) = active_.head(m);
    ldp_.f().head(n) = z_.head(n);  // the NNLS leaves f as it is
    for (const double slack : {1e-6, 1e-2}) {
      int cols = 0;
      for (int j = 0; j < m; ++j) {
        const double v = cx_(j) * rinv_(j), t = slack * (1.0 + std::abs(v));
        for (int side = 0; side < 2; ++side) {
          const bool up = side == 1;
          const double bound = up ? upper(j) : lower(j);
          if (!(std::abs(bound) < kInf) || !((up ? bound - cx_(j) : cx_(j) - bound) * rinv_(j) <= t))
            continue;
          E.col(cols).head(n).noalias() =
              (up ? -1.0 : 1.0) * (Rinv.transpose() * C.row(j).head(n).transpose());
          ldp_row_(cols) = up ? -1 - j : j;
          ++cols;
        }
      }
      if (cols == 0 || !ldp_.solve(n, cols, decltype(ldp_)::iterationCap(settings.max_iterations, cols)) ||
          !(0.5 * ldp_.residual().head(n).squaredNorm() <= 0.5 * allowed))
        continue;  // the gradient is not in the cone of these rows' normals: x is not optimal
      for (int k = 0; k < q_; ++k) active_(row_(k)) = 0;
      q_ = 0;
      addPassiveRows([](double mu, int) { return mu; });
      const double tol = settings.feasibility_tol;
      double now = 0.0;
      if (feasible(C, lower, upper, m, tol) && certified(C, lower, upper, now)) return QpStatus::Optimal;
      x_ = xs_;
      q_ = qs;
      row_.head(qs) = rows_s_.head(qs);
      upper_.head(qs) = upper_s_.head(qs);
      u_.head(qs) = u_s_.head(qs);
      active_.head(m) = active_s_.head(m);
      rowsHold(C, lower, upper, m, tol);  // cx_ = C x again for the next slack
    }
    return QpStatus::NumericalFailure;
  }

  bool factorized_ = false;
  int n_ = 0, m_ = 0, q_ = 0, held_ = 0, iterations_ = 0;
  Certificate cert_;  // solve()'s Farkas certificate where it ended Infeasible on one
  Eigen::Matrix<double, MaxRows, MaxN> F_;   // QR of A (R on and above the diagonal)
  Eigen::Matrix<double, MaxRows, 1> c_;  // Q_Aᵀ b
  Eigen::Matrix<double, MaxN, MaxN> J_, Ra_;
  Eigen::Matrix<double, MaxN, (MaxN + 7) / 8 * 8, Eigen::RowMajor> Jr_;  // factorize(): R⁻¹ by rows
  Eigen::Matrix<double, MaxN, 1> d_, z_, r_, np_, u_;
  Eigen::Matrix<int, MaxN, 1> row_, upper_;
  Eigen::Matrix<double, MaxIneq, 1> cx_, rinv_;
  Eigen::Matrix<int, MaxIneq, 1> active_, prefer_;
  VectorX x0_, x_, xs_;  // xs_: refitted()'s entry point, with its active set:
  Eigen::Matrix<int, MaxN, 1> rows_s_, upper_s_;
  Eigen::Matrix<double, MaxN, 1> u_s_;
  Eigen::Matrix<int, MaxIneq, 1> active_s_;
  detail::NonNegativeLeastSquares<MaxN + 1, 2 * MaxIneq> ldp_;  // leastDistance()
  Eigen::Matrix<double, 2 * MaxIneq, 1> ldp_scale_;  // its columns: the row's ‖R⁻ᵀcᵀ‖
  Eigen::Matrix<int, 2 * MaxIneq, 1> ldp_row_;       // row j at lower: j, at upper: −1 − j
  Eigen::Matrix<int, MaxN, 1> order_;                // solveOrderFree(): the dual method's order
  Eigen::Matrix<double, 2 * MaxN, MaxN> Gr_;          // refine(): its rows' R⁻ᵀcᵀ
  Eigen::Matrix<double, 2 * MaxN, 1> er_;             // and residuals
  detail::QpMinNormWorkspace<MaxN, MaxN> refine_ws_;  // the pivoted path sizes it by n alone
};

}  // namespace hqp
