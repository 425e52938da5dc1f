// Warm start: sequences of slightly perturbed problems; warm and cold solves
// must agree (the warm start only changes the path, not the answer).
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "hqp/active_set_qp.hpp"
#include "support/brute_force_qp.hpp"

namespace {

using Qp = hqp::ActiveSetQp<30, 15, 6, 48>;

// A solve's working set (rows and sides), in the form setStartRows() takes.
struct ActiveRows {
  std::vector<int> row;
  bool upper[64] = {};
  int count() const { return static_cast<int>(row.size()); }
};
ActiveRows activeRowsOf(const Qp& qp) {
  ActiveRows a;
  for (int k = 0; k < qp.numActive(); ++k) {
    a.row.push_back(qp.activeRow(k));
    a.upper[k] = qp.activeAtUpper(k);
  }
  return a;
}

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

// setStartRows(): the rows at their bounds at a feasible hint become the first working set.
// Expectations from cold solves of the same problems (the start changes the path only).
TEST(QpWarm, StartRowsAtAFeasibleHintGiveTheColdAnswerInFewerIterations) {
  std::mt19937 rng(21);
  Qp start, plain, cold;
  start.settings().max_iterations = plain.settings().max_iterations =
      cold.settings().max_iterations = 500;
  int with_rows = 0, without_rows = 0, tried = 0;
  for (int k = 0; k < 20; ++k) {
    auto p = hqp::testing::makeRandomQp(rng, 30, 15, 6, 48, k % 2 == 1 ? 10 : -1, 0.5);
    // Put the known feasible point x0 on the lower bound of every third row: those rows are
    // at their bounds at the hint, the others strictly inside or farther.
    const Eigen::VectorXd cx = p.C * p.x0;
    std::vector<int> rows;
    std::vector<char> upper_side;
    for (int j = 0; j < 48; j += 3) {
      p.lower(j) = cx(j);
      rows.push_back(j);
      upper_side.push_back(0);
    }
    // Rows not at their bounds at the hint (and a row index out of range) must be ignored.
    rows.push_back(1);
    upper_side.push_back(1);
    rows.push_back(99);
    upper_side.push_back(0);
    bool up[64];
    for (std::size_t i = 0; i < rows.size(); ++i) up[i] = upper_side[i] != 0;
    hqp::testing::loadInto(start, p);
    hqp::testing::loadInto(plain, p);
    hqp::testing::loadInto(cold, p);
    const Qp::VectorX hint = p.x0;
    start.resetWorkingSet();
    start.setStartRows(static_cast<int>(rows.size()), rows.data(), up);
    ASSERT_EQ(start.solve(hint, false), hqp::QpStatus::Optimal) << k;
    ASSERT_EQ(plain.solve(hint, false), hqp::QpStatus::Optimal) << k;
    ASSERT_EQ(cold.solve(false), hqp::QpStatus::Optimal) << k;
    EXPECT_NEAR(start.objective(), cold.objective(), 1e-9 * (1.0 + cold.objective())) << k;
    if (k % 2 == 0) EXPECT_LE((start.x() - cold.x()).cwiseAbs().maxCoeff(), 1e-9) << k;
    // The start rows are used once: the next solve from the hint without them is plain's.
    ASSERT_EQ(start.solve(hint, false), hqp::QpStatus::Optimal) << k;
    EXPECT_EQ(start.iterations(), plain.iterations()) << k;
    // From the cold optimum with its active set as start rows: nothing left to change.
    if (cold.numActive() >= 3) {
      const ActiveRows act = activeRowsOf(cold);
      const Qp::VectorX xstar = cold.x();
      start.setStartRows(act.count(), act.row.data(), act.upper);
      ASSERT_EQ(start.solve(xstar, false), hqp::QpStatus::Optimal) << k;
      ASSERT_EQ(plain.solve(xstar, false), hqp::QpStatus::Optimal) << k;
      EXPECT_NEAR(start.objective(), cold.objective(), 1e-9 * (1.0 + cold.objective())) << k;
      with_rows += start.iterations();
      without_rows += plain.iterations();
      ++tried;
    }
  }
  ASSERT_GT(tried, 5);
  // Without them every active row is re-added as a blocking row, one iteration each.
  EXPECT_LT(with_rows, without_rows / 2) << with_rows << " vs " << without_rows;
}

// setStartRows() is for the next solve only, also when that solve stops before its first
// working set (crossed bounds, invalid input): the solve after it is a plain one. Expectations
// from a solver that never had start rows.
TEST(QpWarm, StartRowsAreDroppedBySolvesThatStopEarly) {
  std::mt19937 rng(34);
  Qp start, plain, cold;
  start.settings().max_iterations = plain.settings().max_iterations =
      cold.settings().max_iterations = 500;
  int tried = 0;
  for (int k = 0; k < 20; ++k) {
    const auto p = hqp::testing::makeRandomQp(rng, 30, 15, 6, 48, -1, 0.5);
    hqp::testing::loadInto(cold, p);
    ASSERT_EQ(cold.solve(false), hqp::QpStatus::Optimal) << k;
    if (cold.numActive() < 3) continue;
    const ActiveRows act = activeRowsOf(cold);
    const Qp::VectorX xstar = cold.x();
    hqp::testing::loadInto(plain, p);
    ASSERT_EQ(plain.solve(xstar, false), hqp::QpStatus::Optimal) << k;
    // The start rows matter here: with them the solve takes fewer iterations.
    hqp::testing::loadInto(start, p);
    start.setStartRows(act.count(), act.row.data(), act.upper);
    ASSERT_EQ(start.solve(xstar, false), hqp::QpStatus::Optimal) << k;
    ASSERT_LT(start.iterations(), plain.iterations()) << k;
    for (int early = 0; early < 2; ++early) {
      hqp::testing::loadInto(start, p);
      start.setStartRows(act.count(), act.row.data(), act.upper);
      if (early == 0) {
        start.lower()(0) = 1.0;  // an empty interval
        start.upper()(0) = 0.0;
        EXPECT_EQ(start.solve(xstar, false), hqp::QpStatus::Infeasible) << k;
      } else {
        start.A()(0, 0) = std::numeric_limits<double>::quiet_NaN();
        EXPECT_EQ(start.solve(xstar, false), hqp::QpStatus::InvalidInput) << k;
      }
      hqp::testing::loadInto(start, p);
      ASSERT_EQ(start.solve(xstar, false), hqp::QpStatus::Optimal) << k << " " << early;
      EXPECT_EQ(start.iterations(), plain.iterations()) << k << " " << early;
      EXPECT_LE((start.x() - plain.x()).cwiseAbs().maxCoeff(), 1e-12) << k << " " << early;
    }
    ++tried;
  }
  ASSERT_GT(tried, 5);
}

}  // namespace
