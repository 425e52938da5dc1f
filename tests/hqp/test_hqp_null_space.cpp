// Task, Constraint, Level stacking and the COD null space (no QP involved).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

#include "hqp/constraint.hpp"
#include "hqp/detail/householder_strips.hpp"
#include "hqp/level.hpp"
#include "hqp/null_space.hpp"
#include "hqp/task.hpp"

namespace {

Eigen::MatrixXd randomMatrix(int r, int c, std::mt19937& g) {
  std::normal_distribution<double> nd(0.0, 1.0);
  Eigen::MatrixXd M(r, c);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c; ++j) M(i, j) = nd(g);
  return M;
}

// Rank-k matrix r x c.
Eigen::MatrixXd randomRank(int r, int c, int k, std::mt19937& g) {
  if (k == 0) return Eigen::MatrixXd::Zero(r, c);
  return randomMatrix(r, k, g) * randomMatrix(k, c, g);
}

// rank and null space by SVD, the independent reference.
int svdRank(const Eigen::MatrixXd& M, double cut) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
  int k = 0;
  for (Eigen::Index i = 0; i < svd.singularValues().size(); ++i) k += svd.singularValues()(i) > cut;
  return k;
}

}  // namespace

TEST(NullSpace, BasisRankProjectorRotatedMatrix) {
  std::mt19937 g(7);
  constexpr int MaxR = 8, MaxC = 10;
  hqp::NullSpace<MaxR, MaxC> ns;
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int r = 1 + static_cast<int>(g() % MaxR);
    const int c = 1 + static_cast<int>(g() % MaxC);
    const int k = static_cast<int>(g() % (std::min(r, c) + 1));
    const Eigen::MatrixXd M = randomRank(r, c, k, g);
    ns.computeRelative(M, 1e-9);
    const double scale = M.rowwise().norm().maxCoeff();
    ASSERT_EQ(ns.rank(), svdRank(M, 1e-9 * std::max(scale, 1e-300))) << "trial " << trial;
    ASSERT_EQ(ns.rank(), k);
    ASSERT_EQ(ns.dim(), c - k);

    hqp::MaxMatrix<MaxC, MaxC> Z;
    ns.basis(Z);
    ASSERT_EQ(Z.rows(), c);
    ASSERT_EQ(Z.cols(), c - k);
    if (c - k > 0) {
      EXPECT_LT((Z.transpose() * Z - Eigen::MatrixXd::Identity(c - k, c - k)).norm(), 1e-12);
      EXPECT_LT((M * Z).norm(), 1e-10 * (1.0 + M.norm()));
    }
    // N = Z Zᵀ = I − M⁺ M (pseudo-inverse by SVD).
    hqp::MaxMatrix<MaxC, MaxC> N;
    ns.projector(N);
    const Eigen::MatrixXd Mp = M.completeOrthogonalDecomposition().pseudoInverse();
    const Eigen::MatrixXd Nref =
        k == 0 ? Eigen::MatrixXd::Identity(c, c) : Eigen::MatrixXd(Eigen::MatrixXd::Identity(c, c) - Mp * M);
    EXPECT_LT((N - Nref).norm(), 1e-9) << "trial " << trial;

    // rotatedMatrix == M Q (Q applied to the identity), columns ≥ rank ≈ 0.
    Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(c, c);
    ns.applyQOnTheRight(Q);
    EXPECT_LT((Q.transpose() * Q - Eigen::MatrixXd::Identity(c, c)).norm(), 1e-12);
    hqp::MaxMatrix<MaxR, MaxC> MQ;
    ns.rotatedMatrix(MQ);
    EXPECT_LT((MQ - M * Q).norm(), 1e-10 * (1.0 + M.norm())) << "trial " << trial;
    EXPECT_TRUE((MQ.rightCols(c - k).array() == 0.0).all());
    ++checked;
  }
  EXPECT_EQ(checked, 200);
}

// Y Q and Y Qᵀ by 8-row strips (a last strip of 1–4 rows at its own height) against Eigen's
// own Householder sequence (a dynamic Y takes that path), for row counts that fill strips,
// leave 1, 2, 3, 4 or 5–7 rows over; and the in-place strip product Y Zᵀ against Eigen's
// product.
TEST(NullSpace, QOnTheRightAndStripProductMatchEigen) {
  std::mt19937 g(11);
  constexpr int MaxR = 12, MaxC = 14, MaxY = 24;
  hqp::NullSpace<MaxR, MaxC> ns;
  using Fixed = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, MaxY, MaxC>;
  for (int trial = 0; trial < 300; ++trial) {
    const int r = 1 + static_cast<int>(g() % MaxR);
    const int c = 1 + static_cast<int>(g() % MaxC);
    const int k = static_cast<int>(g() % (std::min(r, c) + 1));
    ns.computeRelative(randomRank(r, c, k, g), 1e-9);
    Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(c, c);
    ns.applyQOnTheRight(Q);  // Eigen's householderSequence
    const int rows = 1 + trial % MaxY;
    const Eigen::MatrixXd Y0 = randomMatrix(rows, c, g);
    Fixed Y = Y0;
    ns.applyQTransposeOnTheRight(Y);
    EXPECT_LT((Y - Y0 * Q.transpose()).norm(), 1e-12 * (1.0 + Y0.norm()))
        << "trial " << trial << ", " << rows << " rows";
    Fixed Yq = Y0;
    ns.applyQOnTheRight(Yq);
    EXPECT_LT((Yq - Y0 * Q).norm(), 1e-12 * (1.0 + Y0.norm()))
        << "trial " << trial << ", " << rows << " rows";

    const int n = 1 + static_cast<int>(g() % c);
    const Eigen::MatrixXd Zt = randomMatrix(n, c, g);
    Fixed P = Y0;
    hqp::detail::multiplyRowStrips<MaxC>(P, P, rows, c, Zt, n);  // in place
    EXPECT_LT((P.rightCols(n) - Y0 * Zt.transpose()).norm(), 1e-12 * (1.0 + Y0.norm() * Zt.norm()))
        << "trial " << trial << ", " << rows << " rows, n = " << n;
    Fixed O = Fixed::Zero(rows, c);
    hqp::detail::multiplyRowStrips<MaxC>(Y0, O, rows, c, Zt, n);
    EXPECT_EQ(O.rightCols(n), P.rightCols(n)) << "out of place, trial " << trial;
  }
}

TEST(NullSpace, ThresholdCutsTinyDirections) {
  // Row 2 = row 0 + 1e-13 · noise: rank 2 with a relative tolerance of 1e-9, 3 without.
  std::mt19937 g(3);
  Eigen::MatrixXd M = randomMatrix(3, 5, g);
  M.row(2) = M.row(0) + 1e-13 * randomMatrix(1, 5, g);
  hqp::NullSpace<3, 5> ns;
  ns.computeRelative(M, 1e-9);
  EXPECT_EQ(ns.rank(), 2);
  ns.compute(M, 0.0);
  EXPECT_EQ(ns.rank(), 3);
  ns.compute(Eigen::MatrixXd::Zero(3, 5), 0.0);  // all-zero task: no rank at all
  EXPECT_EQ(ns.rank(), 0);
  EXPECT_EQ(ns.dim(), 5);
}

TEST(Level, StacksTasksAndConstraintsByPosition) {
  constexpr int N = 5;
  using L = hqp::Level<N, hqp::TaskList<hqp::Task<2, N>, hqp::Task<3, N>>,
                       hqp::ConstraintList<hqp::Constraint<1, N>, hqp::Constraint<4, N>>>;
  static_assert(L::task_rows == 5 && L::constraint_rows == 5);
  static_assert(L::num_tasks == 2 && L::num_constraints == 2);
  static_assert(L::task_offsets[1] == 2 && L::constraint_offsets[1] == 1);
  using L2 = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>>;
  static_assert(L2::constraint_rows == 0);

  L level;
  std::mt19937 g(11);
  level.task<0>().A = randomMatrix(2, N, g);
  level.task<0>().b.setConstant(1.0);
  level.task<0>().setWeight(4.0);
  level.task<1>().A = randomMatrix(3, N, g);
  level.task<1>().b.setConstant(2.0);
  level.constraint<0>().D = randomMatrix(1, N, g);
  level.constraint<0>().setUpperBound(Eigen::Matrix<double, 1, 1>(3.0));
  level.constraint<1>().D = randomMatrix(4, N, g);
  level.constraint<1>().lower.setConstant(-1.0);
  level.constraint<1>().upper.setConstant(1.0);

  Eigen::Matrix<double, 7, N> A = Eigen::Matrix<double, 7, N>::Zero();
  Eigen::Matrix<double, 7, 1> b = Eigen::Matrix<double, 7, 1>::Zero(), w = b;
  level.stackTasks(A, b, w, 1);
  EXPECT_TRUE(A.row(0).isZero());
  EXPECT_EQ(A.middleRows(1, 2), level.task<0>().A);
  EXPECT_EQ(A.middleRows(3, 3), level.task<1>().A);
  EXPECT_TRUE(A.row(6).isZero());
  EXPECT_EQ(b.segment(1, 5), (Eigen::VectorXd(5) << 1, 1, 2, 2, 2).finished());
  EXPECT_EQ(w.segment(1, 5), (Eigen::VectorXd(5) << 4, 4, 1, 1, 1).finished());

  Eigen::Matrix<double, 5, N> D;
  Eigen::Matrix<double, 5, 1> lo, up;
  level.stackConstraints(D, lo, up, 0);
  EXPECT_EQ(D.topRows(1), level.constraint<0>().D);
  EXPECT_EQ(D.bottomRows(4), level.constraint<1>().D);
  EXPECT_EQ(lo(0), -hqp::kInf);
  EXPECT_EQ(up(0), 3.0);
  EXPECT_EQ(lo(3), -1.0);
  EXPECT_EQ(up(4), 1.0);

  Eigen::Matrix<double, N, 1> x = Eigen::Matrix<double, N, 1>::Constant(0.5);
  const double expected = (level.task<0>().A * x - level.task<0>().b).squaredNorm() +
                          (level.task<1>().A * x - level.task<1>().b).squaredNorm();
  EXPECT_DOUBLE_EQ(level.residual(x), expected);
  // violation(): D x above the upper bound by a known amount
  hqp::Constraint<1, N> c;
  c.D.setOnes();
  c.setUpperBound(Eigen::Matrix<double, 1, 1>(2.0));
  EXPECT_DOUBLE_EQ(c.violation(x), 0.5);
}
