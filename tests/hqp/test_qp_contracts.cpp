// Input contracts and "no wrong Optimal" of ActiveSetQp and DualActiveSetQp (docs/hqp.md,
// "Contracts"): regressions built from answers that were silently wrong. Expectations come
// from closed forms, brute-force enumeration or KKT conditions computed here.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "hqp/active_set_qp.hpp"
#include "hqp/dual_active_set_qp.hpp"
#include "support/brute_force_qp.hpp"

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
std::string str(hqp::QpStatus s) { return hqp::toString(s); }

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
  double v = 0.0;
  const Eigen::VectorXd cx = C * x;
  for (Eigen::Index j = 0; j < C.rows(); ++j) {
    const double s = std::max(C.row(j).norm(), 1e-300);
    v = std::max(v, std::max(lo(j) - cx(j), cx(j) - up(j)) / s);
  }
  return v;
}

using Dual2 = hqp::DualActiveSetQp<2, 2, 2>;

// min ½‖x‖² s.t. 1 ≤ x₀ ≤ 0: no feasible point (was: Optimal with x₀ = 1).
TEST(QpContracts, DualCrossedBoundsAreInfeasible) {
  Dual2 qp;
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
  Dual2 qp;
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

using Qp3 = hqp::ActiveSetQp<3, 3, 0, 2>;

// A row [+inf, +inf] was ignored (Optimal); [−inf, −inf] gave NumericalFailure.
TEST(QpContracts, ActiveSetRefusesWrongSideInfinities) {
  Qp3 qp;
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
    hqp::DualActiveSetQp<8, 12, 10> qp;
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

// KKT of the reported solution, computed here: feasibility, μ ≥ 0, complementarity (the
// returned error) and stationarity Aᵀ(Ax − b) + Eᵀλ + Σ ±μ c = 0 relative to its terms
// (*stat, not asserted: with column scales over six decades and rank-deficient A it is not a
// sharp test, so the objective is checked against enumeration and against a cold solve).
double kktError(const Qp28& qp, const RankDeficientQp& p, double* stat) {
  const Eigen::VectorXd x = qp.x();
  const Eigen::VectorXd g = p.A.transpose() * (p.A * x - p.b);
  Eigen::VectorXd s = g + p.E.transpose() * qp.equalityMultipliers();
  double scale = 1.0 + g.cwiseAbs().maxCoeff();
  double err = 0.0;
  for (int a = 0; a < qp.numActive(); ++a) {
    const int j = qp.activeRow(a);
    const double mu = qp.multiplier(a);
    const Eigen::VectorXd t = (qp.activeAtUpper(a) ? mu : -mu) * p.C.row(j).transpose();
    s += t;
    scale = std::max(scale, t.cwiseAbs().maxCoeff());
    err = std::max(err, -mu / scale);
    const double bound = qp.activeAtUpper(a) ? p.upper(j) : p.lower(j);
    err = std::max(err, std::abs(p.C.row(j).dot(x) - bound) / p.C.row(j).norm());
  }
  *stat = s.cwiseAbs().maxCoeff() / scale;
  err = std::max(err, violation(p.C, p.lower, p.upper, x));
  err = std::max(err, std::abs(p.E.row(0).dot(x) - p.e(0)) / p.E.row(0).norm());
  return err;
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

}  // namespace
