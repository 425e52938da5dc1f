// Warm start: sequences of slightly perturbed problems; warm and cold solves
// must agree (the warm start only changes the path, not the answer).
#include <gtest/gtest.h>

#include <random>

#include "hqp/active_set_qp.hpp"
#include "support/brute_force_qp.hpp"

namespace {

using Qp = hqp::ActiveSetQp<30, 15, 6, 48>;

TEST(QpWarm, PerturbedSequencesMatchColdStarts) {
  std::mt19937 rng(99);
  std::normal_distribution<double> N(0.0, 1.0);
  hqp::QpSettings settings;
  settings.max_iterations = 500;
  Qp warm(settings), cold(settings);
  int warm_iters = 0, cold_iters = 0, steps = 0;
  for (int seq = 0; seq < 20; ++seq) {
    const bool rankdef = seq % 2 == 1;
    auto p = hqp::testing::makeRandomQp(rng, 30, 15, 6, 48, rankdef ? 10 : -1, 0.5);
    warm.resetWorkingSet();
    for (int step = 0; step < 30; ++step) {
      // Perturb the data slightly, as between two control ticks.
      for (int i = 0; i < p.b.size(); ++i) p.b(i) += 0.02 * N(rng);
      for (int i = 0; i < p.A.rows(); ++i)
        for (int j = 0; j < p.A.cols(); ++j) p.A(i, j) += 1e-3 * N(rng);
      // Move the known feasible point and the constraints with it (stays feasible).
      const Eigen::VectorXd dx = 0.01 * Eigen::VectorXd::NullaryExpr(30, [&] { return N(rng); });
      p.x0 += dx;
      const Eigen::VectorXd shift = p.C * dx;
      p.lower += shift;
      p.upper += shift;
      p.e = p.E * p.x0;
      hqp::testing::loadInto(warm, p);
      hqp::testing::loadInto(cold, p);
      const auto sw = warm.solve(true);
      const auto sc = cold.solve(false);
      ASSERT_EQ(sc, hqp::QpStatus::Optimal) << seq << " " << step;
      ASSERT_EQ(sw, hqp::QpStatus::Optimal) << seq << " " << step;
      EXPECT_NEAR(warm.objective(), cold.objective(), 1e-9 * (1.0 + cold.objective()));
      if (!rankdef) {  // unique optimum: the points agree
        EXPECT_LE((warm.x() - cold.x()).cwiseAbs().maxCoeff(), 1e-9) << seq << " " << step;
      }
      warm_iters += warm.iterations();
      cold_iters += cold.iterations();
      ++steps;
    }
  }
  // The warm start must actually save work.
  EXPECT_LT(warm_iters, cold_iters / 3);
  RecordProperty("warm_iterations_per_solve", warm_iters / steps);
  RecordProperty("cold_iterations_per_solve", cold_iters / steps);
}

TEST(QpWarm, StaleWorkingSetAfterLargeChangeIsRepaired) {
  std::mt19937 rng(5);
  Qp warm, cold;
  warm.settings().max_iterations = cold.settings().max_iterations = 500;
  for (int k = 0; k < 20; ++k) {
    // Unrelated problems one after another: the previous working set is useless
    // (often infeasible or dependent) and must be dropped.
    const auto p = hqp::testing::makeRandomQp(rng, 30, 15, 6, 48, -1, 0.5);
    hqp::testing::loadInto(warm, p);
    hqp::testing::loadInto(cold, p);
    ASSERT_EQ(warm.solve(true), hqp::QpStatus::Optimal);
    ASSERT_EQ(cold.solve(false), hqp::QpStatus::Optimal);
    EXPECT_LE((warm.x() - cold.x()).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(QpWarm, FeasibleHintSkipsPhaseOneAndGivesSameAnswer) {
  std::mt19937 rng(8);
  Qp a, b;
  a.settings().max_iterations = b.settings().max_iterations = 500;
  for (int k = 0; k < 20; ++k) {
    const auto p = hqp::testing::makeRandomQp(rng, 30, 15, 6, 48, -1, 0.5);
    hqp::testing::loadInto(a, p);
    hqp::testing::loadInto(b, p);
    const Qp::VectorX hint = p.x0;  // feasible by construction
    ASSERT_EQ(a.solve(hint, false), hqp::QpStatus::Optimal);
    ASSERT_EQ(b.solve(false), hqp::QpStatus::Optimal);
    EXPECT_LE((a.x() - b.x()).cwiseAbs().maxCoeff(), 1e-9);
    // An infeasible hint is ignored.
    const Qp::VectorX bad = Qp::VectorX::Constant(30, 100.0);
    ASSERT_EQ(a.solve(bad, false), hqp::QpStatus::Optimal);
    EXPECT_LE((a.x() - b.x()).cwiseAbs().maxCoeff(), 1e-9);
  }
}

}  // namespace
