// The paper's shape (Table I): Nx = 30 = 18 q̈ + 12 F, four levels
//   (6 eq + 12 two-sided torque rows), (12 eq + 18 contact rows), (3 eq), (3 + 12 eq),
// on synthetic dynamics-like data. Checks the null-space dimensions 24 → 12 → 9 → 0,
// feasibility, strict priority under changes of lower levels, and that solve() never
// allocates (EIGEN_RUNTIME_NO_MALLOC + a counting global operator new).
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "hqp/hqp_wbc.hpp"
#include "hqp/wqp_wbc.hpp"
#include "support/allocation_counter.hpp"

using hqp::testing::g_counting;
using hqp::testing::g_news;

namespace {

constexpr int N = 30;
using Dyn = hqp::Level<N, hqp::TaskList<hqp::Task<6, N>>, hqp::ConstraintList<hqp::Constraint<12, N>>>;
using Foot = hqp::SoftLevel<N, hqp::TaskList<hqp::Task<12, N>>, hqp::ConstraintList<hqp::Constraint<18, N>>>;
using Com = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>>;
using Low = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>, hqp::Task<12, N>>>;
using Wbc = hqp::HqpWbc<N, Dyn, Foot, Com, Low>;
using Wqp = hqp::WqpWbc<N, Dyn, Foot, Com, Low>;

template <int R, int C>
Eigen::Matrix<double, R, C> randn(std::mt19937& g, double s = 1.0) {
  std::normal_distribution<double> nd(0.0, s);
  Eigen::Matrix<double, R, C> M;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) M(i, j) = nd(g);
  return M;
}

// Dynamics-like data: M SPD with a heavy floating base, contact Jacobians, a friction
// pyramid + CoP rectangle per foot, torque limits tight enough to bind now and then.
struct Scene {
  Eigen::Matrix<double, 18, 18> M;
  Eigen::Matrix<double, 18, 1> h;
  Eigen::Matrix<double, 12, 18> J;
  Eigen::Matrix<double, 3, 18> Jcom, Jtorso;
  Eigen::Matrix<double, 12, 1> a_feet, F_ref;
  Eigen::Matrix<double, 3, 1> a_com, a_torso;
  double tau_max = 150.0;
};

Scene makeScene(std::mt19937& g) {
  Scene s;
  const Eigen::Matrix<double, 18, 18> B = randn<18, 18>(g, 0.6);
  s.M = B * B.transpose();
  s.M.diagonal().head(3).array() += 40.0;  // base mass
  s.M.diagonal().segment(3, 3).array() += 4.0;
  s.M.diagonal().tail(12).array() += 0.5;  // reflected rotor inertia
  s.h = randn<18, 1>(g, 5.0);
  s.h(2) += 40.0 * 9.81;
  s.J = randn<12, 18>(g, 0.5);
  s.J.block<3, 3>(0, 0).setIdentity();
  s.J.block<3, 3>(6, 0).setIdentity();
  s.Jcom = randn<3, 18>(g, 0.3);
  s.Jcom.leftCols(3).setIdentity();
  s.Jtorso = randn<3, 18>(g, 0.3);
  s.a_feet = randn<12, 1>(g, 0.5);
  s.a_com = randn<3, 1>(g, 1.0);
  s.a_torso = randn<3, 1>(g, 1.0);
  s.F_ref.setZero();
  s.F_ref(2) = s.F_ref(8) = 0.5 * 40.0 * 9.81;
  s.F_ref.segment<2>(0) = randn<2, 1>(g, 150.0);  // pushes outside the friction pyramid
  s.F_ref.segment<3>(3) = randn<3, 1>(g, 20.0);
  s.tau_max = std::uniform_real_distribution<double>(80.0, 300.0)(g);
  return s;
}

template <class W>
void fill(W& wbc, const Scene& s) {
  auto& dyn = wbc.template level<0>().template task<0>();  // S_f (M q̈ + h − Jᵀ F) = 0
  dyn.A << s.M.topRows(6), -s.J.leftCols(6).transpose();
  dyn.b = -s.h.head(6);
  auto& tau = wbc.template level<0>().template constraint<0>();  // τ = S_a (M q̈ + h − Jᵀ F)
  tau.D << s.M.bottomRows(12), -s.J.rightCols(12).transpose();
  tau.lower = Eigen::Matrix<double, 12, 1>::Constant(-s.tau_max) - s.h.tail(12);
  tau.upper = Eigen::Matrix<double, 12, 1>::Constant(s.tau_max) - s.h.tail(12);
  auto& feet = wbc.template level<1>().template task<0>();
  feet.A.setZero();
  feet.A.leftCols(18) = s.J;
  feet.b = s.a_feet;
  auto& contact = wbc.template level<1>().template constraint<0>();
  contact.D.setZero();
  const double mu = 0.6, lx = 0.1, ly = 0.05;
  for (int f = 0; f < 2; ++f) {
    const int c = 18 + 6 * f, r = 9 * f;  // columns of [fx fy fz τx τy τz], rows of this foot
    contact.D(r + 0, c + 2) = -1.0;                                      // fz ≥ 0
    contact.D(r + 1, c + 0) = 1.0, contact.D(r + 1, c + 2) = -mu;        // fx ≤ μ fz
    contact.D(r + 2, c + 0) = -1.0, contact.D(r + 2, c + 2) = -mu;       // −fx ≤ μ fz
    contact.D(r + 3, c + 1) = 1.0, contact.D(r + 3, c + 2) = -mu;
    contact.D(r + 4, c + 1) = -1.0, contact.D(r + 4, c + 2) = -mu;
    contact.D(r + 5, c + 3) = 1.0, contact.D(r + 5, c + 2) = -ly;        // CoP
    contact.D(r + 6, c + 3) = -1.0, contact.D(r + 6, c + 2) = -ly;
    contact.D(r + 7, c + 4) = 1.0, contact.D(r + 7, c + 2) = -lx;
    contact.D(r + 8, c + 4) = -1.0, contact.D(r + 8, c + 2) = -lx;
  }
  contact.setUpperBound(Eigen::Matrix<double, 18, 1>::Zero());
  auto& com = wbc.template level<2>().template task<0>();
  com.A.setZero();
  com.A.leftCols(18) = s.Jcom;
  com.b = s.a_com;
  auto& torso = wbc.template level<3>().template task<0>();
  torso.A.setZero();
  torso.A.leftCols(18) = s.Jtorso;
  torso.b = s.a_torso;
  auto& force = wbc.template level<3>().template task<1>();
  force.A.setZero();
  force.A.rightCols(12).setIdentity();
  force.b = s.F_ref;
}

// Largest violation of all constraints at x, scaled by the row norm.
template <class W>
double maxViolation(W& wbc, const Eigen::Matrix<double, N, 1>& x) {
  double v = 0.0;
  auto check = [&](const auto& c) {
    const auto d = (c.D * x).eval();
    for (int i = 0; i < d.size(); ++i)
      v = std::max(v, std::max(c.lower(i) - d(i), d(i) - c.upper(i)) / c.D.row(i).norm());
  };
  check(wbc.template level<0>().template constraint<0>());
  check(wbc.template level<1>().template constraint<0>());
  return v;
}

}  // namespace

TEST(HqpPaperShape, NullSpaceDimensionsAndFeasibility) {
  std::mt19937 g(1);
  static Wbc wbc;
  int active_torque = 0, active_contact = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Scene s = makeScene(g);
    fill(wbc, s);
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal) << "trial " << trial;
    const auto& res = wbc.result();
    const int dims[] = {24, 12, 9, 0};
    const int vars[] = {30, 24, 12, 9};
    for (int p = 0; p < 4; ++p) {
      EXPECT_EQ(res.levels[static_cast<size_t>(p)].null_dim, dims[p]);
      EXPECT_EQ(res.levels[static_cast<size_t>(p)].variables, vars[p]);
    }
    // Levels 1–3 are met exactly (full rank, 21 ≤ 30 rows, constraints admit it),
    // level 4 is a least-squares compromise.
    EXPECT_LT(res.levels[0].residual, 1e-14 * s.h.squaredNorm());
    EXPECT_LT(maxViolation(wbc, res.x), 1e-8);
    // Dynamics hold: S_f (M q̈ + h − Jᵀ F) = 0 recomputed from the scene.
    const Eigen::Matrix<double, 18, 1> gen =
        s.M * res.x.head(18) + s.h - s.J.transpose() * res.x.tail(12);
    EXPECT_LT(gen.head(6).norm(), 1e-8 * s.h.norm());
    for (int p = 0; p < 4; ++p)
      for (int a = 0; a < res.levels[static_cast<size_t>(p)].num_active; ++a) {
        const int row = res.levels[static_cast<size_t>(p)].active_row[static_cast<size_t>(a)];
        active_torque += p == 3 && row < 12;
        active_contact += p == 3 && row >= 12;
      }
  }
  EXPECT_GT(active_contact, 20);  // the lowest level really runs into constraints
  EXPECT_GT(active_torque, 0);
}

TEST(HqpPaperShape, LowerLevelsNeverChangeHigherResiduals) {
  std::mt19937 g(2);
  static Wbc wbc;
  int moved = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Scene s = makeScene(g);
    fill(wbc, s);
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
    const auto before = wbc.result();
    // Without the lower levels (all-zero tasks carry no rank and change nothing) ...
    wbc.level<2>().task<0>().A.setZero();
    wbc.level<2>().task<0>().b.setZero();
    wbc.level<3>().task<0>().A.setZero();
    wbc.level<3>().task<1>().A.setZero();
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
    for (int p = 0; p < 2; ++p)
      EXPECT_NEAR(wbc.result().levels[static_cast<size_t>(p)].residual,
                  before.levels[static_cast<size_t>(p)].residual,
                  1e-9 * (1.0 + before.levels[static_cast<size_t>(p)].residual));
    // ... and with different lower-level data.
    s.a_com = randn<3, 1>(g, 5.0);
    s.F_ref = randn<12, 1>(g, 300.0);
    fill(wbc, s);
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
    for (int p = 0; p < 2; ++p)
      EXPECT_NEAR(wbc.result().levels[static_cast<size_t>(p)].residual,
                  before.levels[static_cast<size_t>(p)].residual,
                  1e-9 * (1.0 + before.levels[static_cast<size_t>(p)].residual));
    moved += (wbc.x() - before.x).norm() > 1e-6;
  }
  EXPECT_GT(moved, 0) << "the lower levels never moved x: the residual checks above prove nothing";
}

TEST(HqpPaperShape, SolveNeverAllocates) {
  std::mt19937 g(3);
  static Wbc wbc;
  static Wqp wqp;
  ASSERT_TRUE(wbc.setSlack(1, true));
  Scene s = makeScene(g);
  fill(wbc, s);
  fill(wqp, s);
  wbc.solve();  // first solve outside the window (nothing is lazily allocated, but be fair)
  int slack_solves = 0;
  for (int tick = 0; tick < 30; ++tick) {
    // Perturbed ticks; every 10th tick demands an impossible contact (slack path).
    s.a_feet += randn<12, 1>(g, 0.01);
    s.F_ref += randn<12, 1>(g, 1.0);
    fill(wbc, s);
    fill(wqp, s);
    if (tick % 10 == 5) {
      // fz ≥ 0 and fz ≤ −10 on the left foot: contradictory rows of level 2
      wbc.level<1>().constraint<0>().D.row(1).setZero();
      wbc.level<1>().constraint<0>().D(1, 20) = 1.0;
      wbc.level<1>().constraint<0>().upper(1) = -10.0;
    }
    if (tick == 20) wbc.resetWarmStart();  // a cold solve too
    const long before = g_news.load();
    Eigen::internal::set_is_malloc_allowed(false);
    const hqp::QpStatus st = wbc.solve();
    const hqp::QpStatus sw = wqp.solve();
    Eigen::internal::set_is_malloc_allowed(true);
    const long after = g_news.load();
    EXPECT_EQ(after - before, 0) << "tick " << tick;
    EXPECT_EQ(sw, hqp::QpStatus::Optimal);
    if (tick % 10 == 5) {
      EXPECT_EQ(st, hqp::QpStatus::Infeasible);
      EXPECT_TRUE(wbc.result().levels[1].slack_used);
      ++slack_solves;
    } else {
      EXPECT_EQ(st, hqp::QpStatus::Optimal) << "tick " << tick;
    }
  }
  EXPECT_EQ(slack_solves, 3);
  // The counter itself works.
  const long before = g_news.load();
  void* p = ::operator new(16);  // a direct call: not subject to new-expression elision
  ::operator delete(p);
  EXPECT_EQ(g_news.load() - before, 1);
}
