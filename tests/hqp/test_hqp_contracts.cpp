// Input contracts, finite x and numerical health of HqpWbc and WqpWbc (docs/hqp.md,
// "Contracts"): regressions built from answers that were silently wrong. Expectations come
// from closed forms computed here.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "hqp/hqp_wbc.hpp"
#include "hqp/wqp_wbc.hpp"

namespace {

constexpr int N = 4;
constexpr double kInf = std::numeric_limits<double>::infinity();
using T2 = hqp::Task<2, N>;
using T1 = hqp::Task<1, N>;
using C1 = hqp::Constraint<1, N>;
using Top = hqp::Level<N, hqp::TaskList<T2>, hqp::ConstraintList<C1>>;
using Mid = hqp::Level<N, hqp::TaskList<T1>>;
using Last = hqp::Level<N, hqp::TaskList<hqp::Task<4, N>>, hqp::ConstraintList<C1>>;
using Wbc = hqp::HqpWbc<N, Top, Mid, Mid, Last>;
using Wqp = hqp::WqpWbc<N, Top, Mid, Mid, Last>;

// x₀ + x₁ = 1, x₀ − x₁ = 0 (level 1, so x₀ = x₁ = 0.5), then x₂ = 1 and x₃ = 2, then a full
// rank last level pulling x toward 0, with −10 ≤ x₂ ≤ 10 and −10 ≤ x₃ ≤ 10.
template <class W>
void fillBase(W& w) {
  auto& t = w.template level<0>().template task<0>();
  t.A << 1, 1, 0, 0,  1, -1, 0, 0;
  t.b << 1, 0;
  auto& c0 = w.template level<0>().template constraint<0>();
  c0.D << 0, 0, 1, 0;
  c0.lower << -10;
  c0.upper << 10;
  w.template level<1>().template task<0>().A << 0, 0, 1, 0;
  w.template level<1>().template task<0>().b << 1;
  w.template level<2>().template task<0>().A << 0, 0, 0, 1;
  w.template level<2>().template task<0>().b << 2;
  w.template level<3>().template task<0>().A.setIdentity();
  w.template level<3>().template task<0>().b.setZero();
  auto& c3 = w.template level<3>().template constraint<0>();
  c3.D << 0, 0, 0, 1;
  c3.lower << -10;
  c3.upper << 10;
}

TEST(HqpContracts, ValidBaseProblemIsOptimal) {
  static Wbc wbc;
  fillBase(wbc);
  ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  EXPECT_NEAR(wbc.x()(0), 0.5, 1e-14);
  EXPECT_NEAR(wbc.x()(1), 0.5, 1e-14);
  EXPECT_NEAR(wbc.x()(2), 1.0, 1e-14);
  EXPECT_NEAR(wbc.x()(3), 2.0, 1e-14);
  EXPECT_FALSE(wbc.result().higher_level_degraded);
}

// The last level's own row 1 ≤ x₃ ≤ 0 (empty), with a last level of full column rank: it was
// solved by the dual method, which returned Optimal with the row violated by 1. Now the level
// is Infeasible and its own rows are dropped (the documented policy).
TEST(HqpContracts, LastLevelCrossedOwnBoundsAreInfeasible) {
  using Wbc2 = hqp::HqpWbc<N, Top, Last>;
  static Wbc2 wbc;
  auto& t = wbc.level<0>().task<0>();
  t.A << 1, 1, 0, 0,  1, -1, 0, 0;  // x₀ = x₁ = 0.5; x₂, x₃ free for the last level
  t.b << 1, 0;
  wbc.level<0>().constraint<0>().D << 0, 0, 1, 0;
  wbc.level<0>().constraint<0>().lower << -10;
  wbc.level<0>().constraint<0>().upper << 10;
  wbc.level<1>().task<0>().A.setIdentity();
  wbc.level<1>().task<0>().b << 0, 0, 3, 0.5;
  wbc.level<1>().constraint<0>().D << 0, 0, 0, 1;
  wbc.level<1>().constraint<0>().lower << 1.0;
  wbc.level<1>().constraint<0>().upper << 2.0;
  ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);  // closed form: x₂ = 3, x₃ = clamp(0.5) = 1
  EXPECT_TRUE(wbc.result().levels[1].dual);
  EXPECT_NEAR(wbc.x()(2), 3.0, 1e-12);
  EXPECT_NEAR(wbc.x()(3), 1.0, 1e-12);
  wbc.level<1>().constraint<0>().upper << 0.0;  // 1 ≤ x₃ ≤ 0
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::Infeasible);
  EXPECT_EQ(wbc.result().failed_level, 1);
  EXPECT_TRUE(wbc.result().levels[1].constraints_dropped);
  EXPECT_NEAR(wbc.x()(3), 0.5, 1e-12);  // the row dropped: the task's own optimum
}

// A row with bounds [+inf, +inf] was ignored (Optimal, constraints_dropped false);
// [−inf, −inf] gave NumericalFailure. Both break the contract: InvalidInput, x = 0.
TEST(HqpContracts, WrongSideInfinitiesAreInvalidInput) {
  static Wbc wbc;
  fillBase(wbc);
  wbc.level<0>().constraint<0>().lower << kInf;
  wbc.level<0>().constraint<0>().upper << kInf;
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_EQ(wbc.x().norm(), 0.0);
  wbc.level<0>().constraint<0>().lower << -kInf;
  wbc.level<0>().constraint<0>().upper << -kInf;
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_TRUE(wbc.x().allFinite());
  static Wqp wqp;
  fillBase(wqp);
  wqp.level<0>().constraint<0>().lower << kInf;
  wqp.level<0>().constraint<0>().upper << kInf;
  EXPECT_EQ(wqp.solve(), hqp::QpStatus::InvalidInput);
  wqp.level<0>().constraint<0>().lower << -1.0;
  wqp.level<0>().constraint<0>().upper << 1.0;
  EXPECT_EQ(wqp.solve(), hqp::QpStatus::Optimal);
}

// A level-3 target of DBL_MAX with a level-4 row scaled by 1e200 gave a NaN x. Now:
// InvalidInput (beyond max_magnitude), x = 0; and with the range raised by the caller, x is
// the higher levels' solution (finite) with a non-optimal status.
TEST(HqpContracts, HugeDataNeverGivesNonFiniteX) {
  using T1 = hqp::Task<1, N>;
  using L0 = hqp::Level<N, hqp::TaskList<T1>, hqp::ConstraintList<C1>>;
  using L1 = hqp::Level<N, hqp::TaskList<T1>>;
  using Four = hqp::HqpWbc<N, L0, L1, L1, Last>;
  auto fill = [](Four& w) {
    w.level<0>().task<0>().A << 1, 1, 0, 0;
    w.level<0>().task<0>().b << 1;
    w.level<0>().constraint<0>().D << 0, 0, 0, 1;
    w.level<0>().constraint<0>().lower << -10;
    w.level<0>().constraint<0>().upper << 10;
    w.level<1>().task<0>().A << 1, -1, 0, 0;
    w.level<1>().task<0>().b << 0;
    w.level<2>().task<0>().A << 0, 0, 1, 0.5;
    w.level<2>().task<0>().b << DBL_MAX;
    w.level<3>().task<0>().A.setIdentity();
    w.level<3>().task<0>().A.row(2) *= 1e200;
    w.level<3>().task<0>().b.setZero();
    w.level<3>().constraint<0>().D << 0, 0, 1, 1;
    w.level<3>().constraint<0>().lower << -5;
    w.level<3>().constraint<0>().upper << 5;
  };
  static Four wbc;
  fill(wbc);
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_TRUE(wbc.x().allFinite());
  hqp::HqpSettings wide;
  wide.qp.max_magnitude = DBL_MAX;
  static Four w2(wide);
  fill(w2);
  EXPECT_NE(w2.solve(), hqp::QpStatus::Optimal);
  ASSERT_TRUE(w2.x().allFinite());
  // Levels 1 and 2 alone: x₀ = x₁ = 0.5 (closed form), kept.
  EXPECT_NEAR(w2.x()(0), 0.5, 1e-12);
  EXPECT_NEAR(w2.x()(1), 0.5, 1e-12);
}

// A single level-2 target of 1e150 raised level 1's residual from ~1e-26 to ~1e269, status
// Optimal, nothing flagged. Beyond the default max_magnitude: InvalidInput. Inside it (1e40)
// or with the range raised: the numerical-health flag is set for level 1.
TEST(HqpContracts, LowerLevelSwampingHigherIsFlagged) {
  using Two = hqp::HqpWbc<N, Top, Mid>;
  auto fill = [](Two& w, double target) {
    auto& t = w.level<0>().task<0>();
    t.A << 1, 1, 0.3, 0,  1, -1, 0, 0.7;
    t.b << 1, 0;
    w.level<0>().constraint<0>().D << 0, 0, 1, 0;
    w.level<0>().constraint<0>().lower << -kInf;
    w.level<0>().constraint<0>().upper << kInf;
    w.level<1>().task<0>().A << 0.2, 0.1, 1, 1;
    w.level<1>().task<0>().b << target;
  };
  static Two alone;
  fill(alone, 1.0);
  ASSERT_EQ(alone.solve(), hqp::QpStatus::Optimal);
  EXPECT_LT(alone.result().levels[0].residual, 1e-24);
  EXPECT_FALSE(alone.result().higher_level_degraded);
  EXPECT_FALSE(alone.result().levels[0].degraded);

  static Two big;
  fill(big, 1e150);
  EXPECT_EQ(big.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_TRUE(big.x().allFinite());

  static Two inside;
  fill(inside, 1e40);
  inside.solve();
  // Level 1's residual at the final x, computed here: its rounding is ~eps · 1e40 ≫ 1e-6.
  const auto& t = inside.level<0>().task<0>();
  const double r1 = (t.A * inside.x() - t.b).norm();
  if (r1 > 1e-6) {
    EXPECT_TRUE(inside.result().higher_level_degraded) << "level 1 residual " << r1;
    EXPECT_TRUE(inside.result().levels[0].degraded);
  }
  EXPECT_GT(r1, 1e-6);  // the reproduction does raise level 1's residual

  static Two wide(hqp::HqpSettings{hqp::QpSettings{100, 1e-9, 1e-12, 1e-10, 1e200}});
  fill(wide, 1e150);
  wide.solve();
  EXPECT_TRUE(wide.x().allFinite());
  EXPECT_TRUE(wide.result().higher_level_degraded);
  EXPECT_TRUE(wide.result().levels[0].degraded);
  EXPECT_FALSE(wide.result().levels[1].degraded);
}

// Random well-scaled hierarchies never raise the flag (no false alarms in normal use).
TEST(HqpContracts, HealthFlagQuietOnOrdinaryProblems) {
  std::mt19937 g(5);
  std::normal_distribution<double> nd(0.0, 1.0);
  static Wbc wbc;
  for (int k = 0; k < 500; ++k) {
    fillBase(wbc);
    auto rnd = [&](auto& M) {
      for (Eigen::Index i = 0; i < M.size(); ++i) M.data()[i] = nd(g) * (k % 3 == 0 ? 100.0 : 1.0);
    };
    rnd(wbc.level<0>().task<0>().A);
    rnd(wbc.level<0>().task<0>().b);
    rnd(wbc.level<1>().task<0>().A);
    rnd(wbc.level<1>().task<0>().b);
    rnd(wbc.level<2>().task<0>().A);
    rnd(wbc.level<2>().task<0>().b);
    rnd(wbc.level<3>().task<0>().A);
    rnd(wbc.level<3>().task<0>().b);
    wbc.solve();
    EXPECT_TRUE(wbc.x().allFinite());
    EXPECT_FALSE(wbc.result().higher_level_degraded) << "instance " << k;
  }
}

// The magnitude contract is entry-wise at its edge: with max_magnitude = 10, an entry of A or D
// at 10 is accepted and one a hair above it is InvalidInput (HqpWbc skips the entry-wise scan
// when every row norm is ≤ 5), with the other rows short or long (4.9s, norm 9.8).
TEST(HqpContracts, MagnitudeLimitIsEntryWise) {
  static Wbc wbc(hqp::HqpSettings{hqp::QpSettings{100, 1e-9, 1e-12, 1e-10, 10.0}});
  const double above = std::nextafter(10.0, 20.0);
  for (const bool long_rows : {false, true}) {
    const auto set = [&](double a_entry, double d_entry) {
      fillBase(wbc);
      auto& A = wbc.level<3>().task<0>().A;
      auto& D = wbc.level<3>().constraint<0>().D;
      if (long_rows) {
        A.row(1).setConstant(4.9);
        D.row(0).setConstant(4.9);
      }
      A(1, 2) = a_entry;
      D(0, 1) = d_entry;
      return wbc.solve();
    };
    const std::string rows = long_rows ? "long rows" : "short rows";  // for the messages
    EXPECT_NE(set(10.0, -10.0), hqp::QpStatus::InvalidInput) << rows;
    EXPECT_NE(set(-10.0, 10.0), hqp::QpStatus::InvalidInput) << rows;
    EXPECT_EQ(set(above, 1.0), hqp::QpStatus::InvalidInput) << rows;
    EXPECT_EQ(set(1.0, -above), hqp::QpStatus::InvalidInput) << rows;
    EXPECT_TRUE(wbc.x().allFinite());
  }
  fillBase(wbc);  // short rows, every entry ≤ 2: valid
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
}

// NaN is InvalidInput in both hierarchies (was NumericalFailure), x finite.
TEST(HqpContracts, NaNIsInvalidInput) {
  static Wbc wbc;
  fillBase(wbc);
  wbc.level<1>().task<0>().A(0, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_TRUE(wbc.x().allFinite());
  static Wqp wqp;
  fillBase(wqp);
  wqp.level<3>().constraint<0>().upper << std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(wqp.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_TRUE(wqp.x().allFinite());
}

// Bounds that cross by less than feasibility_tol on the unit-norm row are one value within the
// tolerance, not an empty row (the rule of every solver, docs/hqp.md "Contracts"; the fuzzer's
// hqp_optimal_with_inverted_row crossed by 4.3e-11). Level 0's row 2 x₂ ∈ [l, 3]: crossed by
// half the tolerance it holds x₂ at 1.5 (level 1 wants 1); crossed by four times the
// tolerance it is empty and dropped, and x₂ = 1.
TEST(HqpContracts, BoundsCrossedWithinTheToleranceAreHeld) {
  static Wbc wbc;
  fillBase(wbc);
  const double tol = hqp::QpSettings{}.feasibility_tol;
  auto& c0 = wbc.level<0>().constraint<0>();
  c0.D << 0, 0, 2, 0;  // ‖d‖ = 2
  c0.upper << 3.0;
  c0.lower << 3.0 + 0.5 * tol * 2.0;
  ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  EXPECT_FALSE(wbc.result().levels[0].constraints_dropped);
  EXPECT_NEAR(wbc.x()(2), 1.5, tol * (1.0 + 1.5));
  c0.lower << 3.0 + 4.0 * tol * 2.0;
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::Infeasible);
  EXPECT_EQ(wbc.result().failed_level, 0);
  EXPECT_TRUE(wbc.result().levels[0].constraints_dropped);
  EXPECT_NEAR(wbc.x()(2), 1.0, 1e-12);
}

}  // namespace
