#pragma once
// Reference solver for SMALL least-squares QPs, by enumeration of active sets.
//   min ½‖A x − b‖²  s.t.  E x = e,  lower ≤ C x ≤ upper
// For every set W of inequality rows, each held at its lower or its upper bound
// (|W| ≤ n suffices: a face of the optimal set is cut out by ≤ n independent rows),
// it solves the equality-constrained least squares with [E; C_W] as equalities
// (minimum-norm minimizer, via SVD) and keeps the primal-feasible candidates.
// The lowest objective among them is the QP optimum: the optimal set is a
// polyhedron, and on its minimal face F (an affine set cut out by E and the rows
// active on F) every minimizer of the equality-constrained problem lies in F, so
// the minimum-norm one is feasible and is found here.
// Cost: up to 3^mi candidates; meant for n ≤ ~8 and mi ≤ ~10, in tests only.
// Shares no code with the solver under test (dynamic-size Eigen SVD only).

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace hqp::testing {

struct BruteForceResult {
  bool feasible = false;     // some candidate satisfied every constraint
  double objective = std::numeric_limits<double>::infinity();  // ½‖A x − b‖²
  Eigen::VectorXd x;         // a minimizer (the minimum-norm one of its face)
  int candidates = 0;        // equality-constrained problems solved
};

namespace detail {

// Minimum-norm minimizer of ½‖A x − b‖² over {K x = r}; false if K x = r is
// inconsistent (relative tolerance).
inline bool equalityLeastSquares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                                 const Eigen::MatrixXd& K, const Eigen::VectorXd& r,
                                 double tol, Eigen::VectorXd& x) {
  const Eigen::Index n = A.cols();
  Eigen::VectorXd xp = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd Z = Eigen::MatrixXd::Identity(n, n);
  if (K.rows() > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(K, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const double smax = svd.singularValues().size() > 0 ? svd.singularValues()(0) : 0.0;
    Eigen::Index rank = 0;
    for (Eigen::Index i = 0; i < svd.singularValues().size(); ++i)
      if (svd.singularValues()(i) > 1e-10 * std::max(1.0, smax)) ++rank;
    // xp = V_r S_r^-1 U_r^T r : the minimum-norm point of the affine set
    const Eigen::VectorXd ur = svd.matrixU().leftCols(rank).transpose() * r;
    xp = svd.matrixV().leftCols(rank) *
         (ur.array() / svd.singularValues().head(rank).array()).matrix();
    if ((K * xp - r).norm() > tol * (1.0 + r.norm())) return false;
    Z = svd.matrixV().rightCols(n - rank);
  }
  // Minimizers: xp + Z p, p = (A Z)^+ (b − A xp); xp ⊥ range(Z) so min-norm p
  // gives the min-norm x.
  if (Z.cols() > 0 && A.rows() > 0) {
    const Eigen::MatrixXd AZ = A * Z;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(AZ, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const double smax = svd.singularValues().size() > 0 ? svd.singularValues()(0) : 0.0;
    if (smax > 1e-10) {
      svd.setThreshold(1e-10 * std::max(1.0, smax) / smax);
      const Eigen::VectorXd p = svd.solve(b - A * xp);
      x = xp + Z * p;
    } else {
      x = xp;  // A Z = 0: every point of the affine set is optimal
    }
  } else {
    x = xp;
  }
  return true;
}

}  // namespace detail

// Enumerates active sets. `feas_tol` is the accepted violation of a row scaled to
// unit norm (zero rows: unscaled).
inline BruteForceResult bruteForceQp(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                                     const Eigen::MatrixXd& E, const Eigen::VectorXd& e,
                                     const Eigen::MatrixXd& C, const Eigen::VectorXd& lower,
                                     const Eigen::VectorXd& upper, double feas_tol = 1e-9) {
  const Eigen::Index n = A.cols();
  const Eigen::Index me = E.rows();
  const Eigen::Index mi = C.rows();
  BruteForceResult best;
  // state[j]: 0 inactive, 1 at lower, 2 at upper
  std::vector<int> state(static_cast<size_t>(mi), 0);
  const double inf = std::numeric_limits<double>::infinity();

  auto feasible = [&](const Eigen::VectorXd& x) {
    if (me > 0) {
      const Eigen::VectorXd re = E * x - e;
      for (Eigen::Index i = 0; i < me; ++i) {
        const double s = std::max(E.row(i).norm(), 1.0);
        if (std::abs(re(i)) > 1e-8 * s * (1.0 + std::abs(e(i)))) return false;
      }
    }
    const Eigen::VectorXd cx = C * x;
    const Eigen::VectorXd cax = C.cwiseAbs() * x.cwiseAbs();
    for (Eigen::Index j = 0; j < mi; ++j) {
      const double nrm = C.row(j).norm();
      const double s = nrm > 0.0 ? nrm : 1.0;
      // The solvers' rule, feas_tol (1 + |ĉ x|) on a unit row, plus the rounding of c x
      // itself: an optimum far out (|x| ~ 1e7 on a direction C does not see) is
      // otherwise rejected for rounding noise and the enumeration misses it.
      const double tol = feas_tol * (1.0 + std::abs(cx(j)) / s) + 1e-14 * cax(j) / s;
      if (lower(j) > -inf && (lower(j) - cx(j)) / s > tol) return false;
      if (upper(j) < inf && (cx(j) - upper(j)) / s > tol) return false;
    }
    return true;
  };

  auto evaluate = [&]() {
    int k = 0;
    for (int s : state) k += (s != 0);
    Eigen::MatrixXd K(me + k, n);
    Eigen::VectorXd r(me + k);
    if (me > 0) {
      K.topRows(me) = E;
      r.head(me) = e;
    }
    int row = static_cast<int>(me);
    for (Eigen::Index j = 0; j < mi; ++j) {
      if (state[static_cast<size_t>(j)] == 0) continue;
      K.row(row) = C.row(j);
      r(row) = state[static_cast<size_t>(j)] == 1 ? lower(j) : upper(j);
      ++row;
    }
    Eigen::VectorXd x;
    ++best.candidates;
    if (!detail::equalityLeastSquares(A, b, K, r, 1e-9, x)) return;
    if (!x.allFinite() || !feasible(x)) return;
    const double f = 0.5 * (A * x - b).squaredNorm();
    if (!best.feasible || f < best.objective) {
      best.feasible = true;
      best.objective = f;
      best.x = x;
    }
  };

  // Depth-first enumeration over rows; at most n rows held active.
  auto recurse = [&](auto&& self, Eigen::Index j, int active) -> void {
    if (j == mi) {
      evaluate();
      return;
    }
    state[static_cast<size_t>(j)] = 0;
    self(self, j + 1, active);
    if (active >= n) return;
    const bool zero_row = C.row(j).norm() == 0.0;
    if (zero_row) return;  // a zero row never cuts out a face
    if (lower(j) > -inf) {
      state[static_cast<size_t>(j)] = 1;
      self(self, j + 1, active + 1);
    }
    if (upper(j) < inf && upper(j) != lower(j)) {
      state[static_cast<size_t>(j)] = 2;
      self(self, j + 1, active + 1);
    }
    state[static_cast<size_t>(j)] = 0;
  };
  recurse(recurse, 0, 0);
  return best;
}

}  // namespace hqp::testing

namespace hqp::testing {

// A random least-squares QP (dynamic sizes) for property tests.
struct RandomQp {
  Eigen::MatrixXd A, E, C;
  Eigen::VectorXd b, e, lower, upper;
  Eigen::VectorXd x0;  // a point that satisfies the constraints (when built feasible)
};

// Copies a problem (any struct with A, b, E, e, C, lower, upper) into an ActiveSetQp-like solver.
template <class Qp, class Problem>
void loadInto(Qp& qp, const Problem& p) {
  qp.resize(static_cast<int>(p.A.cols()), static_cast<int>(p.A.rows()),
            static_cast<int>(p.E.rows()), static_cast<int>(p.C.rows()));
  qp.A() = p.A;
  qp.b() = p.b;
  qp.E() = p.E;
  qp.e() = p.e;
  qp.C() = p.C;
  qp.lower() = p.lower;
  qp.upper() = p.upper;
}

// rank_a < 0: full rank. two_sided: fraction of inequality rows bounded on both
// sides; the rest get one side. Bounds are placed around C x0 with random slack,
// some exactly at C x0 (many active at a point), so the problem is feasible unless
// `infeasible` shifts a bound pair across.
template <class Rng>
RandomQp makeRandomQp(Rng& rng, int n, int m, int me, int mi, int rank_a, double two_sided,
                      bool redundant_eq = false, bool infeasible = false) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  auto randm = [&](int r, int c) {
    Eigen::MatrixXd M(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) M(i, j) = U(rng);
    return M;
  };
  auto randv = [&](int r) {
    Eigen::VectorXd v(r);
    for (int i = 0; i < r; ++i) v(i) = U(rng);
    return v;
  };
  RandomQp q;
  if (rank_a >= 0 && m > 0)
    q.A = randm(m, rank_a) * randm(rank_a, n);
  else
    q.A = randm(m, n);
  q.b = randv(m) * 2.0;
  q.x0 = randv(n);
  q.E = randm(me, n);
  if (redundant_eq && me >= 2) q.E.row(me - 1) = 0.5 * q.E.row(0) - 2.0 * q.E.row(1);
  q.e = q.E * q.x0;
  q.C = randm(mi, n);
  const Eigen::VectorXd cx = q.C * q.x0;
  const double inf = std::numeric_limits<double>::infinity();
  q.lower.resize(mi);
  q.upper.resize(mi);
  for (int j = 0; j < mi; ++j) {
    const double s_lo = U01(rng) < 0.25 ? 0.0 : 0.5 * U01(rng);
    const double s_up = U01(rng) < 0.25 ? 0.0 : 0.5 * U01(rng);
    q.lower(j) = cx(j) - s_lo;
    q.upper(j) = cx(j) + s_up;
    if (U01(rng) >= two_sided) {
      if (U01(rng) < 0.5)
        q.lower(j) = -inf;
      else
        q.upper(j) = inf;
    }
  }
  if (infeasible && mi >= 1) {
    // Row 0 and a copy of it with a disjoint interval.
    if (mi >= 2) {
      q.C.row(1) = q.C.row(0);
      q.lower(0) = cx(0) - 0.1;
      q.upper(0) = cx(0) + 0.1;
      q.lower(1) = cx(0) + 0.3;
      q.upper(1) = inf;
    }
  }
  return q;
}

}  // namespace hqp::testing
