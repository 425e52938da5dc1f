// DualActiveSetQp's final check on nearly dependent vertices: it must not call a point Optimal
// that is not, and must keep calling a true vertex with huge multipliers Optimal. This unit is
// compiled with -march=native where the compiler has it (tests/hqp/CMakeLists.txt): the
// recorded QP below went wrong only with fused multiply-adds, as benchmark builds make them.
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hqp/dual_active_set_qp.hpp"

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct RecordedQp {
  int n = 0, r = 0, m = 0;
  double min_sigma = 0.0;
  Eigen::MatrixXd A, C;
  Eigen::VectorXd b, lower, upper;
  std::vector<int> first_order;  // rows the dual method takes first (the level above's)
};

RecordedQp readQp(const char* path) {
  std::ifstream in(path);
  RecordedQp q;
  std::string line;
  while (in.peek() == '#') std::getline(in, line);
  int own = 0;
  in >> q.n >> q.r >> q.m >> own >> q.min_sigma;
  const auto number = [&in] {
    std::string t;
    in >> t;
    return std::stod(t);  // also "inf", "-inf"
  };
  q.A.resize(q.r, q.n);
  q.b.resize(q.r);
  q.C.resize(q.m, q.n);
  q.lower.resize(q.m);
  q.upper.resize(q.m);
  for (int i = 0; i < q.r; ++i)
    for (int j = 0; j < q.n; ++j) q.A(i, j) = number();
  for (int i = 0; i < q.r; ++i) q.b(i) = number();
  for (int i = 0; i < q.m; ++i)
    for (int j = 0; j < q.n; ++j) q.C(i, j) = number();
  for (int i = 0; i < q.m; ++i) q.lower(i) = number();
  for (int i = 0; i < q.m; ++i) q.upper(i) = number();
  q.first_order.resize(static_cast<std::size_t>(own));
  for (int& row : q.first_order) in >> row;
  EXPECT_TRUE(in.good()) << path;
  return q;
}

// Largest bound violation per unit row.
double violation(const RecordedQp& q, const Eigen::VectorXd& x) {
  double v = 0.0;
  for (int j = 0; j < q.m; ++j) {
    const double cx = q.C.row(j).dot(x), nr = q.C.row(j).norm();
    v = std::max(v, std::max(q.lower(j) - cx, cx - q.upper(j)) / nr);
  }
  return v;
}

// HqpWbc's last level on stress corpus instance 38. With FMA contraction the dual method's
// first order ends NumericalFailure, and the order-free route used to stop at 813.48, twice the
// optimum 402.04, on multipliers of ~1e14 whose size passed the stationarity test. Every route
// that says Optimal must be at the optimum; others may fail, but keep x finite.
TEST(QpDualFinalCheck, RecordedNearlyDependentVertexIsNotCalledOptimalAboveTheOptimum) {
  const RecordedQp q = readQp(HQP_DUAL_NEARLY_DEPENDENT_QP_FILE);
  ASSERT_EQ(q.n, 9);
  ASSERT_EQ(q.r, 15);
  ASSERT_EQ(q.m, 30);
  constexpr double kOptimum = 402.04164;
  hqp::DualActiveSetQp<15, 15, 60> qp;
  int optimal = 0;
  for (const bool order_free : {false, true}) {
    ASSERT_TRUE(qp.factorize(q.A, q.b, q.r, q.n, q.min_sigma));
    const hqp::QpStatus s = order_free ? qp.solveOrderFree(q.C, q.lower, q.upper, q.m, {})
                                       : qp.solve(q.C, q.lower, q.upper, q.m, {});
    ASSERT_TRUE(qp.x().head(q.n).allFinite());
    if (s != hqp::QpStatus::Optimal) {
      EXPECT_EQ(s, hqp::QpStatus::NumericalFailure) << "order-free " << order_free;
      continue;
    }
    ++optimal;
    const Eigen::VectorXd x = qp.x().head(q.n);
    EXPECT_LE(violation(q, x), 1e-8) << "order-free " << order_free;
    EXPECT_LE((q.A * x - q.b).squaredNorm(), kOptimum * (1.0 + 1e-6))
        << "Optimal above the optimum, order-free " << order_free;
  }
  std::printf("routes ending Optimal: %d of 2\n", optimal);
}

// The same level as the dual method sees it on the shipped path in a clang -march=native build.
// Row 29 depends on the active rows through the nearly opposite pair 21, 26 (cos −1 + 4e-8), so
// their rounding, magnified by a ~1e7 combination, leaves it 1e-8 off its bound (tol 1e-9):
// every route used to end NumericalFailure there, and the last level with them. The final
// check's refinement (DualActiveSetQp::refine) takes such residuals out. The optimum,
// 402.041625, is the primal method's point (that row 1e-8 off) and SciPy's SLSQP's.
TEST(QpDualFinalCheck, HeldRowOffItsBoundByRoundingIsRefinedToTheOptimum) {
  const RecordedQp q = readQp(HQP_DUAL_HELD_ROW_QP_FILE);
  ASSERT_EQ(q.n, 9);
  ASSERT_EQ(q.m, 30);
  constexpr double kOptimum = 402.041625;
  hqp::DualActiveSetQp<15, 15, 60> qp;
  ASSERT_TRUE(qp.factorize(q.A, q.b, q.r, q.n, q.min_sigma));
  ASSERT_EQ(qp.solveOrderFree(q.C, q.lower, q.upper, q.m, {}), hqp::QpStatus::Optimal);
  const Eigen::VectorXd x = qp.x().head(q.n);
  EXPECT_LE(violation(q, x), 1e-9 * (1.0 + x.norm()));
  EXPECT_NEAR((q.A * x - q.b).squaredNorm(), kOptimum, 1e-6 * kOptimum);
}

// min ½‖x − (0, 10)‖² s.t. x1 ≤ 0, −x1 + δ x2 ≤ 0 (δ = 1e-7): the optimum is the apex x = 0
// (objective ½ · 100) with multipliers 10/δ = 1e8 on both rows (closed form of g + Σ μ c = 0).
// The multipliers are huge but right: the check must keep calling it Optimal. (At δ = 1e-9 the
// dual method takes the second row as dependent on the first and declines: NumericalFailure.)
TEST(QpDualFinalCheck, WedgeOfNearlyOppositeRowsIsOptimalWithItsLargeMultipliers) {
  hqp::DualActiveSetQp<2, 2, 2> qp;
  Eigen::Matrix2d A = Eigen::Matrix2d::Identity(), C;
  C << 1.0, 0.0, -1.0, 1e-7;
  const Eigen::Vector2d b(0.0, 10.0), lower(-kInf, -kInf), upper(0.0, 0.0);
  ASSERT_TRUE(qp.factorize(A, b, 2, 2, 0.0));
  ASSERT_EQ(qp.solve(C, lower, upper, 2, {}), hqp::QpStatus::Optimal);
  EXPECT_LE(qp.x().cwiseAbs().maxCoeff(), 1e-6);
  ASSERT_EQ(qp.numActive(), 2);
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(qp.activeAtUpper(k));
    EXPECT_NEAR(qp.multiplier(k), 1e8, 1e2) << "row " << qp.activeRow(k);
  }
}

}  // namespace

// Stress instance 203 written another way (variables permuted, rows rescaled: `hqp_corpus
// reformulate --seed 1`), its last level as the dual method sees it in a clang -march=native
// build. Every route ends on the optimum's vertex, nine nearly dependent rows, but its
// multipliers there are ~1/σ_min noise: the first order's and the order-free route's points
// ended NumericalFailure (a duality gap hundreds of times the allowed one) in that build, the
// plain order's in GCC builds with and without -march=native. Multipliers fitted afresh on the
// rows at their bounds (DualActiveSetQp::refitted) certify it. The reference is independent: the
// vertex of those nine rows (17, 13, 6, 24, 27, 15, 22, 0, 19) solved in 60-digit arithmetic
// (mpmath), ‖A x − b‖² = 4803.293002690, with every multiplier of g = Σ μ n positive there
// (0.36 … 4.6e7), so that vertex is the optimum of the QP on those rows.
TEST(QpDualFinalCheck, VertexWithNoiseMultipliersIsCertifiedByRefittedOnes) {
  const RecordedQp q = readQp(HQP_DUAL_REFITTED_QP_FILE);
  ASSERT_EQ(q.n, 9);
  ASSERT_EQ(q.m, 30);
  ASSERT_EQ(q.first_order.size(), 10u);
  constexpr double kOptimum = 4803.293002690;
  hqp::DualActiveSetQp<15, 15, 60> qp;
  for (int route = 0; route < 3; ++route) {
    ASSERT_TRUE(qp.factorize(q.A, q.b, q.r, q.n, q.min_sigma));
    const int own = static_cast<int>(q.first_order.size());
    const hqp::QpStatus s =
        route == 0   ? qp.solve(q.C, q.lower, q.upper, q.m, {}, q.first_order.data(), own)
        : route == 1 ? qp.solve(q.C, q.lower, q.upper, q.m, {})
                     : qp.solveOrderFree(q.C, q.lower, q.upper, q.m, {});
    ASSERT_EQ(s, hqp::QpStatus::Optimal) << "route " << route;
    const Eigen::VectorXd x = qp.x().head(q.n);
    EXPECT_LE(violation(q, x), 1e-9 * (1.0 + x.norm())) << "route " << route;
    // A row 1e-13 inside its bound moves the objective by μ · 1e-13 ≈ 5e-6 here.
    EXPECT_NEAR((q.A * x - q.b).squaredNorm(), kOptimum, 1e-8 * kOptimum) << "route " << route;
    EXPECT_EQ(qp.numActive(), 9) << "route " << route;
    for (int k = 0; k < qp.numActive(); ++k) EXPECT_GE(qp.multiplier(k), 0.0) << "route " << route;
  }
}
