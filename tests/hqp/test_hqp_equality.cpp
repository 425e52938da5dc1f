// Equality-only hierarchies: HqpWbc == the closed-form recursive pseudo-inverse cascade
// (tests/support/reference_cascade.hpp), with rank-deficient and conflicting tasks.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>
#include <vector>

#include "hqp/hqp_wbc.hpp"
#include "support/reference_cascade.hpp"

namespace {

constexpr int N = 8;
using T2 = hqp::Task<2, N>;
using T3 = hqp::Task<3, N>;
using T4 = hqp::Task<4, N>;
using C2 = hqp::Constraint<2, N>;
// Four levels, 3 + (2 + 2) + 4 + 3 = 14 task rows for 8 variables: the lower levels
// run out of freedom and become least-squares compromises.
using L1 = hqp::Level<N, hqp::TaskList<T3>>;
using L2 = hqp::Level<N, hqp::TaskList<T2, T2>>;
using L3 = hqp::Level<N, hqp::TaskList<T4>>;
using L4 = hqp::Level<N, hqp::TaskList<T3>>;
using Wbc = hqp::HqpWbc<N, L1, L2, L3, L4>;
// The same with (never active) constraints: every level goes through the QP.
using L1c = hqp::Level<N, hqp::TaskList<T3>, hqp::ConstraintList<C2>>;
using L3c = hqp::Level<N, hqp::TaskList<T4>, hqp::ConstraintList<C2>>;
using WbcQp = hqp::HqpWbc<N, L1c, L2, L3c, L4>;

Eigen::MatrixXd randn(int r, int c, std::mt19937& g) {
  std::normal_distribution<double> nd(0.0, 1.0);
  Eigen::MatrixXd M(r, c);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c; ++j) M(i, j) = nd(g);
  return M;
}

// Random task data for one trial; `kind` selects full rank, rank deficiency inside a level,
// or conflicts with higher levels (rows of lower tasks copied from higher ones, other b).
struct Data {
  std::vector<Eigen::MatrixXd> A;  // per task, in level order: L1 t0, L2 t0, L2 t1, L3 t0, L4 t0
  std::vector<Eigen::VectorXd> b;
};

Data makeData(int kind, std::mt19937& g) {
  const int rows[] = {3, 2, 2, 4, 3};
  Data d;
  for (int t = 0; t < 5; ++t) {
    d.A.push_back(randn(rows[t], N, g));
    d.b.push_back(randn(rows[t], 1, g) * 3.0);
  }
  if (kind == 1) {
    d.A[0] = randn(3, 1, g) * randn(1, N, g);   // rank 1 top level
    d.A[3] = randn(4, 2, g) * randn(2, N, g);   // rank 2
  } else if (kind == 2) {
    d.A[1].row(0) = d.A[0].row(1);               // same row as level 1, different target
    d.A[3].topRows(2) = d.A[1];                  // level 3 repeats level 2's first task
    d.A[4].row(2) = 2.0 * d.A[0].row(0) - d.A[2].row(1);
  } else if (kind == 3) {
    d.A[2] = d.A[1];                             // two identical tasks inside level 2
    d.b[2] = d.b[1] + Eigen::VectorXd::Ones(2);  // with conflicting targets
    d.A[0].row(2).setZero();                     // a zero row
  }
  return d;
}

template <class W>
void fill(W& wbc, const Data& d) {
  wbc.template level<0>().template task<0>().A = d.A[0];
  wbc.template level<0>().template task<0>().b = d.b[0];
  wbc.template level<1>().template task<0>().A = d.A[1];
  wbc.template level<1>().template task<0>().b = d.b[1];
  wbc.template level<1>().template task<1>().A = d.A[2];
  wbc.template level<1>().template task<1>().b = d.b[2];
  wbc.template level<2>().template task<0>().A = d.A[3];
  wbc.template level<2>().template task<0>().b = d.b[3];
  wbc.template level<3>().template task<0>().A = d.A[4];
  wbc.template level<3>().template task<0>().b = d.b[4];
}

std::vector<hqp::testing::RefLevel> refLevels(const Data& d) {
  std::vector<hqp::testing::RefLevel> L(4);
  auto set = [](hqp::testing::RefLevel& l, Eigen::MatrixXd A, Eigen::VectorXd b) {
    l.A = std::move(A);
    l.b = std::move(b);
    l.D.resize(0, N);
    l.lower.resize(0);
    l.upper.resize(0);
  };
  set(L[0], d.A[0], d.b[0]);
  Eigen::MatrixXd A2(4, N);
  A2 << d.A[1], d.A[2];
  Eigen::VectorXd b2(4);
  b2 << d.b[1], d.b[2];
  set(L[1], A2, b2);
  set(L[2], d.A[3], d.b[3]);
  set(L[3], d.A[4], d.b[4]);
  return L;
}

}  // namespace

TEST(HqpEquality, MatchesPseudoInverseCascade) {
  std::mt19937 g(2024);
  static Wbc wbc;      // static: large object, keep it off the test's stack
  static WbcQp wbcqp;  // loose constraints: the QP path
  int trials = 0, deficient = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const int kind = trial % 4;
    const Data d = makeData(kind, g);
    const auto ref = hqp::testing::pseudoInverseCascade(refLevels(d), N);

    fill(wbc, d);
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
    EXPECT_LT((wbc.x() - ref.x).norm(), 1e-9 * (1.0 + ref.x.norm())) << "trial " << trial;
    int n = N;
    for (int p = 0; p < 4; ++p) {
      const auto& lr = wbc.result().levels[static_cast<size_t>(p)];
      EXPECT_EQ(lr.rank, ref.rank[static_cast<size_t>(p)]) << "trial " << trial << " level " << p;
      EXPECT_EQ(lr.variables, n);
      n -= lr.rank;
      EXPECT_EQ(lr.null_dim, n);
      EXPECT_NEAR(lr.residual, ref.residual[static_cast<size_t>(p)],
                  1e-9 * (1.0 + ref.residual[static_cast<size_t>(p)]));
      deficient += lr.rank < std::min(lr.variables, p == 1 ? 4 : (p == 2 ? 4 : 3));
    }

    fill(wbcqp, d);
    auto& c1 = wbcqp.level<0>().constraint<0>();
    c1.D = randn(2, N, g);
    c1.lower.setConstant(-1e6);
    c1.upper.setConstant(1e6);
    auto& c3 = wbcqp.level<2>().constraint<0>();
    c3.D = randn(2, N, g);
    c3.setUpperBound(Eigen::Vector2d::Constant(1e6));
    ASSERT_EQ(wbcqp.solve(), hqp::QpStatus::Optimal) << "trial " << trial;
    EXPECT_LT((wbcqp.x() - ref.x).norm(), 1e-9 * (1.0 + ref.x.norm())) << "trial " << trial;
    for (int p = 0; p < 4; ++p)
      EXPECT_NEAR(wbcqp.result().levels[static_cast<size_t>(p)].residual,
                  ref.residual[static_cast<size_t>(p)],
                  1e-9 * (1.0 + ref.residual[static_cast<size_t>(p)]));
    ++trials;
  }
  EXPECT_EQ(trials, 120);
  EXPECT_GT(deficient, 30);  // the rank-deficient/conflicting cases really occurred
}

TEST(HqpEquality, FullRankDimensionsShrink) {
  // Full-rank data: null-space dimensions 8 → 5 → 1 → 0 → 0.
  std::mt19937 g(5);
  static Wbc wbc;
  fill(wbc, makeData(0, g));
  ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  const int dims[] = {5, 1, 0, 0};
  for (int p = 0; p < 4; ++p) EXPECT_EQ(wbc.result().levels[static_cast<size_t>(p)].null_dim, dims[p]);
  // level 1 and 2 are met exactly (3 + 4 ≤ 8 rows, full rank)
  EXPECT_LT(wbc.result().levels[0].residual, 1e-20);
  EXPECT_LT(wbc.result().levels[1].residual, 1e-18);
  EXPECT_GT(wbc.result().levels[2].residual, 1e-6);
}

TEST(HqpEquality, WeightsWithinALevel) {
  // Two conflicting tasks in level 2 weighted 1 : 9 → the weighted compromise, which the
  // pseudo-inverse cascade reproduces on rows scaled by √w.
  std::mt19937 g(9);
  Data d = makeData(3, g);
  static Wbc wbc;
  fill(wbc, d);
  wbc.level<1>().task<1>().setWeight(9.0);
  ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  auto L = refLevels(d);
  L[1].A.bottomRows(2) *= 3.0;
  L[1].b.tail(2) *= 3.0;
  const auto ref = hqp::testing::pseudoInverseCascade(L, N);
  EXPECT_LT((wbc.x() - ref.x).norm(), 1e-9 * (1.0 + ref.x.norm()));
  EXPECT_NEAR(wbc.result().levels[1].objective, ref.residual[1], 1e-9 * (1.0 + ref.residual[1]));
  wbc.level<1>().task<1>().setWeight(1.0);
}
