// The certificate of HqpWbc::result() (multipliers and KKT residuals per level), checked
// against an independent KKT check of each level's problem written here:
//   min ½‖W_p^½ (A_p x − b_p)‖²  over  x ∈ x*_{p−1} + null([W^½A_0; …; W^½A_{p−1}]),
//   lower_i ≤ D_i x ≤ upper_i for the constraint rows i of levels ≤ p,
// with the null-space basis from an SVD here (not the solver's QR). Also: bounds of magnitude
// ≥ 1e20 are no bounds (bit-identical to ±inf), and the residuals switch.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "hqp/hqp_wbc.hpp"

namespace {

constexpr int N = 8;
// 3 + 3 + 4 task rows over 8 variables: levels of 8, 5 and 2 variables; the last one has
// full column rank (dual method by default, ActiveSetQp with setDualLastLevel(false)).
using L0 = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>, hqp::ConstraintList<hqp::Constraint<3, N>>>;
using L1 = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>, hqp::ConstraintList<hqp::Constraint<3, N>>>;
using L2 = hqp::Level<N, hqp::TaskList<hqp::Task<4, N>>, hqp::ConstraintList<hqp::Constraint<3, N>>>;
using Wbc = hqp::HqpWbc<N, L0, L1, L2>;
constexpr int kLevels = 3;
constexpr int kTaskRows[] = {3, 3, 4};
constexpr int kConRows = 3;  // per level
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Instance {
  Eigen::MatrixXd A[kLevels], D[kLevels];
  Eigen::VectorXd b[kLevels], w[kLevels], lo[kLevels], up[kLevels];
};

Instance makeInstance(unsigned seed) {
  std::mt19937 g(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> ud(0.0, 1.0);
  Instance in;
  for (int p = 0; p < kLevels; ++p) {
    const int r = kTaskRows[p];
    in.A[p] = Eigen::MatrixXd::NullaryExpr(r, N, [&] { return nd(g); });
    in.b[p] = Eigen::VectorXd::NullaryExpr(r, [&] { return 4.0 * nd(g); });  // pushes on the bounds
    in.w[p] = Eigen::VectorXd::NullaryExpr(r, [&] { return 0.5 + 1.5 * ud(g); });
    in.D[p] = Eigen::MatrixXd::NullaryExpr(kConRows, N, [&] { return nd(g); });
    in.lo[p].resize(kConRows);
    in.up[p].resize(kConRows);
    // The last level (2 variables left) gets wider bounds, else it is mostly infeasible.
    const double wide = p + 1 == kLevels ? 4.0 : 1.0;
    for (int i = 0; i < kConRows; ++i) {
      in.lo[p](i) = ud(g) < 0.3 ? -kInf : -wide * (0.5 + 2.0 * ud(g));
      in.up[p](i) = ud(g) < 0.3 ? kInf : wide * (0.5 + 2.0 * ud(g));
    }
  }
  return in;
}

void fill(Wbc& wbc, const Instance& in, int levels = kLevels) {
  auto set = [&](auto& level, int p) {
    auto& t = level.template task<0>();
    auto& c = level.template constraint<0>();
    if (p < levels) {
      t.A = in.A[p];
      t.b = in.b[p];
      t.weight = in.w[p];
      c.D = in.D[p];
      c.lower = in.lo[p];
      c.upper = in.up[p];
    } else {  // level left out: no task, no bound, so x stays x*_{levels−1}
      t.A.setZero();
      t.b.setZero();
      c.D = in.D[p];
      c.lower.setConstant(-kInf);
      c.upper.setConstant(kInf);
    }
  };
  set(wbc.level<0>(), 0);
  set(wbc.level<1>(), 1);
  set(wbc.level<2>(), 2);
}

// Stacked constraint rows of levels ≤ p.
Eigen::MatrixXd stackedD(const Instance& in, int p) {
  Eigen::MatrixXd D((p + 1) * kConRows, N);
  for (int q = 0; q <= p; ++q) D.middleRows(q * kConRows, kConRows) = in.D[q];
  return D;
}
// dropped[q]: level q was infeasible and its own rows were dropped (policy, docs/hqp.md): they
// bound no level any more.
double stackedBound(const Instance& in, int row, bool upper, const bool* dropped) {
  const int q = row / kConRows, i = row % kConRows;
  if (dropped[q]) return upper ? kInf : -kInf;
  return upper ? in.up[q](i) : in.lo[q](i);
}

// Orthonormal basis of null([W^½A_0; …; W^½A_{p−1}]) by SVD (I for p = 0).
Eigen::MatrixXd nullBasis(const Instance& in, int p) {
  if (p == 0) return Eigen::MatrixXd::Identity(N, N);
  int rows = 0;
  for (int q = 0; q < p; ++q) rows += kTaskRows[q];
  Eigen::MatrixXd M(rows, N);
  int r0 = 0;
  for (int q = 0; q < p; ++q) {
    M.middleRows(r0, kTaskRows[q]) = in.w[q].cwiseSqrt().asDiagonal() * in.A[q];
    r0 += kTaskRows[q];
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeFullV);
  const auto& s = svd.singularValues();
  int rank = 0;
  for (int i = 0; i < s.size(); ++i) rank += s(i) > 1e-9 * s(0) ? 1 : 0;
  return svd.matrixV().rightCols(N - rank);
}

struct Check {
  double stationarity = 0.0;  // ‖Zᵀ(g + Dᵀλ)‖_∞ / (1 + size of the terms)
  double sign = 0.0;          // largest wrong-signed |λ| (λ ≥ 0 at upper, ≤ 0 at lower)
  double primal = 0.0;        // largest bound violation of rows ≤ p at x*_p (unit rows)
  double complementarity = 0.0;  // largest |λ (D x*_p − bound)|
  bool ownRows = true;        // every active row belongs to a level ≤ p
};

// The independent KKT check of level p at its solution xp (= x*_p) with multipliers λ of the
// rows `row` (side `upper`). The gradient uses A_p xp, which the lower levels do not change.
template <class LevelResult>
Check kktCheck(const Instance& in, int p, const Eigen::VectorXd& xp, const LevelResult& lr,
               const bool* dropped) {
  Check c;
  auto stackedBound = [&](const Instance& i, int row, bool upper) {
    return ::stackedBound(i, row, upper, dropped);
  };
  const Eigen::MatrixXd Z = nullBasis(in, p);
  const Eigen::MatrixXd D = stackedD(in, p);
  const Eigen::VectorXd e = in.A[p] * xp - in.b[p];
  Eigen::VectorXd g = in.A[p].transpose() * in.w[p].asDiagonal() * e;  // ∇ ½‖W^½(A x − b)‖²
  double scale = (in.w[p].asDiagonal() * in.A[p]).norm() * e.norm();
  for (int a = 0; a < lr.num_active; ++a) {
    const int j = lr.active_row[a];
    const double l = lr.multiplier[a];
    if (j < 0 || j >= D.rows()) {
      c.ownRows = false;
      continue;
    }
    g += l * D.row(j).transpose();
    scale += std::abs(l) * D.row(j).norm();
    const bool upper = lr.active_upper[a];
    const double bound = stackedBound(in, j, upper);
    if (stackedBound(in, j, false) != stackedBound(in, j, true))
      c.sign = std::max(c.sign, (upper ? -l : l) * D.row(j).norm());
    c.complementarity = std::max(c.complementarity, std::abs(l * (D.row(j).dot(xp) - bound)));
  }
  c.stationarity = (Z.transpose() * g).cwiseAbs().maxCoeff() / (1.0 + scale);
  for (int j = 0; j < D.rows(); ++j) {
    const double d = D.row(j).dot(xp), n = D.row(j).norm();
    c.primal = std::max(c.primal, (stackedBound(in, j, false) - d) / n);
    c.primal = std::max(c.primal, (d - stackedBound(in, j, true)) / n);
  }
  return c;
}

bool passes(const Check& c) {
  return c.ownRows && c.stationarity <= 1e-8 && c.sign <= 1e-9 && c.primal <= 1e-8 &&
         c.complementarity <= 1e-7;
}

Wbc g_wbc, g_part, g_inf, g_big;

// x*_p: the same hierarchy with the levels below p left out (no task, no bound), cold.
Eigen::VectorXd levelSolution(const Instance& in, int p) {
  g_part.resetWarmStart();
  fill(g_part, in, p + 1);
  g_part.solve();
  return g_part.x();
}

TEST(HqpCertificate, MultipliersPassAnIndependentKktCheck) {
  int checked = 0, with_active = 0, dual_levels = 0, active_higher = 0;
  for (int dual = 0; dual < 2; ++dual) {
    g_wbc.setDualLastLevel(dual == 1);
    g_part.setDualLastLevel(dual == 1);
    g_wbc.setKktResiduals(true);
    for (unsigned seed = 1; seed <= 150; ++seed) {
      const Instance in = makeInstance(seed);
      g_wbc.resetWarmStart();
      fill(g_wbc, in);
      g_wbc.solve();
      const auto& res = g_wbc.result();
      for (int p = 0; p < kLevels; ++p) {
        const auto& lr = res.levels[static_cast<std::size_t>(p)];
        if (lr.status != hqp::QpStatus::Optimal) continue;  // infeasible levels: own rows dropped
        const Eigen::VectorXd xp = p + 1 == kLevels ? Eigen::VectorXd(res.x) : levelSolution(in, p);
        bool dropped[kLevels] = {};
      for (int q = 0; q < p; ++q) dropped[q] = res.levels[static_cast<std::size_t>(q)].constraints_dropped;
      const Check c = kktCheck(in, p, xp, lr, dropped);
        EXPECT_TRUE(passes(c)) << "seed " << seed << " level " << p << " dual " << dual
                               << ": stationarity " << c.stationarity << " sign " << c.sign
                               << " primal " << c.primal << " compl " << c.complementarity;
        // The residuals the solver reports agree.
        ASSERT_TRUE(lr.kkt.computed);
        EXPECT_LE(lr.kkt.stationarity, 1e-9 * (1.0 + lr.kkt.stationarity_scale)) << seed << " " << p;
        EXPECT_LE(lr.kkt.primal, 1e-8) << seed << " " << p;
        EXPECT_LE(lr.kkt.dual, 1e-9) << seed << " " << p;
        EXPECT_LE(lr.kkt.complementarity, 1e-7) << seed << " " << p;
        ++checked;
        if (lr.num_active > 0) ++with_active;
        if (lr.dual) ++dual_levels;
        for (int a = 0; a < lr.num_active; ++a)
          if (lr.active_row[a] < p * kConRows && std::abs(lr.multiplier[a]) > 1e-6) ++active_higher;
      }
    }
  }
  // The instances exercise what is certified: active rows, the dual path, higher rows.
  std::printf("checked %d, with active rows %d, dual path %d, active higher rows %d\n", checked,
              with_active, dual_levels, active_higher);
  EXPECT_GT(checked, 600);
  EXPECT_GT(with_active, 200);
  EXPECT_GT(dual_levels, 40);
  EXPECT_GT(active_higher, 20);
  g_wbc.setDualLastLevel(true);
}

TEST(HqpCertificate, WrongMultipliersAreDetected) {
  // The independent check is not vacuous: a flipped sign, a flipped side or a dropped
  // multiplier of a row that matters fails it.
  g_wbc.setDualLastLevel(true);
  int tried = 0;
  for (unsigned seed = 1; seed <= 150 && tried < 30; ++seed) {
    const Instance in = makeInstance(seed);
    g_wbc.resetWarmStart();
    fill(g_wbc, in);
    g_wbc.solve();
    bool dropped[kLevels] = {};
    for (int p = 0; p < kLevels; ++p) {
      auto lr = g_wbc.result().levels[static_cast<std::size_t>(p)];
      if (p > 0) dropped[p - 1] = g_wbc.result().levels[static_cast<std::size_t>(p - 1)].constraints_dropped;
      if (lr.status != hqp::QpStatus::Optimal || lr.num_active == 0) continue;
      int a = 0;
      for (int k = 1; k < lr.num_active; ++k)
        if (std::abs(lr.multiplier[k]) > std::abs(lr.multiplier[a])) a = k;
      if (std::abs(lr.multiplier[a]) < 1e-3) continue;
      const Eigen::VectorXd xp = p + 1 == kLevels ? Eigen::VectorXd(g_wbc.x()) : levelSolution(in, p);
      ASSERT_TRUE(passes(kktCheck(in, p, xp, lr, dropped))) << seed << " " << p;
      auto flipped = lr;
      flipped.multiplier[a] = -flipped.multiplier[a];
      const Check c1 = kktCheck(in, p, xp, flipped, dropped);
      EXPECT_FALSE(passes(c1)) << seed << " " << p;
      EXPECT_GT(c1.sign, 1e-4) << seed << " " << p;
      EXPECT_GT(c1.stationarity, 1e-6) << seed << " " << p;
      auto side = lr;
      side.active_upper[a] = !side.active_upper[a];
      EXPECT_FALSE(passes(kktCheck(in, p, xp, side, dropped))) << seed << " " << p;
      auto dropped_lr = lr;
      dropped_lr.multiplier[a] = 0.0;
      EXPECT_GT(kktCheck(in, p, xp, dropped_lr, dropped).stationarity, 1e-6) << seed << " " << p;
      ++tried;
    }
  }
  EXPECT_GE(tried, 30);
}

TEST(HqpCertificate, ResidualsAreSwitchableAndChangeNothing) {
  // Off by default; on or off, x, statuses and multipliers are bit-identical.
  EXPECT_FALSE(hqp::HqpSettings{}.kkt_residuals);
  for (unsigned seed = 1; seed <= 40; ++seed) {
    const Instance in = makeInstance(seed);
    g_wbc.setKktResiduals(false);
    g_part.setKktResiduals(true);
    g_wbc.resetWarmStart();
    g_part.resetWarmStart();
    fill(g_wbc, in);
    fill(g_part, in);
    g_wbc.solve();
    g_part.solve();
    EXPECT_TRUE(g_wbc.x() == g_part.x()) << seed;
    for (int p = 0; p < kLevels; ++p) {
      const auto& a = g_wbc.result().levels[static_cast<std::size_t>(p)];
      const auto& b = g_part.result().levels[static_cast<std::size_t>(p)];
      EXPECT_EQ(a.status, b.status) << seed;
      EXPECT_FALSE(a.kkt.computed);
      EXPECT_EQ(a.num_active, b.num_active) << seed;
      for (int k = 0; k < a.num_active; ++k) EXPECT_EQ(a.multiplier[k], b.multiplier[k]) << seed;
    }
  }
  g_part.setKktResiduals(false);
}

// ±1e20 and beyond: no bound, bit for bit as ±inf.
TEST(HqpInfBound, BoundsBeyond1e20AreInfinite) {
  EXPECT_EQ(hqp::kInfBound, 1e20);
  EXPECT_EQ(hqp::interpretBound(1e20), kInf);
  EXPECT_EQ(hqp::interpretBound(-1e20), -kInf);
  EXPECT_EQ(hqp::interpretBound(-3e300), -kInf);
  EXPECT_EQ(hqp::interpretBound(9.99e19), 9.99e19);
  std::mt19937 g(7);
  std::uniform_real_distribution<double> ud(0.0, 1.0);
  int replaced = 0;
  for (unsigned seed = 1; seed <= 80; ++seed) {
    Instance in = makeInstance(seed);
    Instance big = in;
    for (int p = 0; p < kLevels; ++p)
      for (int i = 0; i < kConRows; ++i) {
        // Rows made one-sided or free, with ±inf here and a huge finite value there.
        if (ud(g) < 0.4) {
          in.lo[p](i) = -kInf;
          big.lo[p](i) = ud(g) < 0.5 ? -1e20 : -1e20 * (1.0 + 1e6 * ud(g));
          ++replaced;
        }
        if (ud(g) < 0.4) {
          in.up[p](i) = kInf;
          big.up[p](i) = ud(g) < 0.5 ? 1e20 : 1e20 * (1.0 + 1e6 * ud(g));
          ++replaced;
        }
      }
    for (int tick = 0; tick < 2; ++tick) {  // cold, then warm
      if (tick == 0) {
        g_inf.resetWarmStart();
        g_big.resetWarmStart();
      }
      fill(g_inf, in);
      fill(g_big, big);
      const auto s1 = g_inf.solve(), s2 = g_big.solve();
      EXPECT_EQ(s1, s2) << seed;
      EXPECT_TRUE(g_inf.x() == g_big.x()) << seed;  // bit for bit
      for (int p = 0; p < kLevels; ++p) {
        const auto& a = g_inf.result().levels[static_cast<std::size_t>(p)];
        const auto& b = g_big.result().levels[static_cast<std::size_t>(p)];
        EXPECT_EQ(a.status, b.status) << seed;
        ASSERT_EQ(a.num_active, b.num_active) << seed;
        for (int k = 0; k < a.num_active; ++k) {
          EXPECT_EQ(a.active_row[k], b.active_row[k]) << seed;
          EXPECT_EQ(a.active_upper[k], b.active_upper[k]) << seed;
          EXPECT_EQ(a.multiplier[k], b.multiplier[k]) << seed;
        }
      }
    }
  }
  EXPECT_GT(replaced, 500);
}

// A bound just below 1e20 is a bound, and can be active; the input contract reads ≥ 1e20 as inf.
TEST(HqpInfBound, BoundBelow1e20IsABound) {
  Instance in;
  for (int p = 0; p < kLevels; ++p) {
    in.A[p] = Eigen::MatrixXd::Zero(kTaskRows[p], N);
    in.b[p] = Eigen::VectorXd::Zero(kTaskRows[p]);
    in.w[p] = Eigen::VectorXd::Ones(kTaskRows[p]);
    in.D[p] = Eigen::MatrixXd::Zero(kConRows, N);
    in.lo[p] = Eigen::VectorXd::Constant(kConRows, -kInf);
    in.up[p] = Eigen::VectorXd::Constant(kConRows, kInf);
  }
  in.A[0](0, 0) = 1.0;
  in.b[0](0) = 5e19;  // level 0 wants x_0 = 5e19
  in.D[0](0, 0) = 1.0;
  for (double bound : {1e19, 1e20, 2e20}) {
    in.up[0](0) = bound;
    g_wbc.resetWarmStart();
    fill(g_wbc, in);
    ASSERT_EQ(g_wbc.solve(), hqp::QpStatus::Optimal) << bound;
    const auto& lr = g_wbc.result().levels[0];
    if (bound < hqp::kInfBound) {
      EXPECT_NEAR(g_wbc.x()(0), 1e19, 1e19 * 1e-12);
      ASSERT_EQ(lr.num_active, 1);
      EXPECT_EQ(lr.active_row[0], 0);
      EXPECT_TRUE(lr.active_upper[0]);
      EXPECT_NEAR(lr.multiplier[0], 4e19, 4e19 * 1e-9);  // λ = −(x_0 − b_0) ≥ 0 at upper
    } else {
      EXPECT_NEAR(g_wbc.x()(0), 5e19, 5e19 * 1e-12);
      EXPECT_EQ(lr.num_active, 0);
    }
  }
  // A lower bound of +1e20 reads as +inf, outside the contract as +inf is; NaN still is.
  for (double lower : {1e20, kInf, std::numeric_limits<double>::quiet_NaN()}) {
    in.up[0](0) = kInf;
    in.lo[0](0) = lower;
    fill(g_wbc, in);
    EXPECT_EQ(g_wbc.solve(), hqp::QpStatus::InvalidInput) << lower;
  }
  // With max_magnitude below 1e20 a ±1e20 bound is still accepted (it is no bound).
  hqp::HqpSettings s;
  s.qp.max_magnitude = 1e10;
  static Wbc small(s);
  in.lo[0](0) = -1e20;
  in.up[0](0) = 1e20;
  in.b[0](0) = 1.0;
  fill(small, in);
  EXPECT_EQ(small.solve(), hqp::QpStatus::Optimal);
  EXPECT_NEAR(small.x()(0), 1.0, 1e-12);
}

}  // namespace
