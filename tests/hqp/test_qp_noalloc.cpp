// solve() never touches the heap: Eigen's run-time malloc check plus a counting
// global operator new around cold, warm, phase-1 and infeasible solves.
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "hqp/active_set_qp.hpp"
#include "support/brute_force_qp.hpp"
#include "support/allocation_counter.hpp"

using hqp::testing::g_counting;
using hqp::testing::g_news;

namespace {

using Qp = hqp::ActiveSetQp<30, 15, 6, 48>;

TEST(QpNoAlloc, SolveDoesNotAllocate) {
  std::mt19937 rng(21);
  static Qp qp;  // the solver object itself may live anywhere; only solve() is checked
  int solves = 0;
  for (int k = 0; k < 10; ++k) {
    const bool infeasible = k % 5 == 4;
    const auto p = hqp::testing::makeRandomQp(rng, 30, 15, 6, 48, k % 2 ? 10 : -1, 0.5, false,
                                              infeasible);
    hqp::testing::loadInto(qp, p);
    const Qp::VectorX hint = p.x0;
    g_news = 0;
    g_counting = true;
    Eigen::internal::set_is_malloc_allowed(false);
    qp.solve(false);            // cold (phase 1 from the min-norm point)
    qp.solve(true);             // warm
    qp.solve(hint, false);      // from a feasible hint
    qp.b()(0) += 0.1;
    qp.solve(true);             // warm, perturbed
    Eigen::internal::set_is_malloc_allowed(true);
    g_counting = false;
    EXPECT_EQ(g_news.load(), 0) << k;
    solves += 4;
  }
  EXPECT_EQ(solves, 40);
  // The counter works: an allocation while counting is seen.
  g_counting = true;
  auto* v = new std::vector<int>(10);
  g_counting = false;
  EXPECT_GE(g_news.load(), 1);
  delete v;
}

}  // namespace
