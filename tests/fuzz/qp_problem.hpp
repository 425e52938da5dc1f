#pragma once
// A least-squares QP decoded from fuzzer bytes, and independent checks of a solver's answer
// (feasibility, KKT conditions with the reported multipliers), for fuzz_active_set_qp and
// fuzz_dual_qp:  min ½‖A x − b‖²  s.t.  E x = e,  lower ≤ C x ≤ upper.

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <vector>

#include "fuzz_common.hpp"

namespace hqp::fuzz {

struct QpProblem {
  Eigen::MatrixXd A, E, C;
  Eigen::VectorXd b, e, lower, upper;
  bool finite_data = true;      // A, b, E, e, C finite and no NaN bound
  bool inverted_bounds = false;  // some lower > upper beyond the tolerance (empty row)
  bool impossible_inf = false;   // some lower = +inf or upper = −inf (a row no x can meet)
  bool by_construction = false;  // bounds and e built around a point x0: feasible
  Eigen::VectorXd x0;
  bool validInput() const { return finite_data && !inverted_bounds && !impossible_inf; }
  // Printed before a finding is reported (stderr), so that a crash file explains itself.
  void print() const {
    std::fprintf(stderr, "n %d m %d me %d mi %d finite %d inverted %d impossible_inf %d by_construction %d\n",
                 static_cast<int>(A.cols()), static_cast<int>(A.rows()), static_cast<int>(E.rows()),
                 static_cast<int>(C.rows()), finite_data, inverted_bounds, impossible_inf, by_construction);
    Eigen::IOFormat f(Eigen::FullPrecision, 0, " ", "\n", "  [", "]");
    std::fprintf(stderr, "A, b, E, e, C, lower, upper:\n");
    for (const Eigen::MatrixXd* M : {&A, &E, &C}) {
      std::cerr << M->format(f) << "\n--\n";
    }
    std::cerr << b.transpose().format(f) << "\n" << e.transpose().format(f) << "\n"
              << lower.transpose().format(f) << "\n" << upper.transpose().format(f) << "\n";
  }
};

// Sizes at most n_max, m_max, me_max, mi_max; strict: A gets at least n rows (dual method).
inline QpProblem decodeQp(FuzzedDataProvider& in, int n_max, int m_max, int me_max, int mi_max,
                          bool tall_a = false) {
  QpProblem p;
  const int n = in.ConsumeIntegralInRange<int>(1, n_max);
  const int m = tall_a ? in.ConsumeIntegralInRange<int>(n, m_max) : in.ConsumeIntegralInRange<int>(0, m_max);
  const int me = in.ConsumeIntegralInRange<int>(0, me_max);
  const int mi = in.ConsumeIntegralInRange<int>(0, mi_max);
  const unsigned flags = in.ConsumeIntegral<unsigned char>();
  const bool special = (flags & 1) != 0;        // ±inf / NaN may appear in the data
  p.by_construction = (flags & 2) != 0;
  const bool copies = (flags & 4) != 0;         // repeat rows: degenerate active sets
  auto fill = [&](Eigen::MatrixXd& M, int rows) {
    M.resize(rows, n);
    for (int i = 0; i < rows; ++i) {
      if (copies && i > 0 && in.ConsumeBool()) {
        const int k = in.ConsumeIntegralInRange<int>(0, i - 1);
        M.row(i) = (in.ConsumeIntegralInRange<int>(-4, 4) / 2.0) * M.row(k);  // exact multiple
        continue;
      }
      for (int j = 0; j < n; ++j) M(i, j) = number(in, special && (flags & 8));
    }
  };
  fill(p.A, m);
  fill(p.E, me);
  fill(p.C, mi);
  p.b.resize(m);
  for (int i = 0; i < m; ++i) p.b(i) = number(in, special && (flags & 16));
  p.x0.resize(n);
  for (int j = 0; j < n; ++j) p.x0(j) = number(in);
  p.e.resize(me);
  for (int i = 0; i < me; ++i) p.e(i) = p.by_construction ? p.E.row(i).dot(p.x0) : number(in);
  p.lower.resize(mi);
  p.upper.resize(mi);
  for (int i = 0; i < mi; ++i) {
    const int kind = in.ConsumeIntegralInRange<int>(0, 7);
    const double c = p.by_construction ? p.C.row(i).dot(p.x0) : number(in);
    const double w1 = std::abs(number(in)), w2 = std::abs(number(in));
    switch (kind) {
      case 0: p.lower(i) = c - w1, p.upper(i) = c + w2; break;  // two-sided
      case 1: p.lower(i) = c - w1, p.upper(i) = kInf; break;
      case 2: p.lower(i) = -kInf, p.upper(i) = c + w2; break;
      case 3: p.lower(i) = p.upper(i) = c; break;               // equality row
      case 4: p.lower(i) = -kInf, p.upper(i) = kInf; break;     // free row
      case 5: p.lower(i) = c, p.upper(i) = c + w2; break;       // at a bound
      case 6:                                                    // anything, maybe inverted
        p.lower(i) = number(in, special, false);
        p.upper(i) = number(in, special, false);
        p.by_construction = p.by_construction && !(p.lower(i) > c || p.upper(i) < c);
        break;
      default:                                                   // infinite either way
        p.lower(i) = in.ConsumeBool() ? kInf : -kInf;
        p.upper(i) = in.ConsumeBool() ? kInf : -kInf;
        p.by_construction = p.by_construction && !(p.lower(i) > c || p.upper(i) < c);
        break;
    }
  }
  p.finite_data = p.A.allFinite() && p.b.allFinite() && p.E.allFinite() && p.e.allFinite() &&
                  p.C.allFinite() && !p.lower.hasNaN() && !p.upper.hasNaN();
  for (int i = 0; i < mi; ++i) {
    // The solvers' rule (docs/hqp.md, "Contracts"): empty only if the bounds cross by more
    // than feasibility_tol on the unit-norm row (zero rows unscaled); a smaller crossing is a
    // row held within the tolerance.
    const double nrm = p.C.row(i).norm();
    p.inverted_bounds = p.inverted_bounds || (p.lower(i) - p.upper(i)) / (nrm > 0.0 ? nrm : 1.0) > 1e-9;
    p.impossible_inf = p.impossible_inf || p.lower(i) == kInf || p.upper(i) == -kInf;
  }
  p.by_construction = p.by_construction && p.finite_data && !p.inverted_bounds && !p.impossible_inf &&
                      p.x0.allFinite();
  return p;
}

// Tolerance of row c·x against a bound: the solvers' feasibility_tol (1e-9 per unit row, zero
// rows unscaled) plus rounding relative to the size of the terms.
inline double rowTol(const Eigen::VectorXd& c, const Eigen::VectorXd& x, double bound) {
  return 1e-9 * std::max(c.norm(), 1.0) + 1e-7 * (c.cwiseAbs().dot(x.cwiseAbs()) + c.norm() + (std::isfinite(bound) ? std::abs(bound) : 0.0));
}

// x meets E x = e and lower ≤ C x ≤ upper to tolerance.
inline void checkFeasible(const QpProblem& p, const Eigen::VectorXd& x) {
  HQP_FUZZ_CHECK(x.size() == p.A.cols() && x.allFinite());
  for (int i = 0; i < p.E.rows(); ++i) {
    const Eigen::VectorXd r = p.E.row(i).transpose();
    const double v = r.dot(x) - p.e(i);
    HQP_FUZZ_CHECK2(std::abs(v) <= rowTol(r, x, p.e(i)), v, static_cast<double>(i));
  }
  for (int i = 0; i < p.C.rows(); ++i) {
    const Eigen::VectorXd r = p.C.row(i).transpose();
    const double cx = r.dot(x);
    HQP_FUZZ_CHECK2(p.lower(i) - cx <= rowTol(r, x, p.lower(i)), p.lower(i) - cx, static_cast<double>(i));
    HQP_FUZZ_CHECK2(cx - p.upper(i) <= rowTol(r, x, p.upper(i)), cx - p.upper(i), static_cast<double>(i));
  }
}

// One active inequality row as a solver reports it.
struct ActiveRow {
  int row;
  bool upper;
  double mu;
};

// KKT conditions at x: Aᵀ(Ax − b) + Eᵀλ + Σ_upper μ c − Σ_lower μ c = 0, μ ≥ 0, every active row
// at its (finite) bound, no row twice.
inline void checkKkt(const QpProblem& p, const Eigen::VectorXd& x, const Eigen::VectorXd& lambda,
                     const std::vector<ActiveRow>& active) {
  const Eigen::VectorXd res = p.A * x - p.b;
  Eigen::VectorXd g = p.A.transpose() * res;
  // Size of the terms whose rounding the residual carries: |A|ᵀ(|A||x| + |b|) and the others.
  Eigen::VectorXd scale = p.A.cwiseAbs().transpose() * (p.A.cwiseAbs() * x.cwiseAbs() + p.b.cwiseAbs());
  if (lambda.size() > 0) {
    HQP_FUZZ_CHECK(lambda.size() == p.E.rows() && lambda.allFinite());
    g += p.E.transpose() * lambda;
    scale += p.E.cwiseAbs().transpose() * lambda.cwiseAbs();
  }
  double mu_scale = 1.0 + scale.maxCoeff();
  std::vector<int> seen(static_cast<size_t>(p.C.rows()), 0);
  for (const ActiveRow& a : active) {
    HQP_FUZZ_CHECK(a.row >= 0 && a.row < p.C.rows());
    HQP_FUZZ_CHECK(seen[static_cast<size_t>(a.row)] == 0);
    seen[static_cast<size_t>(a.row)] = 1;
    HQP_FUZZ_CHECK(std::isfinite(a.mu));
    const Eigen::VectorXd r = p.C.row(a.row).transpose();
    g += (a.upper ? a.mu : -a.mu) * r;
    scale += std::abs(a.mu) * r.cwiseAbs();
    mu_scale = std::max(mu_scale, std::abs(a.mu) * r.norm());
    const double bound = a.upper ? p.upper(a.row) : p.lower(a.row);
    HQP_FUZZ_CHECK2(std::isfinite(bound), bound, static_cast<double>(a.row));
    const double gap = r.dot(x) - bound;
    HQP_FUZZ_CHECK2(std::abs(gap) <= rowTol(r, x, bound) || a.mu == 0.0, gap, a.mu);
  }
  for (const ActiveRow& a : active)
    HQP_FUZZ_CHECK2(a.mu * p.C.row(a.row).norm() >= -1e-7 * mu_scale, a.mu, mu_scale);
  // Normwise part: the rounding of b through the factorization, ‖A‖ (‖A‖ ‖x‖ + ‖b‖) ε.
  const double normwise = p.A.norm() * (p.A.norm() * x.norm() + p.b.norm());
  for (int j = 0; j < g.size(); ++j)
    HQP_FUZZ_CHECK2(std::abs(g(j)) <= 1e-7 * (scale(j) + scale.maxCoeff() + normwise) + 1e-12, g(j), scale(j));
}

// A point so far out that no row value can be computed to the tolerance in double precision
// (docs/hqp.md, "Contracts": ‖x‖ > feasibility_tol / ε · (1 + max |bound| on unit rows)) is no
// witness of feasibility: the solvers may call such a problem Infeasible.
inline bool beyondVerifiable(const QpProblem& p, const Eigen::VectorXd& x) {
  double bmax = 0.0;
  for (int i = 0; i < p.C.rows(); ++i) {
    const double nrm = p.C.row(i).norm(), s = nrm > 0.0 ? nrm : 1.0;
    for (double b : {p.lower(i), p.upper(i)})
      if (std::isfinite(b)) bmax = std::max(bmax, std::abs(b) / s);
  }
  for (int i = 0; i < p.E.rows(); ++i) {
    const double nrm = p.E.row(i).norm();
    bmax = std::max(bmax, std::abs(p.e(i)) / (nrm > 0.0 ? nrm : 1.0));
  }
  return x.norm() > 1e-9 / std::numeric_limits<double>::epsilon() * (1.0 + bmax);
}

inline double objective(const QpProblem& p, const Eigen::VectorXd& x) {
  return 0.5 * (p.A * x - p.b).squaredNorm();
}

// Lower bound on the objective at any point y from a KKT point x with multipliers (λ, μ),
// by convexity: f(y) ≥ f(x) + ∇f(x)ᵀ(y − x), and with ∇f(x) = −Eᵀλ − Σ ±μ c + s (s the
// stationarity residual), ∇f(x)ᵀ(y − x) ≥ −Σ μ (viol_k(y) + |c_k x − b_k|) − |λ|ᵀ|E (y − x)|
// − ‖s‖ ‖y − x‖, viol_k(y) ≥ 0 how far y is outside row k's active bound b_k. Two answers that are each feasible
// to the tolerance can differ in objective by this much, no more: with (nearly) parallel rows
// the multipliers are huge and the tolerance-wide feasible set much larger than the exact one.
inline double lagrangianBound(const QpProblem& p, const Eigen::VectorXd& x, const Eigen::VectorXd& lambda,
                              const std::vector<ActiveRow>& active, const Eigen::VectorXd& y) {
  Eigen::VectorXd s = p.A.transpose() * (p.A * x - p.b);
  double bound = objective(p, x);
  if (lambda.size() > 0) {
    s += p.E.transpose() * lambda;
    bound -= lambda.cwiseAbs().dot((p.E * (y - x)).cwiseAbs());
  }
  for (const ActiveRow& a : active) {
    const Eigen::VectorXd r = p.C.row(a.row).transpose();
    s += (a.upper ? a.mu : -a.mu) * r;
    const double cy = r.dot(y);
    const double viol = a.upper ? cy - p.upper(a.row) : p.lower(a.row) - cy;
    bound -= a.mu >= 0.0 ? a.mu * std::max(viol, 0.0) : -a.mu * std::abs(viol);
    // viol itself carries the rounding of c y and c x (at a row value of 2715 ~5e-13, which
    // multipliers of 2e15 on two nearly parallel equality rows turn into ~1e3).
    const double b = a.upper ? p.upper(a.row) : p.lower(a.row);
    bound -= std::abs(a.mu) * 1e-14 * (r.cwiseAbs().dot(y.cwiseAbs()) + r.cwiseAbs().dot(x.cwiseAbs()) + std::abs(b));
    // x's own row off its bound (within the tolerance) shifts the bound by μ |c x − b|.
    bound -= std::abs(a.mu) * std::abs(r.dot(x) - b);
  }
  return bound - s.norm() * (y - x).norm();
}

}  // namespace hqp::fuzz
