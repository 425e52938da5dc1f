// Deadline-aware solving (HqpSettings::budget_us / budget_iterations): a cut leaves the levels
// above it exactly as the hierarchy truncated to them solves them, x stays finite, a budget
// large enough changes nothing, and solve() still never allocates.
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <random>

#include "hqp/hqp_wbc.hpp"
#include "support/allocation_counter.hpp"

using hqp::testing::g_news;

namespace {

constexpr int N = 8;
// Level 0: 3 task rows, 2 bounds; level 1: 3 task rows pushed against 2 bounds of its own
// (so its QP needs ≥ 2 working-set changes from a cold start); level 2: 4 task rows.
using L0 = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>, hqp::ConstraintList<hqp::Constraint<2, N>>>;
using L1 = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>, hqp::ConstraintList<hqp::Constraint<2, N>>>;
using L2 = hqp::Level<N, hqp::TaskList<hqp::Task<4, N>>>;
using Full = hqp::HqpWbc<N, L0, L1, L2>;
using Top1 = hqp::HqpWbc<N, L0>;
using Top2 = hqp::HqpWbc<N, L0, L1>;

struct Data {
  Eigen::Matrix<double, 3, N> A0, A1;
  Eigen::Matrix<double, 3, 1> b0, b1;
  Eigen::Matrix<double, 2, N> D0, D1;
  Eigen::Matrix<double, 4, N> A2;
  Eigen::Matrix<double, 4, 1> b2;
};

Data makeData(unsigned seed) {
  std::mt19937 g(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  Data d;
  d.A0 = d.A0.unaryExpr([&](double) { return nd(g); });
  d.A1 = d.A1.unaryExpr([&](double) { return nd(g); });
  d.A2 = d.A2.unaryExpr([&](double) { return nd(g); });
  d.D0 = d.D0.unaryExpr([&](double) { return nd(g); });
  d.b0 = d.b0.unaryExpr([&](double) { return nd(g); });
  d.b2 = d.b2.unaryExpr([&](double) { return nd(g); });
  // Level 1's own rows are its first two task rows, bounded well below their targets.
  d.D1 = d.A1.topRows<2>();
  d.b1 = d.b1.unaryExpr([&](double) { return 10.0 + nd(g); });
  return d;
}

template <class W>
void fill(W& w, const Data& d) {
  auto& t0 = w.template level<0>().template task<0>();
  t0.A = d.A0;
  t0.b = d.b0;
  auto& c0 = w.template level<0>().template constraint<0>();
  c0.D = d.D0;
  c0.lower.setConstant(-100.0);  // inactive: level 0 is its free step (0 iterations)
  c0.upper.setConstant(100.0);
  if constexpr (W::num_levels > 1) {
    auto& t1 = w.template level<1>().template task<0>();
    t1.A = d.A1;
    t1.b = d.b1;
    w.template level<1>().template constraint<0>().setUpperBound(Eigen::Vector2d(1.0, 1.0));
    w.template level<1>().template constraint<0>().D = d.D1;
  }
  if constexpr (W::num_levels > 2) {
    auto& t2 = w.template level<2>().template task<0>();
    t2.A = d.A2;
    t2.b = d.b2;
  }
}

// Static storage: the solvers are large.
Full g_full, g_plain;
Top1 g_top1;
Top2 g_top2;

TEST(HqpBudget, TinyTimeBudgetKeepsLevelZeroExact) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Data d = makeData(seed);
    g_full.resetWarmStart();
    g_top1.resetWarmStart();
    g_full.setBudget(1e-6, 0);  // 1 ps: over before level 1 can start
    fill(g_full, d);
    fill(g_top1, d);
    const auto s = g_full.solve();
    ASSERT_EQ(g_top1.solve(), hqp::QpStatus::Optimal) << seed;
    const auto& r = g_full.result();
    EXPECT_EQ(s, hqp::QpStatus::BudgetCut) << seed;
    EXPECT_EQ(r.cut_level, 1) << seed;
    EXPECT_EQ(r.failed_level, 1) << seed;
    EXPECT_EQ(r.levels[0].status, hqp::QpStatus::Optimal) << seed;
    EXPECT_EQ(r.levels[1].status, hqp::QpStatus::BudgetCut) << seed;
    EXPECT_EQ(r.levels[2].status, hqp::QpStatus::BudgetCut) << seed;
    EXPECT_FALSE(r.higher_level_degraded) << seed;
    ASSERT_TRUE(g_full.x().allFinite()) << seed;
    EXPECT_LE((g_full.x() - g_top1.x()).norm(), 1e-10 * (1.0 + g_top1.x().norm())) << seed;
    // The cut levels' residuals are reported at the final x.
    const Eigen::Matrix<double, 4, 1> e2 = d.A2 * g_full.x() - d.b2;
    EXPECT_NEAR(r.levels[2].residual, e2.squaredNorm(), 1e-9 * (1.0 + e2.squaredNorm())) << seed;
  }
}

// Both hierarchies cold on d, g_full with an iteration budget of 1; returns g_top2's status.
hqp::QpStatus solveWithIterationBudgetOne(const Data& d) {
  g_full.resetWarmStart();
  g_top2.resetWarmStart();
  g_full.setBudget(0.0, 1);
  fill(g_full, d);
  fill(g_top2, d);
  g_full.solve();
  return g_top2.solve();
}

TEST(HqpBudget, IterationBudgetCutsTheLevelThatWouldExceedIt) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Data d = makeData(seed);
    ASSERT_EQ(solveWithIterationBudgetOne(d), hqp::QpStatus::Optimal) << seed;
    const auto& r = g_full.result();
    // Level 1 starts (nothing spent, no history) and needs ≥ 2 iterations: level 2 is cut.
    ASSERT_EQ(r.levels[0].iterations, 0) << seed;
    ASSERT_GE(r.levels[1].iterations, 2) << seed;
    EXPECT_EQ(r.cut_level, 2) << seed;
    EXPECT_EQ(r.status, hqp::QpStatus::BudgetCut) << seed;
    EXPECT_EQ(r.levels[1].status, hqp::QpStatus::Optimal) << seed;
    ASSERT_TRUE(g_full.x().allFinite()) << seed;
    EXPECT_LE((g_full.x() - g_top2.x()).norm(), 1e-10 * (1.0 + g_top2.x().norm())) << seed;
    // The next solve predicts level 1's cost from this one (≥ 2 > 1): level 1 is cut too.
    fill(g_full, d);
    g_full.solve();
    EXPECT_EQ(g_full.result().cut_level, 1) << seed;
    fill(g_top1, d);
    g_top1.resetWarmStart();
    g_top1.solve();
    EXPECT_LE((g_full.x() - g_top1.x()).norm(), 1e-10 * (1.0 + g_top1.x().norm())) << seed;
    // The cut halves level 1's estimate: it is tried again within a few solves.
    bool retried = false;
    for (int k = 0; k < 8 && !retried; ++k) {
      fill(g_full, d);
      g_full.solve();
      retried = g_full.result().cut_level != 1;
    }
    EXPECT_TRUE(retried) << seed;
  }
}

TEST(HqpBudget, LargeBudgetChangesNothing) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Data d = makeData(seed);
    g_full.resetWarmStart();
    g_plain.resetWarmStart();
    g_full.setBudget(1e9, 1000000);
    g_plain.setBudget(0.0, 0);
    for (int tick = 0; tick < 3; ++tick) {  // warm starts included
      fill(g_full, d);
      fill(g_plain, d);
      const auto s = g_full.solve();
      EXPECT_EQ(s, g_plain.solve()) << seed;
      EXPECT_EQ(g_full.result().cut_level, -1) << seed;
      EXPECT_TRUE(g_full.x() == g_plain.x()) << seed;  // bit for bit
    }
  }
}

// HqpSettings::time_levels off: time_us is 0 on every level, and x, statuses, iterations and
// active sets are bit for bit those of a timed solve (warm sequences included).
TEST(HqpLevelTiming, OffGivesZeroTimesAndTheSameSolution) {
  EXPECT_TRUE(hqp::HqpSettings{}.time_levels);
  g_full.setBudget(0.0, 0);
  g_plain.setBudget(0.0, 0);
  g_full.setLevelTiming(false);
  g_plain.setLevelTiming(true);
  double timed = 0.0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Data d = makeData(seed);
    g_full.resetWarmStart();
    g_plain.resetWarmStart();
    for (int tick = 0; tick < 3; ++tick) {
      fill(g_full, d);
      fill(g_plain, d);
      const auto s = g_full.solve();
      EXPECT_EQ(s, g_plain.solve()) << seed;
      EXPECT_TRUE(g_full.x() == g_plain.x()) << seed;  // bit for bit
      for (std::size_t p = 0; p < 3; ++p) {
        const auto& a = g_full.result().levels[p];
        const auto& b = g_plain.result().levels[p];
        EXPECT_EQ(a.time_us, 0.0) << seed;
        EXPECT_EQ(a.status, b.status) << seed;
        EXPECT_EQ(a.iterations, b.iterations) << seed;
        ASSERT_EQ(a.num_active, b.num_active) << seed;
        for (int k = 0; k < a.num_active; ++k) EXPECT_EQ(a.active_row[k], b.active_row[k]) << seed;
        timed += b.time_us;
      }
    }
  }
  EXPECT_GT(timed, 0.0);  // the timed solver does measure
  g_full.setLevelTiming(true);
}

// The iteration budget needs no clock; the time budget still reads it (time_us stays 0).
TEST(HqpLevelTiming, BudgetsWorkWithTimingOff) {
  g_full.setLevelTiming(false);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Data d = makeData(seed);
    ASSERT_EQ(solveWithIterationBudgetOne(d), hqp::QpStatus::Optimal) << seed;
    const auto& r = g_full.result();
    ASSERT_GE(r.levels[1].iterations, 2) << seed;
    EXPECT_EQ(r.cut_level, 2) << seed;
    EXPECT_EQ(r.status, hqp::QpStatus::BudgetCut) << seed;
    EXPECT_LE((g_full.x() - g_top2.x()).norm(), 1e-10 * (1.0 + g_top2.x().norm())) << seed;
    // 1 ps: cut before level 1, and no level reports a time.
    g_full.resetWarmStart();
    g_full.setBudget(1e-6, 0);
    fill(g_full, d);
    EXPECT_EQ(g_full.solve(), hqp::QpStatus::BudgetCut) << seed;
    EXPECT_EQ(r.cut_level, 1) << seed;
    for (const auto& lr : r.levels) EXPECT_EQ(lr.time_us, 0.0) << seed;
  }
  g_full.setBudget(0.0, 0);
  g_full.setLevelTiming(true);
}

TEST(HqpBudget, CutSolveDoesNotAllocate) {
  const Data d = makeData(3);
  g_full.setBudget(1e-6, 0);
  fill(g_full, d);
  g_full.solve();
  const long before = g_news.load();
  Eigen::internal::set_is_malloc_allowed(false);
  for (int i = 0; i < 10; ++i) {
    fill(g_full, d);
    g_full.setBudget(i % 2 ? 1e-6 : 0.0, i % 3 ? 0 : 1);
    g_full.setKktResiduals(i % 4 < 2);  // the certificate's residuals allocate nothing either
    g_full.setLevelTiming(i % 5 < 3);
    g_full.solve();
  }
  Eigen::internal::set_is_malloc_allowed(true);
  g_full.setKktResiduals(false);
  g_full.setLevelTiming(true);
  EXPECT_EQ(g_news.load(), before);
  // The counter sees allocations at all.
  auto* p = new int(1);
  asm volatile("" : : "r"(p) : "memory");  // escapes: clang may not elide the pair
  EXPECT_GT(g_news.load(), before);
  delete p;
}

}  // namespace
