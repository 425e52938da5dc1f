// Random property tests of ActiveSetQp against an enumeration reference (small
// problems) and against the KKT conditions computed here from x and the
// multipliers (larger problems).
#include <gtest/gtest.h>

#include <random>

#include "hqp/active_set_qp.hpp"
#include "support/brute_force_qp.hpp"
#include "support/kkt_error.hpp"

namespace {

using SmallQp = hqp::ActiveSetQp<8, 12, 4, 10>;
using LargeQp = hqp::ActiveSetQp<30, 30, 10, 60>;

using hqp::testing::kkt;
using hqp::testing::KktError;

TEST(QpRandom, SmallProblemsMatchBruteForce) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> Un(1, 8), Um(0, 10), Umi(0, 10), U100(0, 99);
  SmallQp qp;
  int n_feasible = 0, n_infeasible = 0, n_rankdef = 0, n_active = 0;
  for (int trial = 0; trial < 1200; ++trial) {
    const int n = Un(rng);
    const int m = std::min(Um(rng), 12);
    const int me = std::min(n - 1, std::uniform_int_distribution<int>(0, 3)(rng));
    const int mi = Umi(rng);
    const bool rankdef = U100(rng) < 40 && m > 1 && n > 1;
    const int rank_a = rankdef ? std::uniform_int_distribution<int>(0, std::min(m, n) - 1)(rng) : -1;
    const bool redundant = U100(rng) < 15;
    const bool infeasible = U100(rng) < 10;
    // Keep the enumeration small: at most 5 rows bounded on both sides on average.
    const auto p = hqp::testing::makeRandomQp(rng, n, m, me, mi, rank_a, 0.35, redundant,
                                              infeasible);
    hqp::testing::loadInto(qp, p);
    const hqp::QpStatus st = qp.solve(false);
    const auto ref = hqp::testing::bruteForceQp(p.A, p.b, p.E, p.e, p.C, p.lower, p.upper);
    ASSERT_TRUE(qp.x().allFinite()) << trial;
    if (!ref.feasible) {
      EXPECT_EQ(st, hqp::QpStatus::Infeasible) << "trial " << trial;
      ++n_infeasible;
      continue;
    }
    ++n_feasible;
    n_rankdef += rankdef;
    n_active += qp.numActive() > 0;
    ASSERT_EQ(st, hqp::QpStatus::Optimal) << "trial " << trial << " n=" << n << " m=" << m
                                          << " me=" << me << " mi=" << mi;
    EXPECT_NEAR(qp.objective(), ref.objective, 1e-9 * (1.0 + std::abs(ref.objective)))
        << "trial " << trial;
    const KktError k = kkt(qp, p);
    EXPECT_LE(k.primal, 1e-9) << trial;
  }
  EXPECT_GE(n_feasible, 1000);
  EXPECT_GT(n_infeasible, 20);
  EXPECT_GT(n_rankdef, 200);
  EXPECT_GT(n_active, 500);
}

TEST(QpRandom, LargeProblemsSatisfyKkt) {
  std::mt19937 rng(777);
  std::uniform_int_distribution<int> U100(0, 99);
  hqp::QpSettings settings;
  settings.max_iterations = 1000;  // cold from far away: phase 1 may visit a vertex (31 rows)
  LargeQp qp(settings);
  int max_iter = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 30;
    const int m = std::uniform_int_distribution<int>(5, 30)(rng);
    const int me = std::uniform_int_distribution<int>(0, 8)(rng);
    const int mi = std::uniform_int_distribution<int>(0, 60 - me)(rng);
    const int rank_a = U100(rng) < 50 ? std::min(m, 20) - 3 : -1;
    const auto p = hqp::testing::makeRandomQp(rng, n, m, me, mi, rank_a, 0.5);
    hqp::testing::loadInto(qp, p);
    ASSERT_EQ(qp.solve(false), hqp::QpStatus::Optimal) << trial;
    max_iter = std::max(max_iter, qp.iterations());
    const KktError k = kkt(qp, p);
    EXPECT_LE(k.stationarity, 1e-9) << trial;
    EXPECT_LE(k.primal, 1e-9) << trial;
    EXPECT_LE(k.dual, 1e-9) << trial;
    EXPECT_LE(k.complementarity, 1e-9) << trial;
  }
  RecordProperty("max_iterations", max_iter);
}

}  // namespace
