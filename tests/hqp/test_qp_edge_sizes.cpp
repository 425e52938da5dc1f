// ActiveSetQp with the smallest capacities: no equality storage (MaxEq = 0) and
// one-row objective / equality / inequality storage. Expected values come from
// closed forms and from the enumeration reference.
#include <gtest/gtest.h>

#include <random>

#include "hqp/active_set_qp.hpp"
#include "support/brute_force_qp.hpp"

namespace {

template <class Qp>
void expectMatchesBruteForce(Qp& qp, const hqp::testing::RandomQp& p, bool warm) {
  hqp::testing::loadInto(qp, p);
  const hqp::QpStatus s = qp.solve(warm);
  const auto ref = hqp::testing::bruteForceQp(p.A, p.b, p.E, p.e, p.C, p.lower, p.upper);
  ASSERT_TRUE(qp.x().allFinite());
  if (!ref.feasible) {
    EXPECT_EQ(s, hqp::QpStatus::Infeasible);
    return;
  }
  ASSERT_EQ(s, hqp::QpStatus::Optimal);
  const double obj = 0.5 * (p.A * qp.x() - p.b).squaredNorm();
  EXPECT_NEAR(obj, ref.objective, 1e-9 * (1.0 + std::abs(ref.objective)));
  EXPECT_NEAR(qp.objective(), ref.objective, 1e-9 * (1.0 + std::abs(ref.objective)));
  if (p.E.rows() > 0) {
    EXPECT_LE((p.E * qp.x() - p.e).cwiseAbs().maxCoeff(), 1e-8);
  }
  if (p.C.rows() > 0) {
    const Eigen::VectorXd cx = p.C * qp.x();
    for (Eigen::Index j = 0; j < cx.size(); ++j) {
      EXPECT_GE(cx(j), p.lower(j) - 1e-8);
      EXPECT_LE(cx(j), p.upper(j) + 1e-8);
    }
  }
}

TEST(QpEdgeSizes, NoEqualityCapacityReproducer) {
  // The reported case: MaxEq = 0 used to assert in resize(); an empty problem
  // (A = 0, no active bound) has the minimum-norm optimum x = 0.
  hqp::ActiveSetQp<8, 3, 0, 4> qp;
  qp.resize(8, 3, 0, 4);
  EXPECT_EQ(qp.solve(true), hqp::QpStatus::Optimal);
  EXPECT_EQ(qp.x().size(), 8);
  EXPECT_DOUBLE_EQ(qp.x().norm(), 0.0);
  EXPECT_EQ(qp.equalityMultipliers().size(), 0);
}

TEST(QpEdgeSizes, NoEqualityCapacityClosedForm) {
  // min ½‖x − (2, −1)‖² s.t. x0 ≤ 1, x1 ≥ 0  →  x = (1, 0), objective ½(1 + 1) = 1.
  hqp::ActiveSetQp<2, 2, 0, 2> qp;
  qp.resize(2, 2, 0, 2);
  qp.A().setIdentity();
  qp.b() << 2.0, -1.0;
  qp.C().setIdentity();
  qp.lower() << -std::numeric_limits<double>::infinity(), 0.0;
  qp.upper() << 1.0, std::numeric_limits<double>::infinity();
  ASSERT_EQ(qp.solve(false), hqp::QpStatus::Optimal);
  EXPECT_NEAR(qp.x()(0), 1.0, 1e-12);
  EXPECT_NEAR(qp.x()(1), 0.0, 1e-12);
  EXPECT_NEAR(qp.objective(), 1.0, 1e-12);
  EXPECT_EQ(qp.numActive(), 2);
}

TEST(QpEdgeSizes, OneRowEachClosedForm) {
  // min ½(x0 + x1 − 2)² s.t. x0 − x1 = 0, x0 ≤ 0.5: the equality-only optimum
  // (1, 1) violates the bound, so x = (0.5, 0.5), objective ½, and stationarity
  // (x0 + x1 − 2)(1, 1) + λ(1, −1) + μ(1, 0) = 0 gives λ = −1, μ = 2.
  hqp::ActiveSetQp<2, 1, 1, 1> qp;
  qp.resize(2, 1, 1, 1);
  qp.A() << 1.0, 1.0;
  qp.b() << 2.0;
  qp.E() << 1.0, -1.0;
  qp.e() << 0.0;
  qp.C() << 1.0, 0.0;
  qp.lower() << -std::numeric_limits<double>::infinity();
  qp.upper() << 0.5;
  for (bool warm : {false, true, true}) {
    ASSERT_EQ(qp.solve(warm), hqp::QpStatus::Optimal);
    EXPECT_NEAR(qp.x()(0), 0.5, 1e-12);
    EXPECT_NEAR(qp.x()(1), 0.5, 1e-12);
    EXPECT_NEAR(qp.objective(), 0.5, 1e-12);
    ASSERT_EQ(qp.numActive(), 1);
    EXPECT_TRUE(qp.activeAtUpper(0));
    EXPECT_NEAR(qp.multiplier(0), 2.0, 1e-10);
    EXPECT_NEAR(qp.equalityMultipliers()(0), -1.0, 1e-10);
  }
}

TEST(QpEdgeSizes, OneRowEachInfeasible) {
  // x0 = 1 and x0 ≤ 0 cannot both hold.
  hqp::ActiveSetQp<2, 1, 1, 1> qp;
  qp.resize(2, 1, 1, 1);
  qp.A() << 1.0, 1.0;
  qp.b() << 0.0;
  qp.E() << 1.0, 0.0;
  qp.e() << 1.0;
  qp.C() << 1.0, 0.0;
  qp.lower() << -std::numeric_limits<double>::infinity();
  qp.upper() << 0.0;
  EXPECT_EQ(qp.solve(false), hqp::QpStatus::Infeasible);
  EXPECT_TRUE(qp.x().allFinite());
}

TEST(QpEdgeSizes, RandomNoEqualityCapacity) {
  std::mt19937 rng(11);
  hqp::ActiveSetQp<5, 4, 0, 6> qp;
  for (int trial = 0; trial < 150; ++trial) {
    const int n = 1 + trial % 5;
    const int m = 1 + trial % 4;
    const int mi = trial % 7;
    const int rank = trial % 3 == 0 ? std::max(0, std::min(n, m) - 1) : -1;
    const auto p = hqp::testing::makeRandomQp(rng, n, m, 0, mi, rank, 0.5);
    expectMatchesBruteForce(qp, p, trial % 2 == 1);
    expectMatchesBruteForce(qp, p, true);  // warm repeat of the same problem
  }
}

TEST(QpEdgeSizes, RandomOneRowEach) {
  std::mt19937 rng(23);
  hqp::ActiveSetQp<3, 1, 1, 1> qp;
  for (int trial = 0; trial < 150; ++trial) {
    const int n = 1 + trial % 3;
    const int m = trial % 2;
    const int me = (trial / 2) % 2;
    const int mi = (trial / 4) % 2;
    const auto p = hqp::testing::makeRandomQp(rng, n, m, me, mi, -1, 0.5, false,
                                              trial % 5 == 4 && mi > 0);
    expectMatchesBruteForce(qp, p, trial % 2 == 1);
    expectMatchesBruteForce(qp, p, true);
  }
}

}  // namespace
