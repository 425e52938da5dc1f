#pragma once
// Dense primal active-set solver for least-squares QPs (the per-level QP of the
// hierarchy, paper Sec. IV-A, eqs. 3–4):
//   min_x ½‖A x − b‖²   s.t.   E x = e,   lower ≤ C x ≤ upper.
// The Hessian AᵀA is only positive SEMI-definite (rank-deficient A is the normal
// case in the lower levels), so the method never forms or inverts it:
//  - the working set K = [E_indep; C_W] is kept as an incrementally updated QR
//    factorization Kᵀ = Q [R; 0] (a reflector or Givens rotations per added row,
//    Givens per removed row), Z = Q(:, k:) spans its null space, and G = Uᵀ A Q is
//    updated with the same rotations;
//  - the subproblem optimum on the working set is x* = x_p + Z (A Z)⁺ (b − A x_p)
//    with x_p the minimum-norm point of K x = rhs, so the step is defined for any
//    rank and x* is the minimum-norm minimizer on the working set. G_Z = Uᵀ A Z is
//    kept in the form [T 0; 0 0] (T upper triangular) from the start of a cold solve,
//    or after two working-set changes of a warm one, and (A Z)⁺ is a triangular solve;
//    before that, or if T is numerically singular, a complete orthogonal
//    decomposition is used;
//  - multipliers by Kᵀ λ = −Aᵀ(A x − b) through the same QR;
//  - phase 1 is the same method on min ½t² s.t. lower − t ≤ Ĉ x ≤ upper + t, E x = e
//    (Ĉ: rows scaled to unit norm).
// Method, sign conventions, complexity and iteration bound: docs/active-set-qp.md.
// Real-time: no heap (compile-time max sizes), no exceptions, no virtual calls,
// every loop bounded by the sizes or by QpSettings::max_iterations.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Jacobi>

#include <cmath>
#include <limits>

#include "hqp/detail/householder_strips.hpp"
#include "hqp/detail/nonnegative_least_squares.hpp"
#include "hqp/detail/qp_min_norm_ls.hpp"
#include "hqp/qp_settings.hpp"
#include "hqp/qp_status.hpp"

namespace hqp {

namespace detail {
// √(a² + b²) for Givens rotations; the data are row-scaled, so the overflow guard
// of std::hypot (slow) is not needed.
inline double hyp(double a, double b) { return std::sqrt(a * a + b * b); }
}  // namespace detail

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
class ActiveSetQp {
  static_assert(MaxN > 0 && MaxRows >= 0 && MaxEq >= 0 && MaxIneq >= 0, "sizes");
  static constexpr int NV = MaxN + 1;                  // variables incl. phase-1 t
  static constexpr int MR = MaxRows > 0 ? MaxRows : 1;  // objective rows (phase 1 uses 1)
  static constexpr int ME = MaxEq > 0 ? MaxEq : 1;
  static constexpr int MI = MaxIneq > 0 ? MaxIneq : 1;

 public:
  // Eigen requires row-major storage for a matrix of at most one row.
  static constexpr int storage(int max_rows) {
    return max_rows == 1 && MaxN != 1 ? Eigen::RowMajor : Eigen::ColMajor;
  }

  // A capacity of 0 is stored as 1 (Eigen mis-sizes max-size-0 storage); the
  // run-time sizes are still bounded by MaxRows, MaxEq, MaxIneq.
  using MatrixA = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, storage(MR), MR, MaxN>;
  using MatrixE = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, storage(ME), ME, MaxN>;
  using MatrixC = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, storage(MI), MI, MaxN>;
  using VectorX = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, MaxN, 1>;
  using VectorRows = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, MR, 1>;
  using VectorEq = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, ME, 1>;
  using VectorIneq = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, MI, 1>;

  explicit ActiveSetQp(const QpSettings& settings = {}) : settings_(settings) {
    resize(0, 0, 0, 0);
  }

  // Sets the sizes. Keeps the working set (warm start) if the sizes are unchanged.
  void resize(int n, int m, int me, int mi) {
    if (n == n_ && m == m_ && me == me_ && mi == mi_) return;
    // Blocks whose size is unchanged keep their data.
    if (n != n_ || m != m_) {
      A_.setZero(m, n);
      b_.setZero(m);
    }
    if (n != n_ || me != me_) {
      E_.setZero(me, n);
      e_.setZero(me);
    }
    if (n != n_ || mi != mi_) {
      C_.setZero(mi, n);
      lower_.setConstant(mi, -kInf);
      upper_.setConstant(mi, kInf);
    }
    n_ = n;
    m_ = m;
    me_ = me;
    mi_ = mi;
    x_.setZero(n);
    lam_eq_.setZero(me);
    resetWorkingSet();
  }

  MatrixA& A() { return A_; }
  VectorRows& b() { return b_; }
  MatrixE& E() { return E_; }
  VectorEq& e() { return e_; }
  MatrixC& C() { return C_; }
  VectorIneq& lower() { return lower_; }
  VectorIneq& upper() { return upper_; }
  const MatrixA& A() const { return A_; }
  const VectorRows& b() const { return b_; }
  const MatrixE& E() const { return E_; }
  const VectorEq& e() const { return e_; }
  const MatrixC& C() const { return C_; }
  const VectorIneq& lower() const { return lower_; }
  const VectorIneq& upper() const { return upper_; }
  QpSettings& settings() { return settings_; }

  // Hessian form ½xᵀHx + gᵀx → least squares with AᵀA = H, Aᵀb = −g (eigen-
  // decomposition; the objectives differ by a constant). Set-up only: allocates.
  // Returns false if H is not PSD, rank(H) > MaxRows, or g ∉ range(H) (unbounded).
  // Call resize(n, ·, me, mi) first; this sets m = rank(H) and keeps E, C.
  bool setHessianForm(const Eigen::Ref<const Eigen::MatrixXd>& H,
                      const Eigen::Ref<const Eigen::VectorXd>& g);

  QpStatus solve(bool warm_start = true) noexcept { return solveImpl(nullptr, warm_start); }
  // x_init: a point believed feasible (e.g. 0 in the reduced space of the HQP);
  // used as the phase-2 start if it is feasible, ignored otherwise.
  QpStatus solve(const VectorX& x_init, bool warm_start) noexcept {
    return solveImpl(&x_init, warm_start);
  }

  const VectorX& x() const { return x_; }
  double objective() const { return objective_; }  // ½‖A x − b‖²
  int iterations() const { return iterations_; }
  QpStatus status() const { return status_; }

  // Active inequality rows at the solution (the working set).
  int numActive() const { return nw_; }
  int activeRow(int k) const { return ws_row_(k); }
  bool activeAtUpper(int k) const { return ws_upper_(k) != 0; }
  // μ_k ≥ 0 with  Aᵀ(Ax − b) + Eᵀλ + Σ_upper μ_k c_k − Σ_lower μ_k c_k = 0.
  double multiplier(int k) const { return ws_mu_(k); }
  const VectorEq& equalityMultipliers() const { return lam_eq_; }  // λ above
  void resetWorkingSet() {
    nw_ = 0;
    have_ws_ = false;
  }
  // The warm start the next solve() sees (recording / replay of problem instances,
  // docs/recording.md): the size n of the last resize(), and whether the working set above
  // is kept for it (a solve ended on it and no resize or reset dropped it since).
  int variables() const { return n_; }
  bool hasWorkingSet() const { return have_ws_; }
  // Sets the working set the next warm solve starts from, as if a solve at the current
  // sizes had ended on it (rows: C rows, upper: side). The solve re-checks every row.
  void setWorkingSet(int count, const int* rows, const bool* upper) {
    nw_ = copyRows(count, rows, upper, ws_row_, ws_upper_);
    have_ws_ = true;
  }
  // Rows believed to hold at their bounds at the x_init of the next solve (e.g. the rows active
  // at the point a cascade's level starts from). Used by that solve only (which drops them
  // also where it stops early, e.g. on invalid input), and only if it starts phase 2 at x_init
  // (no warm working set kept): the rows that hold at x_init to the feasibility tolerance form
  // its first working set (dependent ones are left out), where without them it starts with
  // none and re-adds each as a blocking row, one iteration apiece.
  void setStartRows(int count, const int* rows, const bool* upper) {
    start_count_ = copyRows(count, rows, upper, start_row_, start_upper_);
  }

 private:
  // The first min(count, NV) rows and sides into a row list; returns how many.
  template <class List>
  static int copyRows(int count, const int* rows, const bool* upper, List& row, List& up) {
    const int cnt = std::max(0, std::min(count, NV));
    for (int k = 0; k < cnt; ++k) {
      row(k) = rows[k];
      up(k) = upper[k] ? 1 : 0;
    }
    return cnt;
  }

  static constexpr double kInf = std::numeric_limits<double>::infinity();
  // Working-set changes after which the two-sided structure pays for itself (warm
  // starts and phase 1; a cold phase 2 sets it up before its first subproblem).
  static constexpr int kEstablishAfter = 2;
  using MatNN = Eigen::Matrix<double, NV, NV>;
  using VecN = Eigen::Matrix<double, NV, 1>;

  QpStatus solveImpl(const VectorX* x_init, bool warm_start) noexcept;
  QpStatus solveOnce(const VectorX* x_init, bool warm_start) noexcept;  // one attempt
  void finish(QpStatus s);
  bool inputValid() const;             // the input contract (InvalidInput if false)
  bool prepare();                      // scaled copies
  void startPhase(bool phase1);        // K = E rows only, objective of the phase
  bool addEqualities();                // returns false if E x = e is inconsistent
  // Adds C row j (side) to K; false if dependent: its part in null(K) relative to its norm is
  // ≤ rank_tol, or ≤ zmin with the row nearly dependent (iterate(), harmlessCut()).
  bool addRow(int j, bool upper, double zmin = 0.0);
  bool addRowVector(double rhs, double zmin = 0.0);  // adds a_ (length nv_) to K
  void removeRow(int pos);             // removes K row pos (pos ≥ neq_)
  void addWarmRows(int nw_prev);       // re-adds ws_prev_* (all at once while Q is implicit)
  // Adds cnt rows (entry c of row l: row(l, c); the phase-1 t entry is 0) to K while Q is
  // implicit, as one right-looking QR in 8-row strips; held(l, independent) after each.
  template <class Row, class Rhs, class Held>
  void addRowsImplicit(int cnt, Row row, Rhs rhs, Held held);
  // A previous working-set row that can be re-added: in range, not held yet, finite bound.
  bool warmUsable(int j, bool up) const {
    return j >= 0 && j < mi_ && !in_ws_(j) && std::abs(up ? us_(j) : ls_(j)) < kInf;
  }
  // Rank decision for a blocking row of phase 2 (docs/active-set-qp.md, "Nearly dependent
  // rows"): the largest part ζ in null(K) for which skipping the row is harmless, and whether
  // the row (w_ = Qᵀa_ set) is nearly dependent on K.
  double harmlessCut(int j, bool upper, double alpha) const;
  bool nearlyDependent(double zeta, double anorm);
  bool subproblem();                   // xs_ = optimum on the working set
  bool phase1Certified();              // phase 1's multipliers prove infeasibility (Farkas)
  bool equalitiesCertified();          // a dependent equality contradicts the others
  bool multipliers();                  // lam_ for K at x = xs_ (needs y_ from subproblem())
  // The optimality test on a nearly dependent K, where lam_'s signs are noise (docs/active-set-
  // qp.md, "Multipliers on a nearly dependent working set"): multipliers of the working set by
  // non-negative least squares on its rows. True if they prove xs_ optimal (lam_ set to them).
  bool coneMultipliers(double gs);
  QpStatus iterate(bool phase1);       // the active-set loop on the current phase
  double maxViolation(const VecN& v);  // scaled, over E and C (uses ev_, cx_)
  // Every row of E and C holds at v: scaled violation ≤ feasibility_tol · (1 + |ĉ v|)
  // (uses ev_, cx_); the final check before Optimal, O((me + mi) n).
  bool feasibleAt(const VecN& v) {
    const double tol = settings_.feasibility_tol;
    if (me_ > 0) {
      ev_.head(me_).noalias() = Es_.topLeftCorner(me_, n_) * v.head(n_);
      for (int i = 0; i < me_; ++i)
        if (!(std::abs(ev_(i) - es_(i)) <= tol * (1.0 + std::abs(ev_(i))))) return false;
    }
    if (mi_ > 0) {
      cx_.head(mi_).noalias() = Cs_.topLeftCorner(mi_, n_) * v.head(n_);
      for (int j = 0; j < mi_; ++j) {
        const double t = tol * (1.0 + std::abs(cx_(j)));
        if (!(ls_(j) - cx_(j) <= t) || !(cx_(j) - us_(j) <= t)) return false;
      }
    }
    return true;
  }
  void givens(int p, double c, double s);    // Q, G columns p, p+1
  // Q is kept implicit (Q = H_0 ⋯ H_{k−1}, the reflectors of the rows added since the
  // phase started) until the first working-set change of iterate(): a warm start whose
  // working set is still optimal never forms the n × n matrix.
  void applyReflector(int j, VecN& v) const;  // v ← H_j v
  void applyQ(VecN& v) const;                 // v ← Q v (v holds nv_ entries)
  void ensureExplicit();                      // Q_ ← H_0 ⋯ H_{k−1}
  // Q_ ← H_0 ⋯ H_{last−1}: the identity's rows through the 8-row strip kernel.
  void formQ(int last) {
    Q_.topLeftCorner(nv_, nv_).setIdentity();
    detail::reflectRowStrips<NV>(Q_, nv_, nv_, Hv_, htau_, 0, last);
  }
  void minNormPoint(VecN& out);               // Q₁ R⁻ᵀ rhs
  // yr_ = R⁻ᵀ rhs. Adding a row appends to R and rhs, removing row pos changes them from
  // pos on: entries below ny_ stay valid, so only the new ones are computed.
  void solveRt() {
    for (int i = ny_; i < k_; ++i) {
      // dot products (vectorized), not a serial chain of scalar updates
      yr_(i) = (rhs_(i) - R_.col(i).head(i).dot(yr_.head(i))) / R_(i, i);
    }
    ny_ = k_;
  }
  // Two-sided structure of G_Z = Uᵀ A Z = [T 0; 0 0], T upper triangular
  // (r = min(m, nz)): see docs/active-set-qp.md, "Incremental factorizations".
  void colRot(int i, int j, double c, double s);  // Q, G columns i, j
  void gColRot(int i, int j, double c, double s, int rows);  // G columns i, j, rows [0, rows)
  // G rows i, j and c̃; Z columns before local index zfrom are zero in both rows.
  void rowRot(int i, int j, double c, double s, int zfrom = 0);
  void establishStructure();                      // G_Z → [T 0; 0 0]
  void addRowStructured(double rhs);               // after the independence test
  void restoreAfterRemove();                       // new first Z column

  QpSettings settings_;
  int n_ = -1, m_ = -1, me_ = -1, mi_ = -1;
  MatrixA A_;
  VectorRows b_;
  MatrixE E_;
  VectorEq e_;
  MatrixC C_;
  VectorIneq lower_, upper_;

  // Scaled rows (unit norm; zero rows kept as zero).
  Eigen::Matrix<double, MI, MaxN> Cs_;
  Eigen::Matrix<double, MI, 1> ls_, us_, cinv_;
  Eigen::Matrix<double, ME, MaxN> Es_;
  Eigen::Matrix<double, ME, 1> es_, einv_, ev_;
  Eigen::Matrix<int, ME, 1> eq_indep_;  // 1 if E row is in K
  double scale_a_ = 1.0;                // ‖A‖_F, for the absolute rank cut of A Z

  // Current phase.
  int nv_ = 0;     // variables: n (phase 2) or n + 1 (phase 1)
  int mc_ = 0;     // objective rows

  // Working set K (k_ rows: neq_ equalities, then nw_ inequalities).
  int k_ = 0, neq_ = 0, nw_ = 0;
  bool have_ws_ = false;
  bool xs_fresh_ = false;  // xs_ is the subproblem optimum of the current K
  bool cold_ = false;      // this solve has no previous working set to start from
  Eigen::Matrix<int, NV, 1> eq_pos_;     // E row of K row i < neq_
  Eigen::Matrix<int, NV, 1> ws_row_;     // C row of K row neq_ + i
  Eigen::Matrix<int, NV, 1> ws_upper_;   // side
  Eigen::Matrix<double, NV, 1> ws_mu_;   // reported multipliers (unscaled, ≥ 0)
  Eigen::Matrix<int, NV, 1> ws_prev_row_, ws_prev_upper_;  // warm-start copy
  Eigen::Matrix<int, NV, 1> start_row_, start_upper_;      // setStartRows()
  int start_count_ = 0;
  Eigen::Matrix<int, NV, 1> cand_row_, cand_upper_;        // rows addWarmRows tries
  Eigen::Matrix<double, 8, NV> strip_;                     // 8 of their rows, reduced
  Eigen::Matrix<int, MI, 1> in_ws_;
  Eigen::Matrix<int, MI, 1> skip_;  // iterate(): K version at which row j was found dependent
  Eigen::Matrix<int, MI, 1> pin_;   // iterate(): row kept in K, never dropped (see there)
  Eigen::Matrix<double, NV, 1> rhs_;
  MatNN Q_, R_;
  bool qexplicit_ = false;  // Q_ is valid; otherwise Q is the product of Hv_, htau_
  MatNN Hv_;                // reflector j: essential part in Hv_(j+1:, j)
  VecN htau_;
  Eigen::Matrix<double, MR, NV, Eigen::RowMajor> AQ_;  // G = Uᵀ A Q (U: row rotations, in structured mode)
  Eigen::Matrix<double, MR, 1> cU_;       // c̃ = Uᵀ b
  bool trap_ = false;                     // G_Z has the [T 0; 0 0] structure
  int changes_ = 0;                       // working-set changes in this phase
  Eigen::Matrix<double, (MR > NV ? MR : NV), 1> hv_;  // reflector scratch
  Eigen::Matrix<double, MR, NV> M_;       // A Z scratch
  Eigen::Matrix<double, MR, 1> r_;        // residual scratch
  Eigen::Matrix<double, MR, 1> dinv_;     // 1 / T(i, i)
  VecN rc_, rs_;                          // recorded rotations (detail::rotationChain)
  VecN yr_;                               // R⁻ᵀ rhs, valid below ny_
  int ny_ = 0;
  VecN a_, w_, xs_, xc_, d_, y_, p_, lam_;
  Eigen::Matrix<double, (MR > NV ? MR : NV), 1> work_;  // Householder workspace
  Eigen::Matrix<double, MI, 1> cd_, cx_;  // Ĉ d, Ĉ x (ratio test)
  bool cx_at_xc_ = false;                 // cx_ = Ĉ xc_ exactly (set by maxViolation(xc_))
  detail::QpMinNormWorkspace<MR, NV> cod_;
  // coneMultipliers(): the working set's rows (x part; both signs for equalities) as columns.
  detail::NonNegativeLeastSquares<MaxN, 2 * NV> cone_;
  Eigen::Matrix<int, 2 * NV, 1> cone_row_;      // K row of column l
  Eigen::Matrix<double, 2 * NV, 1> cone_sign_;  // its sign

  VectorX x_;
  VectorEq lam_eq_;
  double objective_ = 0.0;
  int iterations_ = 0;
  QpStatus status_ = QpStatus::Optimal;
};

// ---------------------------------------------------------------------------

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::setHessianForm(
    const Eigen::Ref<const Eigen::MatrixXd>& H, const Eigen::Ref<const Eigen::VectorXd>& g) {
  const int n = static_cast<int>(H.rows());
  if (H.cols() != n || g.size() != n || n > MaxN || n <= 0) return false;
  if (!H.allFinite() || !g.allFinite()) return false;
  const Eigen::MatrixXd Hs = 0.5 * (H + H.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Hs);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::VectorXd& lam = eig.eigenvalues();
  const Eigen::MatrixXd& V = eig.eigenvectors();
  const double lmax = lam.cwiseAbs().maxCoeff();
  const double tol = 1e-12 * (lmax > 0.0 ? lmax : 1.0);
  int rank = 0;
  for (int i = 0; i < n; ++i) {
    if (lam(i) < -tol) return false;  // not PSD
    if (lam(i) > tol) ++rank;
  }
  if (rank > MaxRows) return false;
  const Eigen::VectorXd vg = V.transpose() * g;
  for (int i = 0; i < n; ++i)  // g must lie in range(H), else unbounded below
    if (lam(i) <= tol && std::abs(vg(i)) > 1e-9 * (1.0 + g.norm())) return false;
  resize(n, rank, me_ < 0 ? 0 : me_, mi_ < 0 ? 0 : mi_);
  int row = 0;
  for (int i = 0; i < n; ++i) {
    if (lam(i) <= tol) continue;
    const double sq = std::sqrt(lam(i));
    A_.row(row) = sq * V.col(i).transpose();  // A = D^½ Vᵀ  ⇒ AᵀA = H
    b_(row) = -vg(i) / sq;                    // Aᵀb = −g
    ++row;
  }
  return true;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::givens(int p, double c, double s) {
  // Q ← Q Gᵀ on columns p, p+1 (and A Q likewise).
  Eigen::JacobiRotation<double> g(c, -s);
  Q_.block(0, p, nv_, 2).applyOnTheRight(0, 1, g);
  if (mc_ > 0) AQ_.block(0, p, mc_, 2).applyOnTheRight(0, 1, g);
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::applyReflector(int j, VecN& v) const {
  const double tau = htau_(j);
  if (tau == 0.0) return;
  const int len = nv_ - j - 1;
  const double s = tau * (v(j) + Hv_.col(j).segment(j + 1, len).dot(v.segment(j + 1, len)));
  v(j) -= s;
  v.segment(j + 1, len) -= s * Hv_.col(j).segment(j + 1, len);
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::applyQ(VecN& v) const {
  if (qexplicit_) {
    const VecN t = v;
    v.head(nv_).noalias() = Q_.topLeftCorner(nv_, nv_) * t.head(nv_);
  } else {
    for (int j = k_ - 1; j >= 0; --j) applyReflector(j, v);
  }
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::ensureExplicit() {
  if (qexplicit_) return;
  formQ(k_);
  qexplicit_ = true;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::minNormPoint(VecN& out) {
  solveRt();
  out.head(k_) = yr_.head(k_);
  out.segment(k_, nv_ - k_).setZero();
  applyQ(out);
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::addRowVector(double rhs, double zmin) {
  if (k_ >= nv_) return false;
  // w = Qᵀ a; the row is independent of K iff w(k:) = Zᵀ a ≠ 0.
  const int nz = nv_ - k_;
  if (qexplicit_) {
    w_.head(nv_).noalias() = Q_.topLeftCorner(nv_, nv_).transpose() * a_.head(nv_);
  } else {
    w_.head(nv_) = a_.head(nv_);
    for (int j = 0; j < k_; ++j) applyReflector(j, w_);
  }
  const double an2 = a_.head(nv_).squaredNorm();
  const double wn2 = w_.segment(k_, nz).squaredNorm();
  const double tol = settings_.rank_tol;
  if (!(wn2 > tol * tol * an2) || an2 == 0.0) return false;
  if (wn2 <= zmin * zmin * an2 && nearlyDependent(std::sqrt(wn2 / an2), std::sqrt(an2)))
    return false;
  if (trap_) {
    addRowStructured(rhs);
    return true;
  }
  // One reflector H with H w(k:) = β e₀, applied to the Z columns of Q and G.
  double tau = 0.0, beta = 0.0;
  w_.segment(k_, nz).makeHouseholderInPlace(tau, beta);
  if (nz > 1) {
    if (qexplicit_) {
      Q_.block(0, k_, nv_, nz)
          .applyHouseholderOnTheRight(w_.segment(k_ + 1, nz - 1), tau, work_.data());
    } else {
      Hv_.col(k_).segment(k_ + 1, nz - 1) = w_.segment(k_ + 1, nz - 1);
      htau_(k_) = tau;
    }
    if (mc_ > 0) detail::reflectRows(w_.segment(k_ + 1, nz - 1), tau, AQ_.block(0, k_, mc_, nz));
  } else {
    beta = w_(k_);
    htau_(k_) = 0.0;
  }
  R_.col(k_).head(k_) = w_.head(k_);
  R_(k_, k_) = beta;
  R_.col(k_).segment(k_ + 1, nv_ - k_ - 1).setZero();
  rhs_(k_) = rhs;
  ++k_;
  return true;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::colRot(int i, int j, double c, double s) {
  // col_i ← c col_i + s col_j,  col_j ← −s col_i + c col_j
  const Eigen::JacobiRotation<double> g(c, -s);
  Q_.topLeftCorner(nv_, nv_).applyOnTheRight(i, j, g);
  if (mc_ > 0) AQ_.topLeftCorner(mc_, nv_).applyOnTheRight(i, j, g);
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::gColRot(int i, int j, double c, double s,
                                                         int rows) {
  for (int l = 0; l < rows; ++l) {
    const double a = AQ_(l, i), b = AQ_(l, j);
    AQ_(l, i) = c * a + s * b;
    AQ_(l, j) = -s * a + c * b;
  }
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::rowRot(int i, int j, double c, double s,
                                                        int zfrom) {
  // row_i ← c row_i + s row_j,  row_j ← −s row_i + c row_j  (U ← U Gᵀ); G is
  // row-major, so both segments are contiguous (Eigen's vectorized plane rotation).
  const Eigen::JacobiRotation<double> g(c, s);
  if (k_ > 0) AQ_.leftCols(k_).applyOnTheLeft(i, j, g);
  if (nv_ > k_ + zfrom) AQ_.middleCols(k_ + zfrom, nv_ - k_ - zfrom).applyOnTheLeft(i, j, g);
  const double ci = cU_(i), cj = cU_(j);
  cU_(i) = c * ci + s * cj;
  cU_(j) = -s * ci + c * cj;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::establishStructure() {
  // Bring G_Z = G(:, k:) to [T 0; 0 0] once; afterwards every working-set change
  // keeps it with O((n + m)(nz + m)) rotations. Q may still be implicit (a cold start).
  const int nz = nv_ - k_;
  trap_ = true;
  if (mc_ > 0 && nz > mc_) {
    // Wide: reflectors from the right on the rows of G taken bottom-up, G_Z W = J [L 0]
    // (J reverses the rows, L lower triangular), so J L is upper anti-triangular and
    // reversing the first mc Z columns makes it the upper triangular T: no reflectors
    // from the left. The rows go 8 at a time through a local block as in
    // addRowsImplicit(); the reflectors are kept like those of an implicit Q (Hv_, htau_
    // at k.., free once Q is explicit) and Q gets them all in one pass.
    for (int s0 = 0; s0 < mc_; s0 += 8) {
      const int h = std::min(8, mc_ - s0);
      for (int l = 0; l < 8; ++l) {
        if (l < h) strip_.row(l).head(nv_) = AQ_.row(mc_ - 1 - s0 - l).head(nv_);
        else strip_.row(l).head(nv_).setZero();
      }
      detail::reflectStrip<NV>(strip_, nv_, Hv_, htau_, k_, k_ + s0);
      for (int l = 0; l < h; ++l) {
        const int c0 = k_ + s0 + l, len = nv_ - c0;  // len ≥ nz − mc + 1 ≥ 2
        double tau = 0.0, beta = 0.0;
        auto v = Hv_.col(c0).segment(c0, len);
        v = strip_.row(l).segment(c0, len).transpose();
        v.makeHouseholderInPlace(tau, beta);
        htau_(c0) = tau;
        if (l + 1 < h) detail::reflectStrip<NV>(strip_, nv_, Hv_, htau_, c0, c0 + 1);
        strip_(l, c0) = beta;  // what H_c0 made of row l, with exact zeros
        strip_.row(l).segment(c0 + 1, len - 1).setZero();
      }
      for (int l = 0; l < h; ++l) AQ_.row(mc_ - 1 - s0 - l).head(nv_) = strip_.row(l).head(nv_);
    }
    if (qexplicit_) {
      detail::reflectRowStrips<NV>(Q_, nv_, nv_, Hv_, htau_, k_, k_ + mc_);
    } else {
      formQ(k_ + mc_);  // Q = H_0 ⋯ H_{k−1} W_k ⋯ W_{k+mc−1}
      qexplicit_ = true;
    }
    for (int t = 0; t < mc_ / 2; ++t) {
      Q_.col(k_ + t).head(nv_).swap(Q_.col(k_ + mc_ - 1 - t).head(nv_));
      AQ_.col(k_ + t).head(mc_).swap(AQ_.col(k_ + mc_ - 1 - t).head(mc_));
    }
    return;
  }
  ensureExplicit();
  if (mc_ == 0 || nz == 0) return;
  // Reflectors from the left (QR of the first r columns of G_Z): T upper triangular.
  const int r = nz < mc_ ? nz : mc_;
  for (int i = 0; i < r; ++i) {
    const int len = mc_ - i;
    if (len <= 1) break;
    hv_.head(len) = AQ_.col(k_ + i).segment(i, len);
    double tau = 0.0, beta = 0.0;
    hv_.head(len).makeHouseholderInPlace(tau, beta);
    AQ_.block(i, 0, len, nv_)
        .applyHouseholderOnTheLeft(hv_.segment(1, len - 1), tau, work_.data());
    cU_.segment(i, len).applyHouseholderOnTheLeft(hv_.segment(1, len - 1), tau, work_.data());
    AQ_.col(k_ + i).segment(i + 1, len - 1).setZero();
  }
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::addRowStructured(double rhs) {
  // w_ = Qᵀ a is set. Its Z part is rotated into one Z column, the target, which then
  // moves to position k (joins Q₁). The target is the last column of T (tall case) or
  // the first all-zero column r (wide case, after one reflector on Q alone gathers w over
  // the zero columns): rotations run left to right, each column rotation (j, j+1) of T
  // fills (j+1, j), removed at once by a row rotation, and taking out the target column
  // leaves T upper triangular. One sweep (a bottom-up sweep into the first Z column
  // needed a second one to restore T after that column left).
  const int nz = nv_ - k_;
  const int r = nz < mc_ ? nz : mc_;
  int last = nz - 1;  // local index of the target column
  if (nz > r) {
    last = r;
    const int len = nz - r;
    if (len > 1) {
      double tau = 0.0, beta = 0.0;
      w_.segment(k_ + r, len).makeHouseholderInPlace(tau, beta);
      Q_.block(0, k_ + r, nv_, len)
          .applyHouseholderOnTheRight(w_.segment(k_ + r + 1, len - 1), tau, work_.data());
      w_(k_ + r) = beta;
      w_.segment(k_ + r + 1, len - 1).setZero();
    }
  }
  // The rotations of Q depend on w alone: recorded, applied in one chain at the end. G
  // gets each at once (its row rotation depends on it).
  for (int j = 0; j < last; ++j) {
    const int i = k_ + j;
    const double wi = w_(i), wj = w_(i + 1);
    rc_(i) = 1.0;
    rs_(i) = 0.0;
    if (wi == 0.0) continue;
    const double rho = detail::hyp(wi, wj);
    const double c = wj / rho, s = -wi / rho;  // (w_i, w_i+1) → (0, ρ)
    rc_(i) = c;
    rs_(i) = s;
    w_(i) = 0.0;
    w_(i + 1) = rho;
    // Columns j, j+1 of G_Z: rows > j+1 are zero (and row j+1 of column j).
    const bool fill = j + 1 < r;  // column j+1 has a diagonal entry of T
    gColRot(i, i + 1, c, s, fill ? j + 2 : j + 1);
    if (fill) {
      const double a = AQ_(j, i), b = AQ_(j + 1, i);
      if (b != 0.0) {
        const double rr = detail::hyp(a, b);
        rowRot(j, j + 1, a / rr, b / rr, j);
        AQ_(j + 1, i) = 0.0;
      }
    }
  }
  // Q: the chain, storing each column one to the right and the target at k; G likewise.
  if (last > 0) {
    detail::rotationChain<detail::RotationChain::UpShift>(Q_, nv_, k_, k_ + last, rc_, rs_);
    for (int l = 0; l < mc_; ++l) {
      double* g = &AQ_(l, k_);
      const double t = g[last];
      for (int j = last; j > 0; --j) g[j] = g[j - 1];
      g[0] = t;
    }
  }
  for (int i = 0; i < k_; ++i) R_(i, k_) = w_(i);
  R_(k_, k_) = w_(k_ + last);
  R_.col(k_).segment(k_ + 1, nv_ - k_ - 1).setZero();
  rhs_(k_) = rhs;
  ++k_;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::restoreAfterRemove() {
  // G_Z = [g, T, 0]: zero g below its first entry with row rotations (bottom-up);
  // in the wide case this leaves one extra column (index m), cleared against the
  // diagonal with column rotations.
  if (mc_ == 0) return;
  const int nz = nv_ - k_;  // includes the new column
  for (int i = mc_ - 1; i >= 1; --i) {
    const double a = AQ_(i - 1, k_), b = AQ_(i, k_);
    if (b == 0.0) continue;
    const double rr = detail::hyp(a, b);
    rowRot(i - 1, i, a / rr, b / rr);
    AQ_(i, k_) = 0.0;
  }
  if (nz > mc_) {
    const int e = k_ + mc_;  // the extra column
    for (int i = mc_ - 1; i >= 0; --i) {
      const double a = AQ_(i, k_ + i), b = AQ_(i, e);
      if (b == 0.0) continue;
      const double rr = detail::hyp(a, b);
      colRot(k_ + i, e, a / rr, b / rr);
      AQ_(i, e) = 0.0;
    }
  }
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::removeRow(int pos) {
  // Delete column pos of R, then restore the triangle (Hessenberg → Givens).
  for (int j = pos; j < k_ - 1; ++j) {
    for (int i = 0; i <= j + 1; ++i) R_(i, j) = R_(i, j + 1);
    rhs_(j) = rhs_(j + 1);
  }
  for (int j = pos; j < k_ - 1; ++j) {
    const double a = R_(j, j), b = R_(j + 1, j);
    if (b == 0.0) continue;
    const double rho = detail::hyp(a, b);
    const double c = a / rho, s = b / rho;
    for (int l = j; l < k_ - 1; ++l) {
      const double rj = R_(j, l), rq = R_(j + 1, l);
      R_(j, l) = c * rj + s * rq;
      R_(j + 1, l) = -s * rj + c * rq;
    }
    R_(j + 1, j) = 0.0;
    givens(j, c, s);
  }
  --k_;
  if (ny_ > pos) ny_ = pos;
  for (int i = 0; i < nv_; ++i) R_(i, k_) = 0.0;
  if (trap_) restoreAfterRemove();
  // Keep the inequality bookkeeping in K order.
  const int w = pos - neq_;
  in_ws_(ws_row_(w)) = 0;
  for (int i = w; i < nw_ - 1; ++i) {
    ws_row_(i) = ws_row_(i + 1);
    ws_upper_(i) = ws_upper_(i + 1);
  }
  --nw_;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
double ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::harmlessCut(int j, bool upper,
                                                              double alpha) const {
  // Row j (unit norm) blocks the step xc + α d. Left out of K, it moves by at most ζ (1 − α) ‖d‖
  // over the rest of the step (d ∈ null(K), ζ = ‖Zᵀĉ_j‖), so for ζ up to the returned cut it
  // stays within its feasibility tolerance (the one feasibleAt() accepts): skipping it changes
  // x by no more than the solver accepts anyway. 0: no room left.
  const double bound = upper ? us_(j) : ls_(j);
  const double viol = upper ? cx_(j) - bound : bound - cx_(j);  // > 0: already past it
  const double room =
      settings_.feasibility_tol * (1.0 + std::abs(bound)) - (viol > 0.0 ? viol : 0.0);
  const double reach = (1.0 - alpha) * d_.head(nv_).norm();
  if (!(room > 0.0)) return 0.0;
  return reach > room ? room / reach : 1.0;  // 1: every ζ (≤ 1 for a unit row)
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::nearlyDependent(double zeta, double anorm) {
  // In exact arithmetic a blocking row is never dependent on K: d ∈ null(K) and ĉ d ≠ 0
  // (Nocedal & Wright, Numerical Optimization, 2nd ed., Sec. 16.5). One nearly dependent on K
  // blocks through rounding, or because the vertex it forms with K is ill-posed; added, it
  // makes K' = [K; a] nearly singular and the multipliers grow like 1/σ_min(K') (~1e16 seen on
  // the corpus), so their signs, hence the drops and the optimality test, become noise.
  // Measure: a = Kᵀβ + ζ‖a‖ z with Rβ = w(0:k) (Kᵀ = Q₁R), so K' becomes exactly singular
  // under a perturbation of its rows of size δ = ζ / ‖(β/‖a‖, 1)‖ ≥ σ_min(K'). Unlike ζ, δ also
  // catches a row moderately close to a K that is itself nearly dependent (ζ ~1e-7 then ~1e-9
  // gave δ ~1e-16). Nearly dependent: δ ≤ √ε, more than half the multipliers' digits lost.
  // The caller skips such a row only where that is harmless (harmlessCut()), as an exactly
  // dependent one is: treated as held by K, like Goldfarb & Idnani's constraint whose normal
  // is in the span of the active ones. Refusing it where it is not harmless was measured to
  // break feasibility of other QPs (docs/hqp-tuning.md, "The corpus's first check").
  constexpr double kSqrtEps = 1.4901161193847656e-08;
  if (zeta <= kSqrtEps) return true;  // δ ≤ ζ
  for (int i = k_ - 1; i >= 0; --i) {  // β = R⁻¹ w(0:k) into p_ (scratch until subproblem())
    double t = w_(i);
    for (int l = i + 1; l < k_; ++l) t -= R_(i, l) * p_(l);
    p_(i) = t / R_(i, i);
  }
  const double c = std::sqrt(1.0 + p_.head(k_).squaredNorm() / (anorm * anorm));
  return !(zeta > kSqrtEps * c);  // δ ≤ √ε, or NaN
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::addRow(int j, bool upper, double zmin) {
  for (int i = 0; i < n_; ++i) a_(i) = Cs_(j, i);
  if (nv_ > n_) a_(n_) = upper ? -1.0 : 1.0;
  if (!addRowVector(upper ? us_(j) : ls_(j), zmin)) return false;
  ws_row_(nw_) = j;
  ws_upper_(nw_) = upper ? 1 : 0;
  in_ws_(j) = 1;
  ++nw_;
  return true;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::addWarmRows(int nw_prev) {
  // The same as addRow() for each previous working-set row in turn (same acceptance test,
  // same reflectors), but organised as one right-looking Householder QR of the stacked
  // rows: each new reflector is applied to all rows still to come, and G = A Q is updated
  // once at the end, both with the 8-row strip kernel instead of one dot + axpy per row.
  if (qexplicit_ || trap_ || nv_ != n_) {  // not the state after startPhase(false)
    for (int w = 0; w < nw_prev; ++w) {
      const int j = ws_prev_row_(w);
      const bool up = ws_prev_upper_(w) != 0;
      if (warmUsable(j, up)) addRow(j, up);
    }
    return;
  }
  int cnt = 0;
  for (int w = 0; w < nw_prev && cnt < NV; ++w) {
    const int j = ws_prev_row_(w);
    const bool up = ws_prev_upper_(w) != 0;
    if (!warmUsable(j, up)) continue;
    in_ws_(j) = 1;  // provisional (a repeated row is skipped); cleared again if rejected
    cand_row_(cnt) = j;
    cand_upper_(cnt) = up ? 1 : 0;
    ++cnt;
  }
  addRowsImplicit(
      cnt, [this](int l, int c) { return Cs_(cand_row_(l), c); },
      [this](int l) { return cand_upper_(l) ? us_(cand_row_(l)) : ls_(cand_row_(l)); },
      [this](int l, bool held) {
        const int j = cand_row_(l);
        if (!held) {
          in_ws_(j) = 0;  // dependent on K: not held
          return;
        }
        ws_row_(nw_) = j;
        ws_upper_(nw_) = cand_upper_(l);
        ++nw_;
      });
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
template <class Row, class Rhs, class Held>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::addRowsImplicit(int cnt, Row row, Rhs rhs,
                                                                 Held held) {
  const int k0 = k_;
  const double tol2 = settings_.rank_tol * settings_.rank_tol;
  // Candidates 8 at a time in a local block (one row per lane): all reflectors so far
  // (equalities, earlier blocks) are applied to the block at once, then each accepted row's
  // reflector to the whole block, so nothing is stored back between reflectors.
  for (int s0 = 0; s0 < cnt; s0 += 8) {
    const int h = std::min(8, cnt - s0);
    strip_.leftCols(nv_).setZero();
    for (int l = 0; l < h; ++l)
      for (int c = 0; c < n_; ++c) strip_(l, c) = row(s0 + l, c);
    detail::reflectStrip<NV>(strip_, nv_, Hv_, htau_, 0, k_);
    for (int l = 0; l < h; ++l) {
      const int nz = nv_ - k_;
      double an2 = 0.0;
      for (int c = 0; c < n_; ++c) an2 += row(s0 + l, c) * row(s0 + l, c);
      for (int c = 0; c < nv_; ++c) w_(c) = strip_(l, c);
      const double wn2 = nz > 0 ? w_.segment(k_, nz).squaredNorm() : 0.0;
      if (nz <= 0 || !(wn2 > tol2 * an2) || an2 == 0.0) {
        held(s0 + l, false);
        continue;
      }
      double tau = 0.0, beta = 0.0;
      if (nz > 1) {
        w_.segment(k_, nz).makeHouseholderInPlace(tau, beta);
        Hv_.col(k_).segment(k_ + 1, nz - 1) = w_.segment(k_ + 1, nz - 1);
      } else {
        beta = w_(k_);
      }
      htau_(k_) = tau;
      R_.col(k_).head(k_) = w_.head(k_);
      R_(k_, k_) = beta;
      R_.col(k_).segment(k_ + 1, nv_ - k_ - 1).setZero();
      rhs_(k_) = rhs(s0 + l);
      held(s0 + l, true);
      ++k_;
      if (tau != 0.0 && l + 1 < h) detail::reflectStrip<NV>(strip_, nv_, Hv_, htau_, k_ - 1, k_);
    }
  }
  if (mc_ > 0 && k_ > k0) {  // G ← G H_{k0} ⋯ H_{k−1}
    M_.topLeftCorner(mc_, nv_) = AQ_.topLeftCorner(mc_, nv_);
    detail::reflectRowStrips<NV>(M_, mc_, nv_, Hv_, htau_, k0, k_);
    AQ_.topLeftCorner(mc_, nv_) = M_.topLeftCorner(mc_, nv_);
  }
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::inputValid() const {
  // The input contract (docs/hqp.md, "Contracts"): finite data of magnitude ≤ max_magnitude,
  // bounds ±inf only on their own side. One vectorized pass per block.
  if (n_ <= 0) return true;
  const double mx = settings_.max_magnitude;
  if (!detail::withinMagnitude(A_, mx) || !detail::withinMagnitude(b_, mx)) return false;
  if (!detail::withinMagnitude(E_, mx) || !detail::withinMagnitude(e_, mx)) return false;
  if (!detail::withinMagnitude(C_, mx)) return false;
  for (int j = 0; j < mi_; ++j)
    if (!detail::boundsValid(lower_(j), upper_(j), mx)) return false;
  return true;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::prepare() {
  // Rows scaled to unit norm (zero rows stay zero); the input passed inputValid().
  if (n_ <= 0) return true;
  // A row norm is finite iff the row is.
  if (mi_ > 0) {
    cinv_.head(mi_) = C_.rowwise().norm();
    if (!cinv_.head(mi_).allFinite()) return false;
    for (int j = 0; j < mi_; ++j) cinv_(j) = cinv_(j) > 0.0 ? 1.0 / cinv_(j) : 1.0;
    Cs_.topLeftCorner(mi_, n_) = cinv_.head(mi_).asDiagonal() * C_;
    ls_.head(mi_) = lower_.cwiseProduct(cinv_.head(mi_));
    us_.head(mi_) = upper_.cwiseProduct(cinv_.head(mi_));
    in_ws_.head(mi_).setZero();
  }
  if (me_ > 0) {
    einv_.head(me_) = E_.rowwise().norm();
    if (!einv_.head(me_).allFinite()) return false;
    for (int i = 0; i < me_; ++i) einv_(i) = einv_(i) > 0.0 ? 1.0 / einv_(i) : 1.0;
    Es_.topLeftCorner(me_, n_) = einv_.head(me_).asDiagonal() * E_;
    es_.head(me_) = e_.cwiseProduct(einv_.head(me_));
  }
  scale_a_ = m_ > 0 ? A_.norm() : 0.0;
  return std::isfinite(scale_a_);
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::startPhase(bool phase1) {
  // Q = I, G = A (phase 1: A = e_tᵀ, b = 0 for ½t²), c̃ = b. R is written column by
  // column as rows are added.
  nv_ = phase1 ? n_ + 1 : n_;
  qexplicit_ = false;  // k = 0: Q = I
  if (phase1) {
    mc_ = 1;
    AQ_.row(0).head(nv_).setZero();
    AQ_(0, n_) = 1.0;
    cU_(0) = 0.0;
  } else {
    mc_ = m_;
    if (m_ > 0) {
      AQ_.topLeftCorner(m_, n_) = A_;
      cU_.head(m_) = b_;
    }
  }
  trap_ = false;
  changes_ = 0;
  k_ = 0;
  ny_ = 0;
  neq_ = 0;
  for (int j = 0; j < mi_; ++j) in_ws_(j) = 0;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::addEqualities() {
  if (qexplicit_ || trap_ || k_ != 0) {  // not the state after startPhase()
    const int nw_keep = nw_;
    nw_ = 0;
    for (int i = 0; i < me_; ++i) {
      for (int c = 0; c < n_; ++c) a_(c) = Es_(i, c);
      if (nv_ > n_) a_(n_) = 0.0;
      eq_indep_(i) = 0;
      if (addRowVector(es_(i))) {
        eq_indep_(i) = 1;
        eq_pos_(neq_) = i;
        ++neq_;
      }
    }
    nw_ = nw_keep;
  } else {
    addRowsImplicit(
        me_, [this](int l, int c) { return Es_(l, c); }, [this](int l) { return es_(l); },
        [this](int l, bool indep) {
          eq_indep_(l) = indep ? 1 : 0;
          if (indep) eq_pos_(neq_++) = l;
        });
  }
  // Consistency of the dependent rows: residual at the minimum-norm point.
  if (neq_ == me_) return true;
  minNormPoint(xs_);  // scratch: xs_ (xc_ holds the iterate)
  for (int i = 0; i < me_; ++i) {
    double s = -es_(i);
    for (int c = 0; c < n_; ++c) s += Es_(i, c) * xs_(c);
    if (std::abs(s) > settings_.feasibility_tol) return false;
  }
  return true;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::subproblem() {
  // x_p = Q₁ R⁻ᵀ rhs: the minimum-norm point of K x = rhs.
  solveRt();
  y_.head(k_) = yr_.head(k_);
  const int nz = nv_ - k_;
  // r = b − A x_p = b − (A Q₁) y ;  M = A Z = (A Q)(:, k:)
  if (mc_ > 0) {
    // Rotated residual r̃ = Uᵀ(b − A x_p) = c̃ − G₁ y.
    r_.head(mc_) = cU_.head(mc_);
    if (k_ > 0) r_.head(mc_).noalias() -= AQ_.topLeftCorner(mc_, k_) * y_.head(k_);
    if (nz > 0) {
      const double tol = settings_.rank_tol * (scale_a_ > 1.0 ? scale_a_ : 1.0);
      const int r = nz < mc_ ? nz : mc_;
      bool done = false;
      if (trap_) {
        // G_Z = [T 0; 0 0]: p = [T⁻¹ r̃(0:r); 0] is the minimum-norm minimizer.
        done = true;
        for (int i = 0; i < r; ++i) {
          const double t = AQ_(i, k_ + i);
          done = done && std::abs(t) > tol;
          dinv_(i) = 1.0 / t;  // independent divisions, off the solve's dependency chain
        }
        if (done) {
          // By columns: the dependency chain is one multiply and one FMA per entry
          // (a dot product per row ends in a horizontal reduction each).
          for (int i = r - 1; i >= 0; --i) {
            const double pi = r_(i) * dinv_(i);
            p_(i) = pi;
            for (int l = 0; l < i; ++l) r_(l) -= pi * AQ_(l, k_ + i);
          }
          p_.segment(r, nz - r).setZero();
        }
      }
      if (!done) {  // generic (rank-deficient, or structure not yet built)
        M_.topLeftCorner(mc_, nz) = AQ_.block(0, k_, mc_, nz);
        detail::qpMinNormLeastSquares(M_, mc_, nz, r_, p_, tol, cod_);
      }
    }
  }
  if (mc_ == 0) p_.head(nz).setZero();
  // x* = Q [y; p]  (x_p ⊥ range(Z), so the min-norm p gives the min-norm x*).
  y_.segment(k_, nz) = p_.head(nz);
  if (qexplicit_) {
    xs_.head(nv_).noalias() = Q_.topLeftCorner(nv_, nv_) * y_.head(nv_);
  } else {
    xs_.head(nv_) = y_.head(nv_);
    applyQ(xs_);
  }
  return xs_.head(nv_).allFinite();
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::multipliers() {
  // Kᵀ λ = −g, g = Aᵀ(A x − b):  R λ = −(A Q₁)ᵀ (A x − b).
  if (k_ == 0) return true;
  if (mc_ > 0) {
    // Uᵀ(A x − b) = G (Qᵀ x) − c̃, and Qᵀ x = y_ = [y; p] from subproblem().
    r_.head(mc_) = -cU_.head(mc_);
    r_.head(mc_).noalias() += AQ_.topLeftCorner(mc_, nv_) * y_.head(nv_);
    y_.head(k_).noalias() = -AQ_.topLeftCorner(mc_, k_).transpose() * r_.head(mc_);
  } else {
    y_.head(k_).setZero();
  }
  // R λ = y by columns (axpy, vectorized; R is column-major).
  lam_.head(k_) = y_.head(k_);
  for (int i = k_ - 1; i >= 0; --i) {
    lam_(i) /= R_(i, i);
    lam_.head(i) -= lam_(i) * R_.col(i).head(i);
  }
  return lam_.head(k_).allFinite();
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
double ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::maxViolation(const VecN& v) {
  double viol = 0.0;
  if (me_ > 0) {
    ev_.head(me_).noalias() = Es_.topLeftCorner(me_, n_) * v.head(n_);
    viol = (ev_.head(me_) - es_.head(me_)).cwiseAbs().maxCoeff();
  }
  if (mi_ > 0) {
    cx_.head(mi_).noalias() = Cs_.topLeftCorner(mi_, n_) * v.head(n_);
    for (int j = 0; j < mi_; ++j) {
      if (ls_(j) > -kInf) viol = std::max(viol, ls_(j) - cx_(j));
      if (us_(j) < kInf) viol = std::max(viol, cx_(j) - us_(j));
    }
  }
  return viol;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
QpStatus ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::iterate(bool phase1) {
  // Primal active-set loop; xc_ is feasible and satisfies K xc_ = rhs.
  int zero_steps = 0;  // consecutive degenerate steps → smallest-index rule
  // Blocking rows found dependent on K are ignored until K changes: row j is skipped while
  // skip_(j) == kver. All of them, not only the last one: at a degenerate vertex two such
  // rows otherwise take turns blocking a rounding-size step, forever (IterationLimit on
  // ~1 in 1500 random degenerate hierarchies, tests/hqp/test_hqp_inequality.cpp).
  int kver = 0;
  if (mi_ > 0) skip_.head(mi_).setConstant(-1);
  // A row dropped for a negative multiplier moves off its bound in exact arithmetic; if it
  // blocks the very next step at once (zero length), the multiplier's sign is rounding noise
  // (a nearly singular A Z turns it into a huge, meaningless step). The row is re-added and
  // kept ("pinned", its multiplier taken as 0) for the rest of the phase: otherwise the
  // drop / re-add pair repeats until the iteration cap (rank-deficient or badly scaled A).
  int just_dropped = -1;
  if (mi_ > 0) pin_.head(mi_).setZero();
  // Ĉ x; skipped when the caller's feasibility check just computed it at this xc_.
  if (mi_ > 0 && !cx_at_xc_) cx_.head(mi_).noalias() = Cs_.topLeftCorner(mi_, n_) * xc_.head(n_);
  cx_at_xc_ = false;
  // A cold start (K = equalities only) almost always changes K many times: set up the
  // two-sided structure now, so that no subproblem needs the generic decomposition. Not
  // on a warm start whose kept working set is empty: that one usually changes nothing.
  if (cold_ && nw_ == 0 && mi_ > 0 && !trap_ && !phase1) establishStructure();
  for (;;) {
    if (!xs_fresh_ && !subproblem()) return QpStatus::NumericalFailure;
    xs_fresh_ = false;
    double dn = 0.0, xn = 0.0;
    for (int i = 0; i < nv_; ++i) {
      d_(i) = xs_(i) - xc_(i);
      dn = std::max(dn, std::abs(d_(i)));
      xn = std::max(xn, std::abs(xc_(i)));
    }
    // A step at rounding level is no step: its direction is noise, not in null(K). With
    // null(K) = {0} (a vertex: K has nv_ independent rows) every step is one.
    if (dn <= 1e-14 * (1.0 + xn) || k_ == nv_) dn = 0.0;
    // Ratio test over the rows not in K (smallest index wins ties).
    double alpha = 1.0;
    int block = -1;
    bool block_upper = false;
    const double dir_tol = 10.0 * settings_.rank_tol * dn;
    if (dn > 0.0 && mi_ > 0) {
      cd_.head(mi_).noalias() = Cs_.topLeftCorner(mi_, n_) * d_.head(n_);
      // Phase 1 rows: Ĉx − t ≤ û and Ĉx + t ≥ l̂.
      const double dt = nv_ > n_ ? d_(n_) : 0.0, xt = nv_ > n_ ? xc_(n_) : 0.0;
      // A direction component ≤ dir_tol is rounding relative to ‖d‖ and ignored (at a
      // degenerate vertex it would block zero-length steps forever), unless the step would
      // carry the row past its bound by more than the tolerance: on a nearly singular A Z
      // the step can be 1e15 long, and then such a component breaks the row by 1e3.
      const double past = settings_.feasibility_tol;
      // Row j's side approached at rate ad > 0 with the given slack to its bound.
      const auto ratio = [&](int j, double ad, double slack, bool upper) {
        if (!(ad > dir_tol) && !(alpha * ad > slack + past)) return;  // rounding
        if (slack < 0.0) slack = 0.0;
        if (slack < alpha * ad) {
          alpha = slack / ad;
          block = j;
          block_upper = upper;
        }
      };
      for (int j = 0; j < mi_; ++j) {
        if (in_ws_(j) || skip_(j) == kver) continue;
        const double adu = cd_(j) - dt;  // upper side: rises toward û
        if (adu > 0.0 && us_(j) < kInf) ratio(j, adu, us_(j) - (cx_(j) - xt), true);
        const double adl = -(cd_(j) + dt);
        if (adl > 0.0 && ls_(j) > -kInf) ratio(j, adl, (cx_(j) + xt) - ls_(j), false);
      }
    }
    if (dn > 0.0) {
      xc_.head(nv_) += alpha * d_.head(nv_);
      if (mi_ > 0) cx_.head(mi_) += alpha * cd_.head(mi_);
    }
    // Phase 1 is done as soon as the point is feasible (t ≤ 0 up to rounding).
    if (phase1 && xc_(n_) <= 1e-3 * settings_.feasibility_tol) return QpStatus::Optimal;
    if (block >= 0) {
      if (iterations_ >= settings_.max_iterations) return QpStatus::IterationLimit;
      ++iterations_;
      zero_steps = alpha * dn == 0.0 ? zero_steps + 1 : 0;
      ensureExplicit();
      // A row numerically dependent on K cannot be held; skip it until K changes.
      if (!trap_ && ++changes_ >= kEstablishAfter) establishStructure();
      if (!phase1 && block == just_dropped && alpha * dn <= 1e-14 * (1.0 + xn)) pin_(block) = 1;
      just_dropped = -1;
      if (addRow(block, block_upper, phase1 ? 0.0 : harmlessCut(block, block_upper, alpha)))
        ++kver;
      else skip_(block) = kver;
      continue;
    }
    for (int i = 0; i < nv_; ++i) xc_(i) = xs_(i);  // exactly at the subproblem optimum
    if (!multipliers()) return QpStatus::NumericalFailure;
    // Most negative multiplier (μ = λ at upper, −λ at lower); smallest index after
    // repeated degenerate steps (Bland-like anti-cycling). Rows with lower == upper
    // are equalities: never dropped.
    // Sign threshold relative to the gradient's part in range(Kᵀ), y = −Q₁ᵀ g (multipliers()),
    // not to max |λ|: on a nearly dependent K the multipliers grow like 1/σ_min(K) (1e17
    // observed) and a max-|λ| scale let a wrong-signed λ of −505 pass as rounding.
    double gs = 1.0;
    for (int i = 0; i < k_; ++i) gs = std::max(gs, std::abs(y_(i)));
    const double thr = -settings_.dual_tol * gs;
    int drop = -1;
    double worst = thr;
    const bool bland = zero_steps > 2;
    for (int w = 0; w < nw_; ++w) {
      const int j = ws_row_(w);
      if (ls_(j) == us_(j) || pin_(j)) continue;
      const double mu = ws_upper_(w) ? lam_(neq_ + w) : -lam_(neq_ + w);
      if (bland) {
        if (mu < thr && (drop < 0 || j < ws_row_(drop))) drop = w;
      } else if (mu < worst) {
        worst = mu;
        drop = w;
      }
    }
    if (drop < 0) {
      // The signs are only as good as R: λ = R⁻¹ y carries an error of about ε κ ‖λ‖ (κ ≥ the
      // ratio of R's extreme diagonal entries). If that exceeds the test's tolerance and a
      // multiplier taken as ≥ 0 lies within it, the sign test proves nothing: check the cone.
      if (phase1 || neq_ == k_) return QpStatus::Optimal;
      double lmax = 0.0, rmax = 0.0, rmin = std::numeric_limits<double>::infinity(),
             mmin = std::numeric_limits<double>::infinity();
      for (int i = 0; i < k_; ++i) {
        lmax = std::max(lmax, std::abs(lam_(i)));
        rmax = std::max(rmax, std::abs(R_(i, i)));
        rmin = std::min(rmin, std::abs(R_(i, i)));
      }
      for (int w = 0; w < nw_; ++w) {
        const int j = ws_row_(w);
        if (ls_(j) != us_(j) && !pin_(j))
          mmin = std::min(mmin, ws_upper_(w) ? lam_(neq_ + w) : -lam_(neq_ + w));
      }
      const double noise = std::numeric_limits<double>::epsilon() * (rmax / rmin) * lmax;
      // Noise within the sign test's own tolerance, or every sign above it: the test holds.
      if (!(noise > -thr) || !(mmin <= noise)) return QpStatus::Optimal;
      return coneMultipliers(gs) ? QpStatus::Optimal : QpStatus::NumericalFailure;
    }
    if (iterations_ >= settings_.max_iterations) return QpStatus::IterationLimit;
    ++iterations_;
    ensureExplicit();
    if (!trap_ && ++changes_ >= kEstablishAfter) establishStructure();
    just_dropped = ws_row_(drop);
    removeRow(neq_ + drop);
    ++kver;
  }
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::phase1Certified() {
  // At phase 1's optimum Kᵀλ = −(0, t): the x part gives Σ λ_k k_k = 0 over the working set
  // (unit rows k_k, right-hand sides rhs_k, inequality rows with μ ≥ 0). Every row written
  // n x ≥ β with y ≥ 0 turns this into Σ y n = ρ ≈ 0 and gap = Σ y β = −Σ λ_k rhs_k: any x
  // meeting each row to its tolerance τ_k = feasibility_tol (1 + |rhs_k|) has
  // ρᵀx − gap ≥ −Σ |λ_k| τ_k, impossible for ‖x‖ ≤ X (far beyond the iterates) if
  // gap > Σ |λ_k| τ_k + ‖ρ‖ X, X = feasibility_tol / ε · (1 + max |rhs_k|): beyond X no row value
  // can be computed to the tolerance in double precision. ρ must be rounding (‖ρ‖ ≤ 1e-12 Σ |λ_k|): a larger one means the
  // rows are only nearly dependent, and a feasible point may lie far out (|x| ~ gap / ‖ρ‖).
  // Rows with a wrong-signed μ are left out (then in ρ).
  const double tol = settings_.feasibility_tol;
  d_.head(n_).setZero();  // ρ
  double gap = 0.0, slack = 0.0, ysum = 0.0, bmax = 0.0;
  for (int i = 0; i < k_; ++i) {
    const double l = lam_(i);
    if (i >= neq_) {
      const int w = i - neq_, j = ws_row_(w);
      const double mu = ws_upper_(w) ? l : -l;
      if (ls_(j) != us_(j) && mu < 0.0) continue;
      d_.head(n_) -= l * Cs_.row(j).head(n_).transpose();
    } else {
      d_.head(n_) -= l * Es_.row(eq_pos_(i)).head(n_).transpose();
    }
    gap -= l * rhs_(i);
    slack += std::abs(l) * tol * (1.0 + std::abs(rhs_(i)));
    ysum += std::abs(l);
    bmax = std::max(bmax, std::abs(rhs_(i)));
  }
  const double rho = d_.head(n_).norm();
  const double X = tol / std::numeric_limits<double>::epsilon() * (1.0 + bmax);
  return rho <= 1e-12 * ysum && gap > slack + rho * X;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::coneMultipliers(double gs) {
  // Stationarity g + Σ μ_l s_l k_l = 0 over K's rows k_l (unit norm) with signs s_l (+ at an
  // upper bound, − at a lower one, both for equalities and rows with lower == upper), μ ≥ 0:
  // min ‖E μ + g‖ s.t. μ ≥ 0 (Lawson and Hanson's NNLS, detail/nonnegative_least_squares.hpp).
  // Its residual ρ = −(g + E μ*) is unique however dependent the rows are, and a feasible
  // descent direction (the passive columns are orthogonal to ρ, every other column has
  // (s_l k_l)·ρ ≤ 0, and gᵀρ = −‖ρ‖²): ‖ρ‖ at rounding proves x optimal, a larger one that it
  // is not, whatever the sign test on the ill-conditioned multipliers said.
  const int n = n_;
  auto& E = cone_.E();
  auto& f = cone_.f();
  if (m_ > 0) {
    r_.head(m_).noalias() = A_ * xs_.head(n);
    r_.head(m_) -= b_;
    f.head(n).noalias() = -A_.transpose() * r_.head(m_);
  } else {
    f.head(n).setZero();
  }
  int cols = 0;
  const auto column = [&](int i, double sign) {
    const bool eq = i < neq_;
    const int j = eq ? eq_pos_(i) : ws_row_(i - neq_);
    for (int c = 0; c < n; ++c) E(c, cols) = sign * (eq ? Es_(j, c) : Cs_(j, c));
    cone_row_(cols) = i;
    cone_sign_(cols) = sign;
    ++cols;
  };
  for (int i = 0; i < k_; ++i) {
    const int w = i - neq_;
    if (w < 0 || ls_(ws_row_(w)) == us_(ws_row_(w))) {  // equality: both signs
      column(i, 1.0);
      column(i, -1.0);
    } else {
      column(i, ws_upper_(w) ? 1.0 : -1.0);
    }
  }
  const int cap = decltype(cone_)::iterationCap(settings_.max_iterations, cols);
  if (!cone_.solve(n, cols, cap)) return false;
  // Tolerance: the sign test's, plus the rounding of E μ (unit columns).
  const double gn = f.head(n).norm();
  const double tol = settings_.dual_tol * std::max(gs, gn) +
                     64.0 * std::numeric_limits<double>::epsilon() * cone_.mu().head(cols).sum();
  if (cone_.residual().head(n).norm() <= tol) {
    lam_.head(k_).setZero();
    for (int l = 0; l < cols; ++l) lam_(cone_row_(l)) += cone_sign_(l) * cone_.mu()(l);
    return true;
  }
  return false;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
bool ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::equalitiesCertified() {
  // After addEqualities() found a dependent row inconsistent: row i = Kᵀβ + ρ with β = R⁻¹ (Qᵀ ê_i)(0:k)
  // (Kᵀ = Q₁ R). E x = e then forces ê_i x = βᵀ rhs + ρᵀx; it contradicts e_i (the same bound as
  // phase1Certified) only if |e_i − βᵀ rhs| > tol (1 + |e_i| + Σ |β_k| (1 + |rhs_k|)) + ‖ρ‖ X.
  // Rows only 1e-10 apart (huge β) are not certified: NumericalFailure instead of Infeasible.
  const double tol = settings_.feasibility_tol;
  for (int i = 0; i < me_; ++i) {
    if (eq_indep_(i)) continue;
    for (int c = 0; c < n_; ++c) a_(c) = Es_(i, c);
    if (nv_ > n_) a_(n_) = 0.0;
    if (qexplicit_) {
      w_.head(nv_).noalias() = Q_.topLeftCorner(nv_, nv_).transpose() * a_.head(nv_);
    } else {
      w_.head(nv_) = a_.head(nv_);
      for (int j = 0; j < k_; ++j) applyReflector(j, w_);
    }
    const double rho = w_.segment(k_, nv_ - k_).norm();
    for (int j = k_ - 1; j >= 0; --j) {  // β = R⁻¹ w(0:k), in place
      w_(j) /= R_(j, j);
      w_.head(j) -= w_(j) * R_.col(j).head(j);
    }
    double gap = es_(i), slack = tol * (1.0 + std::abs(es_(i))), bmax = std::abs(es_(i));
    for (int j = 0; j < k_; ++j) {
      gap -= w_(j) * rhs_(j);
      slack += std::abs(w_(j)) * tol * (1.0 + std::abs(rhs_(j)));
      bmax = std::max(bmax, std::abs(rhs_(j)));
    }
    const double X = tol / std::numeric_limits<double>::epsilon() * (1.0 + bmax);
    if (std::isfinite(gap) && std::abs(gap) > slack + rho * X) return true;
  }
  return false;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
void ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::finish(QpStatus s) {
  status_ = s;
  objective_ = 0.0;
  for (int i = 0; i < m_; ++i) {
    double r = -b_(i);
    for (int c = 0; c < n_; ++c) r += A_(i, c) * x_(c);
    objective_ += 0.5 * r * r;
  }
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
QpStatus ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::solveImpl(const VectorX* x_init,
                                                               bool warm_start) noexcept {
  const bool warm = warm_start && have_ws_;
  const bool hinted = start_count_ > 0;  // setStartRows(); solveOnce() clears it
  solveOnce(x_init, warm_start);
  // A warm start or start rows that run into the iteration cap (a previous working set that
  // leads the method astray, e.g. through a long degenerate stretch), or that end on a vertex
  // failing the final check (a degenerate vertex held by other rows than the plain path
  // picks, where an inactive row is violated by rounding), fall back to one cold solve with
  // its own budget: the worst case is 2 · max_iterations.
  if ((warm || hinted) &&
      (status_ == QpStatus::IterationLimit || status_ == QpStatus::NumericalFailure)) {
    const int spent = iterations_;
    solveOnce(x_init, false);
    iterations_ += spent;
  }
  return status_;
}

template <int MaxN, int MaxRows, int MaxEq, int MaxIneq>
QpStatus ActiveSetQp<MaxN, MaxRows, MaxEq, MaxIneq>::solveOnce(const VectorX* x_init,
                                                               bool warm_start) noexcept {
  iterations_ = 0;
  xs_fresh_ = false;
  cx_at_xc_ = false;
  // setStartRows() is for this solve only, also if it stops before using them.
  const int start_count = start_count_;
  start_count_ = 0;
  for (int i = 0; i < me_; ++i) lam_eq_(i) = 0.0;
  const bool warm = warm_start && have_ws_;
  cold_ = !warm;
  const int nw_prev = nw_;
  if (!inputValid()) {
    x_.setZero(n_);
    nw_ = 0;
    have_ws_ = false;
    finish(QpStatus::InvalidInput);
    return status_;
  }
  if (!prepare()) {
    x_.setZero(n_);
    nw_ = 0;
    finish(QpStatus::NumericalFailure);
    return status_;
  }
  for (int j = 0; j < mi_; ++j) {
    if (ls_(j) > us_(j) + settings_.feasibility_tol) {  // empty interval
      x_.setZero(n_);
      nw_ = 0;
      finish(QpStatus::Infeasible);
      return status_;
    }
  }
  // Phase 2 factorization with the equalities.
  startPhase(false);
  nw_ = 0;
  if (!addEqualities()) {
    x_.setZero(n_);
    finish(equalitiesCertified() ? QpStatus::Infeasible : QpStatus::NumericalFailure);
    return status_;
  }
  bool started = false;
  if (warm && nw_prev > 0) {
    // Re-add the previous working set (dropping dependent rows and infinite sides);
    // keep it only if its subproblem optimum is feasible.
    // Copy the previous set first: addRow writes into ws_row_.
    ws_prev_row_ = ws_row_;
    ws_prev_upper_ = ws_upper_;
    nw_ = 0;
    addWarmRows(nw_prev);
    if (subproblem() && maxViolation(xs_) <= settings_.feasibility_tol) {
      for (int i = 0; i < n_; ++i) xc_(i) = xs_(i);
      cx_at_xc_ = true;
      started = true;
      xs_fresh_ = true;  // iterate() starts from this subproblem solution
    } else {
      startPhase(false);
      nw_ = 0;
      addEqualities();
    }
  }
  if (!started && x_init != nullptr && x_init->size() == n_) {
    for (int i = 0; i < n_; ++i) xc_(i) = (*x_init)(i);
    started = xc_.head(n_).allFinite() && maxViolation(xc_) <= settings_.feasibility_tol;
    cx_at_xc_ = started;
    if (started && start_count > 0) {
      // setStartRows(): the rows that hold at x_init (maxViolation left cx_ = Ĉ x_init).
      int cnt = 0;
      for (int k = 0; k < start_count; ++k) {
        const int j = start_row_(k);
        const bool up = start_upper_(k) != 0;
        if (j < 0 || j >= mi_) continue;
        const double bound = up ? us_(j) : ls_(j);
        if (!(std::abs(cx_(j) - bound) <= settings_.feasibility_tol * (1.0 + std::abs(cx_(j)))))
          continue;
        ws_prev_row_(cnt) = j;
        ws_prev_upper_(cnt) = up ? 1 : 0;
        ++cnt;
      }
      if (cnt > 0) addWarmRows(cnt);
    }
  }
  if (!started) {
    // Minimum-norm point of E x = e (the subproblem with A = 0 would do the same).
    minNormPoint(xc_);
    const double t0 = maxViolation(xc_);
    cx_at_xc_ = true;  // phase 1 (x part) or phase 2 starts from this xc_
    if (t0 > settings_.feasibility_tol) {
      // Phase 1: min ½t² s.t. Ĉx − t ≤ û, Ĉx + t ≥ l̂, E x = e, from (x_E, t0).
      startPhase(true);
      nw_ = 0;
      addEqualities();
      xc_(n_) = t0;
      const QpStatus s1 = iterate(true);
      if (s1 != QpStatus::Optimal) {
        x_.setZero(n_);
        nw_ = 0;
        finish(s1);
        return status_;
      }
      if (xc_(n_) > settings_.feasibility_tol) {
        // Infeasible only with a checked certificate; a phase 1 stuck on (nearly) parallel
        // rows whose multipliers are rounding noise is a numerical failure instead.
        x_.setZero(n_);
        nw_ = 0;
        finish(phase1Certified() ? QpStatus::Infeasible : QpStatus::NumericalFailure);
        return status_;
      }
      startPhase(false);
      nw_ = 0;
      addEqualities();
    }
  }
  QpStatus s2 = iterate(false);
  // No Optimal without a feasible x: every row re-checked at the returned point.
  if (s2 == QpStatus::Optimal && !feasibleAt(xc_)) s2 = QpStatus::NumericalFailure;
  if (s2 == QpStatus::NumericalFailure && !xc_.head(n_).allFinite()) {
    x_.setZero(n_);
  } else {
    x_ = xc_.head(n_);
  }
  // Report multipliers in the caller's scaling.
  if (s2 == QpStatus::Optimal) {
    for (int i = 0; i < neq_; ++i) lam_eq_(eq_pos_(i)) = lam_(i) * einv_(eq_pos_(i));
    for (int w = 0; w < nw_; ++w) {
      const int j = ws_row_(w);
      double mu = (ws_upper_(w) ? lam_(neq_ + w) : -lam_(neq_ + w)) * cinv_(j);
      if (pin_(j) && ls_(j) != us_(j) && mu < 0.0) mu = 0.0;  // pinned: sign is noise
      if (ls_(j) == us_(j) && mu < 0.0) {  // equality row: report the side by sign
        ws_upper_(w) = ws_upper_(w) ? 0 : 1;
        mu = -mu;
      }
      ws_mu_(w) = mu;
    }
  } else {
    for (int w = 0; w < nw_; ++w) ws_mu_(w) = 0.0;
  }
  have_ws_ = true;
  finish(s2);
  return status_;
}

}  // namespace hqp
