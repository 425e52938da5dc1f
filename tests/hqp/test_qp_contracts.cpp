// Input contracts and "no wrong Optimal" of ActiveSetQp and DualActiveSetQp (docs/hqp.md,
// "Contracts"): regressions built from answers that were silently wrong. Expectations come
// from closed forms, brute-force enumeration or KKT conditions computed here.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "hqp/active_set_qp.hpp"
#include "hqp/dual_active_set_qp.hpp"
#include "support/brute_force_qp.hpp"
#include "support/kkt_error.hpp"

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
std::string str(hqp::QpStatus s) { return hqp::toString(s); }

// Three solver shapes for the whole file (these two and Qp28 below), the problems sized at run
// time within them: each distinct shape is a whole instantiation of its solver, most of this
// unit's compile time (docs/development.md, "Build and CI cost").
using SmallQp = hqp::ActiveSetQp<4, 7, 3, 8>;
using SmallDual = hqp::DualActiveSetQp<8, 12, 10>;

// Largest violation of lower ≤ C x ≤ upper, rows scaled to unit norm; with rel > 0, each row's
// violation is counted only beyond rel · |ĉ x| (rounding of a large row value).
double violation(const Eigen::MatrixXd& C, const Eigen::VectorXd& lo, const Eigen::VectorXd& up,
                 const Eigen::VectorXd& x, double rel) {
  double v = 0.0;
  const Eigen::VectorXd cx = C * x;
  for (Eigen::Index j = 0; j < C.rows(); ++j) {
    const double s = std::max(C.row(j).norm(), 1e-300);
    const double e = std::max(lo(j) - cx(j), cx(j) - up(j)) / s - rel * std::abs(cx(j)) / s;
    v = std::max(v, e);
  }
  return v;
}

// Largest violation of lower ≤ C x ≤ upper, rows scaled to unit norm.
double violation(const Eigen::MatrixXd& C, const Eigen::VectorXd& lo, const Eigen::VectorXd& up,
                 const Eigen::VectorXd& x) {
  return violation(C, lo, up, x, 0.0);
}

// A problem with a feasible point (checked by the caller): ActiveSetQp must not call it
// Infeasible, and an Optimal answer meets every row (rounding of large row values aside).
// min ½‖A x − b‖² s.t. lo ≤ C x ≤ up (no equality rows) loaded into an ActiveSetQp.
void load(SmallQp& qp, const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::MatrixXd& C,
          const Eigen::VectorXd& lo, const Eigen::VectorXd& up) {
  qp.resize(static_cast<int>(A.cols()), static_cast<int>(A.rows()), 0, static_cast<int>(C.rows()));
  qp.A() = A;
  qp.b() = b;
  qp.C() = C;
  qp.lower() = lo;
  qp.upper() = up;
}

void expectNotInfeasible(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::MatrixXd& C,
                         const Eigen::VectorXd& lo, const Eigen::VectorXd& up) {
  SmallQp qp;
  load(qp, A, b, C, lo, up);
  const hqp::QpStatus s = qp.solve(false);
  EXPECT_NE(s, hqp::QpStatus::Infeasible);
  if (s == hqp::QpStatus::Optimal) {
    EXPECT_LE(violation(C, lo, up, qp.x(), 1e-9), 1e-9);
  }
}

// min ½‖x‖² s.t. 1 ≤ x₀ ≤ 0: no feasible point (was: Optimal with x₀ = 1).
TEST(QpContracts, DualCrossedBoundsAreInfeasible) {
  SmallDual qp;
  const Eigen::Matrix2d A = Eigen::Matrix2d::Identity();
  const Eigen::Vector2d b(0.0, 0.0);
  ASSERT_TRUE(qp.factorize(A, b, 2, 2, 0.0));
  Eigen::Matrix<double, 1, 2> C;
  C << 1.0, 0.0;
  Eigen::Matrix<double, 1, 1> lo, up;
  lo << 1.0;
  up << 0.0;
  EXPECT_EQ(str(qp.solve(C, lo, up, 1, hqp::QpSettings{})), "Infeasible");
  // The same row with its sides the right way round: x₀ = 1 is the closed-form optimum.
  up << 2.0;
  ASSERT_EQ(str(qp.solve(C, lo, up, 1, hqp::QpSettings{})), "Optimal");
  EXPECT_NEAR(qp.x()(0), 1.0, 1e-14);
  EXPECT_NEAR(qp.x()(1), 0.0, 1e-14);
}

// NaN in C or in a bound: refused (was: Optimal).
TEST(QpContracts, DualRefusesNaNAndWrongSideInfinities) {
  SmallDual qp;
  const Eigen::Matrix2d A = Eigen::Matrix2d::Identity();
  const Eigen::Vector2d b(3.0, -1.0);
  ASSERT_TRUE(qp.factorize(A, b, 2, 2, 0.0));
  Eigen::Matrix<double, 2, 2> C = Eigen::Matrix2d::Identity();
  Eigen::Vector2d lo(-kInf, -kInf), up(1.0, 1.0);
  ASSERT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "Optimal");
  EXPECT_NEAR(qp.x()(0), 1.0, 1e-14);  // min ½‖x − b‖², x ≤ 1: clamp of b
  EXPECT_NEAR(qp.x()(1), -1.0, 1e-14);
  C(1, 0) = kNaN;
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
  EXPECT_TRUE(qp.x().allFinite());
  C = Eigen::Matrix2d::Identity();
  up(1) = kNaN;
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
  lo(1) = kNaN;
  up(1) = 1.0;
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
  // [+inf, +inf] and [−inf, −inf]: a side infinite the wrong way.
  lo << kInf, -kInf;
  up << kInf, 1.0;
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
  lo << -kInf, -kInf;
  up << -kInf, 1.0;
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
  // Infinite matrix entry, and one beyond max_magnitude.
  lo << -kInf, -kInf;
  up << 1.0, 1.0;
  C(0, 1) = kInf;
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
  C(0, 1) = 1e200;
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
  // factorize() refuses NaN in A or b, and solve() after a refused factorize is refused too.
  Eigen::Vector2d bn(kNaN, 0.0);
  EXPECT_FALSE(qp.factorize(A, bn, 2, 2, 0.0));
  C = Eigen::Matrix2d::Identity();
  EXPECT_EQ(str(qp.solve(C, lo, up, 2, hqp::QpSettings{})), "InvalidInput");
}

// A row [+inf, +inf] was ignored (Optimal); [−inf, −inf] gave NumericalFailure.
TEST(QpContracts, ActiveSetRefusesWrongSideInfinities) {
  SmallQp qp;
  qp.resize(3, 3, 0, 2);
  qp.A().setIdentity();
  qp.b() << 1.0, 2.0, 3.0;
  qp.C() << 1, 0, 0,  0, 1, 0;
  qp.lower() << kInf, -kInf;
  qp.upper() << kInf, kInf;
  EXPECT_EQ(str(qp.solve(false)), "InvalidInput");
  EXPECT_TRUE(qp.x().allFinite());
  EXPECT_EQ(qp.x().norm(), 0.0);
  qp.lower() << -kInf, -kInf;
  qp.upper() << -kInf, kInf;
  EXPECT_EQ(str(qp.solve(false)), "InvalidInput");
  EXPECT_TRUE(qp.x().allFinite());
  // Valid again: x = b with x₀ ≤ 0.5 (closed form: clamp).
  qp.upper() << 0.5, kInf;
  ASSERT_EQ(str(qp.solve(false)), "Optimal");
  EXPECT_NEAR(qp.x()(0), 0.5, 1e-14);
  EXPECT_NEAR(qp.x()(1), 2.0, 1e-14);
  // Magnitudes beyond the documented range, and inf in a matrix.
  qp.b()(2) = 1e60;
  EXPECT_EQ(str(qp.solve(false)), "InvalidInput");
  qp.b()(2) = 3.0;
  qp.C()(1, 2) = -kInf;
  EXPECT_EQ(str(qp.solve(false)), "InvalidInput");
  qp.C()(1, 2) = 0.0;
  qp.lower()(1) = -1e51;  // a finite bound counts as well
  EXPECT_EQ(str(qp.solve(false)), "InvalidInput");
  qp.settings().max_magnitude = 1e52;  // the range is the caller's to set
  EXPECT_EQ(str(qp.solve(false)), "Optimal");
}

// Nearly dependent columns of A (cond ≳ 1e7) and min_sigma = 0: the dual method reported
// Optimal for points violating a row, or Infeasible for feasible problems. Now every Optimal
// is feasible with the enumeration's objective, and no feasible problem is called Infeasible.
TEST(QpContracts, DualNearlySingularNeverWrong) {
  int optimal = 0, refused = 0, other = 0;
  for (int seed = 0; seed < 400; ++seed) {
    std::mt19937 g(static_cast<unsigned>(seed));
    std::normal_distribution<double> N(0.0, 1.0);
    std::uniform_real_distribution<double> U01(0.0, 1.0);
    const int r = 12, n = 8, m = 10;
    const double delta = seed % 2 == 0 ? 1e-8 : 1e-9;  // column n−1 ≈ column n−2
    Eigen::MatrixXd A(r, n), C(m, n);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < n; ++j) A(i, j) = N(g);
    for (int i = 0; i < r; ++i) A(i, n - 1) = A(i, n - 2) + delta * N(g);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < n; ++j) C(i, j) = N(g);
    Eigen::VectorXd b(r), x0(n);
    for (int i = 0; i < r; ++i) b(i) = 3.0 * N(g);
    for (int j = 0; j < n; ++j) x0(j) = N(g);
    const Eigen::VectorXd cx = C * x0;  // x0 is feasible
    Eigen::VectorXd lo(m), up(m);
    for (int j = 0; j < m; ++j) {
      lo(j) = cx(j) - 0.3 * U01(g);
      up(j) = cx(j) + 0.3 * U01(g);
      if (U01(g) < 0.5) lo(j) = -kInf;
      else up(j) = kInf;
    }
    SmallDual qp;
    if (!qp.factorize(A, b, r, n, 0.0)) {
      ++refused;
      continue;
    }
    const hqp::QpStatus s = qp.solve(C, lo, up, m, hqp::QpSettings{});
    ASSERT_NE(str(s), "Infeasible") << "seed " << seed;  // x0 is feasible
    if (s != hqp::QpStatus::Optimal) {
      ++other;
      continue;
    }
    ++optimal;
    const Eigen::VectorXd x = qp.x();
    ASSERT_LE(violation(C, lo, up, x), 1e-8) << "seed " << seed;
    if (seed < 20) {  // objective against the enumeration of all active sets
      const auto ref = hqp::testing::bruteForceQp(A, b, Eigen::MatrixXd(0, n), Eigen::VectorXd(0), C,
                                                  lo, up, 1e-7);
      ASSERT_TRUE(ref.feasible);
      const double obj = 0.5 * (A * x - b).squaredNorm();
      EXPECT_NEAR(obj, ref.objective, 1e-6 * (1.0 + ref.objective)) << "seed " << seed;
    }
  }
  EXPECT_GT(optimal + refused, 0);
  RecordProperty("optimal", optimal);
  RecordProperty("refused", refused);
  RecordProperty("other", other);
}

// Random rank-deficient least-squares QPs: n = 28, A of rank < n with badly scaled columns
// (exactly rank-deficient), one equality, nine inequalities, feasible by construction.
struct RankDeficientQp {
  Eigen::MatrixXd A, E, C;
  Eigen::VectorXd b, e, lower, upper, x0;
};

RankDeficientQp makeRankDeficient(std::mt19937& g) {
  std::uniform_int_distribution<int> Um(5, 40), Ur(1, 27);
  std::uniform_real_distribution<double> U(-1.0, 1.0), U01(0.0, 1.0);
  const int n = 28;
  const int m = Um(g);
  const int rk = std::min(Ur(g), m);
  auto randm = [&](int r, int c) {
    Eigen::MatrixXd M(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) M(i, j) = U(g);
    return M;
  };
  RankDeficientQp q;
  q.A = randm(m, rk) * randm(rk, n);  // rank rk < n
  q.C = randm(9, n);
  q.E = randm(1, n);
  Eigen::VectorXd s(n);
  for (int j = 0; j < n; ++j) s(j) = std::pow(10.0, 3.0 * U(g));  // column scales 1e-3 … 1e3
  q.A = q.A * s.asDiagonal();
  q.C = q.C * s.asDiagonal();
  q.E = q.E * s.asDiagonal();
  q.x0 = randm(n, 1);
  q.b = 2.0 * randm(m, 1);
  q.e = q.E * q.x0;
  const Eigen::VectorXd cx = q.C * q.x0;
  q.lower.resize(9);
  q.upper.resize(9);
  for (int j = 0; j < 9; ++j) {
    q.lower(j) = cx(j) - (U01(g) < 0.5 ? 0.0 : 0.5 * U01(g));
    q.upper(j) = cx(j) + (U01(g) < 0.5 ? 0.0 : 0.5 * U01(g));
    if (U01(g) < 0.5) {
      if (U01(g) < 0.5) q.lower(j) = -kInf;
      else q.upper(j) = kInf;
    }
  }
  return q;
}

using Qp28 = hqp::ActiveSetQp<28, 40, 1, 9>;

// KKT of the reported solution (tests/support/kkt_error.hpp): feasibility, μ ≥ 0 and each
// active row at its bound (the returned error) and stationarity Aᵀ(Ax − b) + Eᵀλ + Σ ±μ c = 0
// relative to its terms (*stat, not asserted: with column scales over six decades and
// rank-deficient A it is not a sharp test, so the objective is checked against enumeration and
// against a cold solve).
double kktError(const Qp28& qp, const RankDeficientQp& p, double* stat) {
  const hqp::testing::KktError k = hqp::testing::kkt(qp, p);
  *stat = k.stationarity;
  return std::max({k.primal, k.dual, k.at_bound});
}

// Were: NumericalFailure or IterationLimit (drop / re-add cycles of one row) on ~28 % of
// the cold solves, and warm re-solves after a change of b stopping at IterationLimit where
// a cold solve reached Optimal.
TEST(QpContracts, RankDeficientFeasibleProblemsAreSolved) {
  static Qp28 qp, cold;
  int failures = 0, warm_failures = 0, total = 0;
  for (int seed = 0; seed < 300; ++seed) {
    std::mt19937 g(static_cast<unsigned>(seed));
    RankDeficientQp p = makeRankDeficient(g);
    qp.resetWorkingSet();
    hqp::testing::loadInto(qp, p);
    ++total;
    if (qp.solve(false) != hqp::QpStatus::Optimal) {
      ++failures;
      continue;
    }
    double stat = 0.0;
    EXPECT_LE(kktError(qp, p, &stat), 1e-9) << "seed " << seed;
    if (seed % 25 == 0) {
      const auto ref = hqp::testing::bruteForceQp(p.A, p.b, p.E, p.e, p.C, p.lower, p.upper, 1e-7);
      ASSERT_TRUE(ref.feasible);
      EXPECT_NEAR(qp.objective(), ref.objective, 1e-7 * (1.0 + ref.objective)) << "seed " << seed;
    }
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int k = 0; k < 3; ++k) {
      for (Eigen::Index i = 0; i < p.b.size(); ++i) p.b(i) += 0.5 * U(g);
      qp.b() = p.b;
      const hqp::QpStatus sw = qp.solve(true);
      cold.resetWorkingSet();
      hqp::testing::loadInto(cold, p);
      const hqp::QpStatus sc = cold.solve(false);
      if (sc == hqp::QpStatus::Optimal && sw != hqp::QpStatus::Optimal) ++warm_failures;
      if (sw == hqp::QpStatus::Optimal) {
        EXPECT_LE(kktError(qp, p, &stat), 1e-9) << "seed " << seed << " re-solve " << k;
        if (sc == hqp::QpStatus::Optimal) {
          EXPECT_NEAR(qp.objective(), cold.objective(), 1e-7 * (1.0 + cold.objective()));
        }
      }
    }
  }
  // Rounding may still defeat a rare instance (then a non-optimal status, never a wrong x).
  EXPECT_LE(failures, total / 100) << failures << " of " << total;
  EXPECT_EQ(warm_failures, 0);
}

// Brute-force reference on a few small rank-deficient instances with the same structure.
TEST(QpContracts, RankDeficientMatchesEnumeration) {
  for (int seed = 0; seed < 6; ++seed) {
    std::mt19937 g(static_cast<unsigned>(1000 + seed));
    RankDeficientQp p = makeRankDeficient(g);
    static Qp28 qp;
    qp.resetWorkingSet();
    hqp::testing::loadInto(qp, p);
    const hqp::QpStatus s = qp.solve(false);
    if (s != hqp::QpStatus::Optimal) continue;  // counted by the test above
    const auto ref = hqp::testing::bruteForceQp(p.A, p.b, p.E, p.e, p.C, p.lower, p.upper, 1e-7);
    ASSERT_TRUE(ref.feasible);
    EXPECT_NEAR(qp.objective(), ref.objective, 1e-6 * (1.0 + ref.objective)) << "seed " << seed;
  }
}

// A numerically rank-deficient A (rank-deficient plus 1e-11 noise, cond ~1e12): the method's
// steps are dominated by rounding. It used to report Optimal at points that violate rows
// (by up to 27 on a unit row); now Optimal is only returned for a feasible x.
TEST(QpContracts, OptimalIsFeasibleOnNearlySingularA) {
  static Qp28 qp;
  int optimal = 0;
  for (int seed = 0; seed < 200; ++seed) {
    std::mt19937 g(static_cast<unsigned>(seed));
    RankDeficientQp p = makeRankDeficient(g);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (Eigen::Index i = 0; i < p.A.size(); ++i) p.A.data()[i] += 1e-11 * U(g);
    p.b *= 100.0;
    qp.resetWorkingSet();
    hqp::testing::loadInto(qp, p);
    const hqp::QpStatus s = qp.solve(false);
    EXPECT_TRUE(qp.x().allFinite());
    if (s != hqp::QpStatus::Optimal) continue;
    ++optimal;
    const Eigen::VectorXd x = qp.x();
    EXPECT_LE(violation(p.C, p.lower, p.upper, x, 1e-8), 1e-8) << "seed " << seed;
  }
  RecordProperty("optimal", optimal);
}

// Inputs the fuzzers found (tests/fuzz/findings/, docs/fuzzing.md): (nearly) parallel or
// duplicate constraint rows, where a sign test on rounding noise used to say Infeasible.
struct RowProblem {
  Eigen::MatrixXd A, C;
  Eigen::VectorXd b, lower, upper;
};

RowProblem nearParallelRows() {  // dual_qp_infeasible_near_parallel_rows
  RowProblem p;
  p.A.resize(3, 2);
  p.A << 5.125, 3.2549019607843128, 3.2549019607843128, 3.2549019607843128, 5.125, 3.2701607498468128;
  p.b = Eigen::VectorXd::Constant(3, -16.0);
  p.C.resize(7, 2);
  p.C << 3.2549014718399611, 3.2549019607843128, 3.2549019607843128, 3.2549019607722585, -10, -16, -16, -16,
      -16, -16, -16, -16, -16, -16;
  p.lower = Eigen::VectorXd::Constant(7, -32.0);
  p.upper = Eigen::VectorXd::Zero(7);
  return p;
}

RowProblem duplicateEqualityRows() {  // dual_qp_infeasible_duplicate_equality_rows
  RowProblem p;
  p.A.resize(3, 2);
  p.A << 5.8431372549019596, 5.843137253314838, 5.8431372549019596, 5.8431374567799956, 0, 0;
  p.b = Eigen::VectorXd::Constant(3, 10.375);
  p.C.resize(7, 2);
  p.C << 0, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375, 10.375;
  p.lower.resize(7);
  p.lower << 107.640625, 215.28125, 215.28125, 215.28125, 215.28125, -kInf, 215.28125;
  p.upper = p.lower;
  p.upper(5) = kInf;
  return p;
}

RowProblem dependentVertexRows() {  // dual_qp_infeasible_primal_feasible_2
  RowProblem p;
  p.A.resize(5, 5);
  p.A << 4.625, -2.2588335205203034, 0, 0, 11.875, 12.875, 5.5, -0.004834595610733689, -11.875, -14.5,
      -0.043944808933338214, 0, 0, 0, 0, 0, 0, 0, 6, 10.875, -14.625, 4.9764463047395004, 0, 2.2136223357280382,
      12.125;
  p.b = Eigen::VectorXd::Constant(5, -16.0);
  p.C.resize(8, 5);
  p.C << 10.75, 8.25, 11.875, 0, -0.98399662887379447, 2.2731204496859565, 0, -5.5, 0.625, 10.75, 0,
      6.1941349662762075, -11, 0, 2.2136223357280382, 12.125, 10.75, 8.25, -8.375, -8.5, -0.032098758180342836, 0,
      0, 0, 0, 0, 0, 15.25, 12, 0, -8.9250958267896241e-05, 9.875, -5.5, -5.625, 0, -10, -16, -16, -16, -16;
  p.lower = Eigen::VectorXd::Constant(8, -32.0);
  p.upper = Eigen::VectorXd::Zero(8);
  return p;
}

// Stationarity Aᵀ(Ax − b) + Σ ±μ c relative to its terms, for the dual's reported multipliers.
template <class Qp>
double dualStationarity(const Qp& qp, const RowProblem& p) {
  const Eigen::VectorXd x = qp.x();
  Eigen::VectorXd g = p.A.transpose() * (p.A * x - p.b);
  double scale = p.A.norm() * (p.A.norm() * x.norm() + p.b.norm());
  for (int k = 0; k < qp.numActive(); ++k) {
    const Eigen::VectorXd c = p.C.row(qp.activeRow(k)).transpose();
    g += (qp.activeAtUpper(k) ? 1.0 : -1.0) * qp.multiplier(k) * c;
    scale += std::abs(qp.multiplier(k)) * c.norm();
  }
  return g.norm() / (1.0 + scale);
}

TEST(QpContracts, DualNeverInfeasibleWithDependentFeasibleRows) {
  const RowProblem problems[] = {nearParallelRows(), duplicateEqualityRows(), dependentVertexRows()};
  // A point meeting every row exactly, by inspection: 0 for the first and third (bounds [−32, 0]),
  // (10.375, 10.375) for the second (10.375 · 10.375 = 107.640625, twice that 215.28125).
  const Eigen::VectorXd points[] = {Eigen::VectorXd::Zero(2), Eigen::VectorXd::Constant(2, 10.375),
                                    Eigen::VectorXd::Zero(5)};
  SmallDual qp;
  for (int i = 0; i < 3; ++i) {
    const RowProblem& p = problems[i];
    ASSERT_EQ(violation(p.C, p.lower, p.upper, points[i]), 0.0) << i;
    const int n = static_cast<int>(p.A.cols()), m = static_cast<int>(p.C.rows());
    ASSERT_TRUE(qp.factorize(p.A, p.b, static_cast<int>(p.A.rows()), n, 1e-9)) << i;
    const hqp::QpStatus s = qp.solve(p.C, p.lower, p.upper, m, hqp::QpSettings{});
    EXPECT_NE(s, hqp::QpStatus::Infeasible) << i;
    if (s != hqp::QpStatus::Optimal) continue;  // NumericalFailure is allowed (HqpWbc falls back)
    EXPECT_LE(violation(p.C, p.lower, p.upper, qp.x(), 1e-9), 1e-9) << i;
    EXPECT_LE(dualStationarity(qp, p), 1e-8) << i;
  }
}

// x₀ ≥ 1, x₁ ≥ 1, x₀ + x₁ ≤ 1: the third row is the sum of the first two, whose bounds
// contradict it (2 > 1). Infeasible, with the certificate y = (1, 1, 1).
TEST(QpContracts, DualDependentContradictingRowsAreInfeasible) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(2, 2), C(3, 2);
  C << 1, 0, 0, 1, 1, 1;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(2), lo(3), up(3);
  lo << 1, 1, -kInf;
  up << kInf, kInf, 1;
  SmallDual qp;
  ASSERT_TRUE(qp.factorize(A, b, 2, 2, 1e-9));
  EXPECT_EQ(str(qp.solve(C, lo, up, 3, hqp::QpSettings{})), "Infeasible");
  up(2) = 2.0;  // now x = (1, 1) meets all three
  EXPECT_EQ(str(qp.solve(C, lo, up, 3, hqp::QpSettings{})), "Optimal");
  EXPECT_NEAR(qp.x()(0), 1.0, 1e-12);
  EXPECT_NEAR(qp.x()(1), 1.0, 1e-12);
}

// active_set_qp_infeasible_near_parallel_rows: five equality rows, three of them [a, a] and
// two at an angle of 1.6e-10 to them. The point where the [a, a] rows and row 1 hold exactly
// (a 2 × 2 solve) meets the two others to 4e-10 on unit rows: feasible to the tolerance, so
// ActiveSetQp must not say Infeasible (its phase 1 stopped on rounding-noise multipliers).
TEST(QpContracts, ActiveSetNeverInfeasibleWhenFeasibleToTheTolerance) {
  Eigen::MatrixXd A(7, 2), C(8, 2);
  A << 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -16, -16, -16, 10.25;
  Eigen::VectorXd b(7), lo(8), up(8);
  b << 7.1764705882352935, 7.1764705882352935, 11.375, 7.1764705882352935, 7.176470588230746,
      7.1764705882352935, 7.1764705882352935;
  C << 10.25, 10.25, 10.25, 11.375, 7.1764705882352935, 7.1764705866163929, 7.1764705882352935,
      7.1764705882352935, 7.1764705882352935, 7.1764705882352935, 7.1764705866163929, 7.1764705882352935,
      7.1764705882352935, 7.1764705882352935, 7.1764705882352935, 11.375;
  lo << 4.1985294117647065, 7.1764705882352935, 7.1764705882352935, 7.1764705882352935, 7.1764705882352935,
      -kInf, 7.1764705882352935, -kInf;
  up << 18.548713277367984, 7.1764705882352935, 7.1764705882352935, 7.1764705882352935, 7.1764705882352935,
      17.426470588235293, 7.1764705882352935, 26.25;
  Eigen::Matrix2d K;
  K << C.row(3), C.row(1);
  const Eigen::Vector2d xt = K.fullPivLu().solve(Eigen::Vector2d(lo(3), lo(1)));
  ASSERT_LE(violation(C, lo, up, xt), 1e-9);
  expectNotInfeasible(A, b, C, lo, up);
}

// active_set_qp_objective_below_enumeration: C does not see the direction (0, 1, −1, 0) and A
// only through 1e-4 entries, so the optimum lies at |x| ~ 1e7. The enumeration of active sets
// used to reject that point for rounding in C x (an absolute tolerance) and reported 5338
// instead of the solver's 2232; it now uses the solvers' relative rule.
TEST(QpContracts, ActiveSetMatchesEnumerationWithTheOptimumFarOut) {
  Eigen::MatrixXd A(3, 4), C(5, 4);
  A << 12.5, 0, -5.7674632352941173e-05, 148.40229930899551, 18.75, 0, -8.6511948529411752e-05,
      222.60344896349326, -0.0060240739996125009, -11.25, -11.25, -11.25;
  C << -6, -11.25, -11.25, -11.25, -11.25, -11.25, -11.25, -11.25, -11.25, -11.25, -11.25, -3.25, -11.25, -11.25,
      -11.25, -11.25, -11.25, -11.25, -11.25, -11.25;
  Eigen::VectorXd b = Eigen::VectorXd::Constant(3, -11.25), lo(5), up(5);
  lo << 143.08216171267756, 187.80091171267756, 164.80091171267756, 187.80091171267756, 187.80091171267756;
  up << kInf, 219.80091171267756, 196.80091171267756, 219.80091171267756, 219.80091171267756;
  SmallQp qp;
  load(qp, A, b, C, lo, up);
  ASSERT_EQ(str(qp.solve(false)), "Optimal");
  EXPECT_LE(violation(C, lo, up, qp.x(), 1e-9), 1e-9);
  const auto ref = hqp::testing::bruteForceQp(A, b, Eigen::MatrixXd(0, 4), Eigen::VectorXd(0), C, lo, up, 1e-9);
  ASSERT_TRUE(ref.feasible);
  EXPECT_GT(ref.x.cwiseAbs().maxCoeff(), 1e6);  // the optimum far out, as the solver's
  EXPECT_NEAR(qp.objective(), ref.objective, 1e-6 * (1.0 + ref.objective));
}

// dual_vs_primal_objective_near_parallel_rows: exactly, only x = 0 is feasible (objective 384);
// to the tolerance a sliver along (−1, 1) is, where the dual method stops at 211.3. Both answers
// are right: each is feasible to the tolerance and no lower than the other's Lagrangian bound
// f(x) − Σ μ viol(y) (convexity), whose huge multipliers account for the gap.
TEST(QpContracts, DualAndPrimalAgreeUpToTheToleranceOnNearlyParallelRows) {
  Eigen::MatrixXd A(3, 2), C(7, 2);
  A << 5.125, -5.25, -5.25, -5.25, 5.125, 3.2549019607843128;
  C << 3.2549019607843128, 3.2549019607843128, 3.2549019588743739, 3.2549019607843128, 3.2549019607843128,
      3.2549019607842844, 3.2549019607843128, -9.9997977493330801, -16, -16, -16, -16, -16, -16;
  const Eigen::VectorXd b = Eigen::VectorXd::Constant(3, -16.0), lo = Eigen::VectorXd::Constant(7, -32.0),
                        up = Eigen::VectorXd::Zero(7);
  SmallDual dual;
  ASSERT_TRUE(dual.factorize(A, b, 3, 2, 1e-9));
  const hqp::QpStatus sd = dual.solve(C, lo, up, 7, hqp::QpSettings{});
  SmallQp primal;
  load(primal, A, b, C, lo, up);
  ASSERT_EQ(str(primal.solve(false)), "Optimal");
  ASSERT_EQ(str(sd), "Optimal");
  const Eigen::VectorXd xd = dual.x(), xp = primal.x();
  EXPECT_LE(violation(C, lo, up, xd, 1e-9), 1e-9);
  EXPECT_LE(violation(C, lo, up, xp, 1e-9), 1e-9);
  auto f = [&](const Eigen::VectorXd& x) { return 0.5 * (A * x - b).squaredNorm(); };
  // bound(x, its multipliers, y) = f(x) − Σ μ max(viol_k(y), 0) − ‖stationarity‖ ‖y − x‖.
  auto bound = [&](const auto& qp, const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
    Eigen::VectorXd g = A.transpose() * (A * x - b);
    double lb = f(x);
    for (int k = 0; k < qp.numActive(); ++k) {
      const int j = qp.activeRow(k);
      const bool upper = qp.activeAtUpper(k);
      const double mu = qp.multiplier(k), cy = C.row(j).dot(y);
      g += (upper ? mu : -mu) * C.row(j).transpose();
      lb -= std::max(mu, 0.0) * std::max(upper ? cy - up(j) : lo(j) - cy, 0.0);
    }
    return lb - g.norm() * (y - x).norm();
  };
  const double tol = 1e-6 * (1.0 + f(xd) + f(xp));
  EXPECT_GE(f(xd), bound(primal, xp, xd) - tol);
  EXPECT_GE(f(xp), bound(dual, xd, xp) - tol);
}

// active_set_qp_infeasible_feasible_far_out: row 0 (an equality) and row 2 fix x₀, x₁ near
// (366, −47); row 4 then needs 2.87e-5 x₃ ≈ 200 and row 3 0.0078 x₂ ≈ 7.63 x₃: feasible, but
// only at |x| ~ 7e9. ActiveSetQp's phase 1 stopped short and called it Infeasible, with a
// "certificate" whose rows are only nearly dependent (their combination is 1e-8, not 0).
TEST(QpContracts, ActiveSetNeverInfeasibleWithAFeasiblePointFarOut) {
  Eigen::MatrixXd A(6, 4), C(5, 4);
  A << -13.625, 11.375, -5.125, -4.5360154656008724, 0.00096312804207165708, 8.9477128477993411, 15.375, 10.5,
      -7.875, 0, 0, 0, 0, 0, 7814.585660491045, 0, 15.125, 6.75, 0.875, -3.5, -15.25, -15.25, 1.125,
      0.096203999707074231;
  Eigen::VectorXd b(6), lo(5), up(5);
  b << 599.99459834443189, 8.875, -7.4559526632203443, 0, -9.625, 11.75;
  C << -0.027058823529411771, -0.026829591377796891, 0, 0, 0, 0, 0, 0, 2, 15.875, 0, 0, 0, 0, 0.0078145856604910444,
      -7.6314779701436954, -1.0124289989623692, -3, 0, 2.8680811157420916e-05;
  lo << -8.625, -32, -32, -32, -32;
  up << -8.625, 0, 0, 0, 0;
  // A witness, row by row: x₁ = −47, x₀ from row 0, x₃ puts row 4 at −16, x₂ puts row 3 at −16.
  Eigen::VectorXd xw(4);
  xw(1) = -47.0;
  xw(0) = (lo(0) - C(0, 1) * xw(1)) / C(0, 0);
  xw(3) = (-16.0 - C(4, 0) * xw(0) - C(4, 1) * xw(1)) / C(4, 3);
  xw(2) = (-16.0 - C(3, 3) * xw(3)) / C(3, 2);
  ASSERT_GT(xw.cwiseAbs().maxCoeff(), 1e9);
  ASSERT_LE(violation(C, lo, up, xw, 1e-9), 1e-9);
  expectNotInfeasible(A, b, C, lo, up);
}

// dual_qp_optimal_active_row_off_bound: rows 0 and 2 at an angle of 1e-11, both active, blew
// the multipliers up to 2e30 and x out to 6e14, where active row 7 was 0.46 off its bound;
// the stationarity check, scaled by those multipliers, let it through as Optimal. An Optimal
// answer must hold its active rows at their bounds (and meet every row).
TEST(QpContracts, DualOptimalHoldsItsActiveRowsAtTheirBounds) {
  Eigen::MatrixXd A(5, 5), C(8, 5);
  A << 4.625, -2.2588335205203034, 0, 10.375, 3.125, 4.6937227658920548, -1.7871433644818691, 5.375,
      -1.1890077928205436, -5.071144449047603, -12.375, 0, 9, -0.02790603440986841, 6, 10.875, -14.625,
      4.9764403442750211, -9.2941176470588243, -9.2941144399865436, -9.625, -14.875, -9.2941176470588243,
      -9.2941176470588243, -9.2941176470588243;
  Eigen::VectorXd b(5), lo(8), up(8);
  b << -9.2941176470588243, -9.2941176470588243, -9.2941176470588243, -9.2941176470588243, -9.2941166197952718;
  C << -9.2941176468951152, -9.2941176470588243, -9.2941176470588243, -9.294117647058755, 0, 0, 0, 0, 0, -14.875,
      -9.2941176470588225, -9.2941176470588243, -9.2941176470588243, -9.2941176470588243, -9.2941176470588243, 10,
      0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 11.875, 0, -9.839966288745286e-05;
  lo << 0, 70.091371920222585, -32, -32, -32, -32, -32, -32;
  up << 6.1941349662762075, kInf, 0, 0, 0, 0, 0, 0;
  SmallDual qp;
  ASSERT_TRUE(qp.factorize(A, b, 5, 5, 1e-9));
  const hqp::QpStatus s = qp.solve(C, lo, up, 8, hqp::QpSettings{});
  if (s != hqp::QpStatus::Optimal) return;  // NumericalFailure is the honest answer here
  EXPECT_LE(violation(C, lo, up, qp.x(), 1e-9), 1e-9);
  for (int k = 0; k < qp.numActive(); ++k) {
    const int j = qp.activeRow(k);
    const double v = C.row(j).dot(qp.x()), bound = qp.activeAtUpper(k) ? up(j) : lo(j);
    EXPECT_LE(std::abs(v - bound) / C.row(j).norm(), 1e-9 * (1.0 + std::abs(v) / C.row(j).norm())) << j;
  }
}

// active_set_qp_infeasible_nearly_dependent_equalities: three equality rows, the second 4.5e-10
// from the first, the third a multiple of x₁ mostly: x = (−16 / 7.33…, 0) meets all three.
// The third was found dependent on the first two, whose nearly singular pair put the
// minimum-norm point 1e-6 off it, and ActiveSetQp said Infeasible without a certificate.
TEST(QpContracts, ActiveSetNeverInfeasibleWithNearlyDependentEqualities) {
  Eigen::MatrixXd A(4, 2), E(3, 2);
  A << -5, -12.625, 7.3333333333333339, 7.3333333333333339, 7.3333333333333339, 7.3333333333333339,
      7.3333333333333339, 7.3333333333333339;
  Eigen::VectorXd b(4), e = Eigen::VectorXd::Constant(3, -16.0);
  b << 0, -7.875, -9.9999989985686475e-05, -16;
  E << 7.3333333333333339, 7.3333333333333339, 7.3333333333333339, 7.3333333300409631, 7.3333333333333339,
      7333.3333300459371;
  const Eigen::Vector2d xw(-16.0 / 7.3333333333333339, 0.0);
  for (int i = 0; i < 3; ++i) ASSERT_LE(std::abs(E.row(i).dot(xw) - e(i)) / E.row(i).norm(), 1e-15) << i;
  SmallQp qp;
  qp.resize(2, 4, 3, 0);
  qp.A() = A;
  qp.b() = b;
  qp.E() = E;
  qp.e() = e;
  const hqp::QpStatus s = qp.solve(false);
  EXPECT_NE(s, hqp::QpStatus::Infeasible);
  if (s == hqp::QpStatus::Optimal) {
    for (int i = 0; i < 3; ++i) {
      const double v = E.row(i).dot(qp.x()) / E.row(i).norm();
      EXPECT_LE(std::abs(v - e(i) / E.row(i).norm()), 1e-9 * (1.0 + std::abs(v))) << i;
    }
  }
  // Contradicting equalities are still Infeasible: x₀ + x₁ = 1 twice, then = 2.
  Eigen::MatrixXd E2(3, 2);
  E2 << 1, 1, 2, 2, 1, 1;
  Eigen::VectorXd e2(3);
  e2 << 1, 2, 2;
  qp.E() = E2;
  qp.e() = e2;
  EXPECT_EQ(str(qp.solve(false)), "Infeasible");
}

}  // namespace
