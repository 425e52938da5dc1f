// Strict priority with inequalities: HqpWbc's per-level residuals == an independent
// brute-force cascade (tests/support/reference_cascade.hpp) that imposes the higher levels'
// optimal task values as explicit equalities, on random 4-level hierarchies.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "hqp/hqp_wbc.hpp"
#include "hqp/wqp_wbc.hpp"
#include "support/reference_cascade.hpp"

namespace {

constexpr int N = 7;
using L1 = hqp::Level<N, hqp::TaskList<hqp::Task<2, N>>, hqp::ConstraintList<hqp::Constraint<2, N>>>;
// Level 2 (index 1) offers the slack option (off unless a test turns it on).
using L2 = hqp::SoftLevel<N, hqp::TaskList<hqp::Task<2, N>>, hqp::ConstraintList<hqp::Constraint<2, N>>>;
using L3 = hqp::Level<N, hqp::TaskList<hqp::Task<2, N>>, hqp::ConstraintList<hqp::Constraint<1, N>>>;
using L4 = hqp::Level<N, hqp::TaskList<hqp::Task<3, N>>>;
using Wbc = hqp::HqpWbc<N, L1, L2, L3, L4>;
using Wqp = hqp::WqpWbc<N, L1, L2, L3, L4>;
constexpr int kTaskRows[] = {2, 2, 2, 3};
constexpr int kConRows[] = {2, 2, 1, 0};

Eigen::MatrixXd randn(int r, int c, std::mt19937& g) {
  std::normal_distribution<double> nd(0.0, 1.0);
  Eigen::MatrixXd M(r, c);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c; ++j) M(i, j) = nd(g);
  return M;
}
double unif(std::mt19937& g, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(g);
}

// kind 0: generic; 1: rank-deficient tasks; 2: tasks conflicting across levels;
// 3: a constraint of level 2 contradicting level 1's task (infeasible level, dropped).
std::vector<hqp::testing::RefLevel> makeLevels(int kind, std::mt19937& g, Eigen::VectorXd* inside = nullptr) {
  std::vector<hqp::testing::RefLevel> L(4);
  const Eigen::VectorXd x0 = randn(N, 1, g);  // feasible for every constraint
  if (inside != nullptr) *inside = x0;
  for (int p = 0; p < 4; ++p) {
    auto& l = L[static_cast<size_t>(p)];
    l.A = randn(kTaskRows[p], N, g);
    l.D = randn(kConRows[p], N, g);
    l.lower.resize(kConRows[p]);
    l.upper.resize(kConRows[p]);
    const Eigen::VectorXd d0 = l.D * x0;
    for (int i = 0; i < kConRows[p]; ++i) {
      const int side = static_cast<int>(g() % 4);  // 0: two-sided, 1: upper only, 2: lower only
      l.lower(i) = side == 1 ? -hqp::kInf : d0(i) - unif(g, 0.05, 0.6);
      l.upper(i) = side == 2 ? hqp::kInf : d0(i) + unif(g, 0.05, 0.6);
      if (side == 3) l.lower(i) = l.upper(i) = d0(i);  // an equality written as two bounds
    }
  }
  if (kind == 1) {
    L[1].A = randn(2, 1, g) * randn(1, N, g);
    L[3].A = randn(3, 2, g) * randn(2, N, g);
  } else if (kind == 2) {
    L[1].A.row(0) = L[0].A.row(1);
    L[2].A = L[1].A + 1e-3 * randn(2, N, g);
    L[3].A.row(0) = L[0].A.row(0) - L[2].A.row(1);
  }
  // Targets far outside the feasible box so that constraints become active.
  for (int p = 0; p < 4; ++p) {
    auto& l = L[static_cast<size_t>(p)];
    l.b = l.A * (x0 + 2.0 * randn(N, 1, g));
  }
  if (kind == 3) {
    // Level 2's first row measures level 1's first task and excludes the value level 1 reaches.
    L[1].D.row(0) = L[0].A.row(0);
    L[1].lower(0) = L[0].b(0) + 0.5;
    L[1].upper(0) = hqp::kInf;
    L[0].D.setZero();  // keep level 1's own target reachable
    L[0].lower.setConstant(-1.0);
    L[0].upper.setConstant(1.0);
  }
  return L;
}

template <class W>
void fill(W& wbc, const std::vector<hqp::testing::RefLevel>& L) {
  auto setLevel = [](auto& level, const hqp::testing::RefLevel& l) {
    level.template task<0>().A = l.A;
    level.template task<0>().b = l.b;
    if constexpr (std::decay_t<decltype(level)>::num_constraints > 0) {
      level.template constraint<0>().D = l.D;
      level.template constraint<0>().lower = l.lower;
      level.template constraint<0>().upper = l.upper;
    }
  };
  setLevel(wbc.template level<0>(), L[0]);
  setLevel(wbc.template level<1>(), L[1]);
  setLevel(wbc.template level<2>(), L[2]);
  setLevel(wbc.template level<3>(), L[3]);
}

// Largest constraint violation (scaled by row norm) of the constraints that were kept.
double maxViolation(const std::vector<hqp::testing::RefLevel>& L, const Eigen::VectorXd& x,
                    const std::vector<bool>& dropped) {
  double v = 0.0;
  for (size_t p = 0; p < L.size(); ++p) {
    if (dropped[p]) continue;
    const Eigen::VectorXd d = L[p].D * x;
    for (Eigen::Index i = 0; i < d.size(); ++i) {
      const double s = std::max(L[p].D.row(i).norm(), 1e-12);
      v = std::max(v, std::max(L[p].lower(i) - d(i), d(i) - L[p].upper(i)) / s);
    }
  }
  return v;
}

}  // namespace

// Both ways of solving the last level: the dual method (default; its Â_p has full column rank
// in almost every trial) and ActiveSetQp.
class HqpInequalityLastLevel : public ::testing::TestWithParam<bool> {};

TEST_P(HqpInequalityLastLevel, PerLevelResidualsMatchBruteForceCascade) {
  std::mt19937 g(31);
  static Wbc wbc;
  wbc.setDualLastLevel(GetParam());
  int trials = 0, with_active = 0, lower_active = 0, infeasible = 0, dual = 0, dual_active = 0;
  for (int trial = 0; trial < 240; ++trial) {
    const int kind = trial % 4;
    const auto L = makeLevels(kind, g);
    const auto ref = hqp::testing::bruteForceCascade(L, N);
    fill(wbc, L);
    const hqp::QpStatus s = wbc.solve();
    const auto& res = wbc.result();
    ASSERT_TRUE(res.x.allFinite());
    bool any_dropped = false;
    for (int p = 0; p < 4; ++p) {
      const auto& lr = res.levels[static_cast<size_t>(p)];
      const double r = ref.residual[static_cast<size_t>(p)];
      EXPECT_NEAR(lr.residual, r, 1e-8 * (1.0 + r)) << "trial " << trial << " level " << p;
      EXPECT_EQ(lr.constraints_dropped, ref.dropped[static_cast<size_t>(p)]) << "trial " << trial;
      any_dropped = any_dropped || lr.constraints_dropped;
      if (lr.num_active > 0) {
        ++with_active;
        lower_active += p >= 2;
      }
      if (lr.dual) {  // the last level by the dual method (HqpSettings::dual_last_level)
        ++dual;
        dual_active += lr.num_active > 0;
      }
    }
    if (any_dropped) {
      ++infeasible;
      EXPECT_EQ(s, hqp::QpStatus::Infeasible);
      int first = 0;
      while (!ref.dropped[static_cast<size_t>(first)]) ++first;
      EXPECT_EQ(res.failed_level, first);
    } else {
      EXPECT_EQ(s, hqp::QpStatus::Optimal) << "trial " << trial;
      for (int p = 0; p < 4 && s != hqp::QpStatus::Optimal; ++p)
        ADD_FAILURE() << "level " << p << ": " << hqp::toString(res.levels[static_cast<size_t>(p)].status)
                      << " after " << res.levels[static_cast<size_t>(p)].iterations << " iterations";
    }
    std::vector<bool> dropped(4);
    for (int p = 0; p < 4; ++p) dropped[static_cast<size_t>(p)] = res.levels[static_cast<size_t>(p)].constraints_dropped;
    EXPECT_LT(maxViolation(L, res.x, dropped), 1e-8) << "trial " << trial;
    ++trials;
  }
  EXPECT_EQ(trials, 240);
  EXPECT_GT(with_active, 200);   // constraints were really active
  EXPECT_GT(lower_active, 50);   // also in the lower levels' QPs
  EXPECT_GE(infeasible, 60);     // kind 3 (and some random cases) really were infeasible
  if (GetParam()) {
    EXPECT_GT(dual, 200);
    EXPECT_GT(dual_active, 150);
  } else {
    EXPECT_EQ(dual, 0);
  }
}
INSTANTIATE_TEST_SUITE_P(HqpInequality, HqpInequalityLastLevel, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& i) {
                           return i.param ? std::string("DualMethod") : std::string("ActiveSetQp");
                         });

// The deferred path (HqpSettings::defer_constraints, docs/hqp.md "Deferred constraints"): the
// levels above the last take their unconstrained steps, the last level holds every row, and
// the cascade runs only if that fails. Half the trials move levels 1–3's targets onto the point
// every row holds (their unconstrained minima are then reachable: the deferred path must
// hold), half keep the far targets (mostly the cascade). Either way: the brute-force cascade's
// per-level residuals, the same x as with the path off (where it ends alike), every kept row
// held, and on the deferred path a certificate checked here, not by the solver.
TEST(HqpInequality, DeferredPathGivesTheCascadesOptimum) {
  std::mt19937 g(47);
  static Wbc on, off;
  off.setDeferConstraints(false);
  on.setKktResiduals(true);
  int deferred = 0, cascade = 0, deferred_active = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::VectorXd x0;
    auto L = makeLevels(trial % 4, g, &x0);
    const bool reachable = trial % 2 == 0;  // kinds 0 and 2
    if (reachable)
      for (int p = 0; p < 3; ++p) L[static_cast<size_t>(p)].b = L[static_cast<size_t>(p)].A * x0;
    const auto ref = hqp::testing::bruteForceCascade(L, N);
    fill(on, L);
    fill(off, L);
    on.resetWarmStart();  // each trial on its own (the next test covers the warm sequence)
    const hqp::QpStatus s = on.solve();
    const hqp::QpStatus s_off = off.solve();
    // The same status, or the deferred path found the optimum (its certificate is checked
    // below) where the cascade stopped short.
    EXPECT_TRUE(s == s_off || (on.result().deferred && s == hqp::QpStatus::Optimal)) << "trial " << trial;
    const auto& r = on.result();
    ASSERT_TRUE(r.x.allFinite());
    EXPECT_FALSE(off.result().deferred);
    if (reachable) EXPECT_TRUE(r.deferred) << "trial " << trial;
    (r.deferred ? deferred : cascade) += 1;
    std::vector<bool> dropped(4);
    for (int p = 0; p < 4; ++p) {
      const auto& lr = r.levels[static_cast<size_t>(p)];
      const double res = ref.residual[static_cast<size_t>(p)];
      EXPECT_NEAR(lr.residual, res, 1e-8 * (1.0 + res)) << "trial " << trial << " level " << p;
      dropped[static_cast<size_t>(p)] = lr.constraints_dropped;
    }
    EXPECT_LT(maxViolation(L, r.x, dropped), 1e-8) << "trial " << trial;
    const double xs = std::max(1.0, off.result().x.lpNorm<Eigen::Infinity>());
    if (s_off == s) EXPECT_LT((r.x - off.result().x).lpNorm<Eigen::Infinity>() / xs, 1e-8) << "trial " << trial;
    if (!r.deferred) continue;
    EXPECT_EQ(s, hqp::QpStatus::Optimal);
    for (int p = 0; p < 3; ++p) {
      // Above the last level: no QP, no active row; the higher tasks at their unconstrained
      // minimum (0 here: full row rank); the rows of levels ≤ p held at the final x.
      const auto& lr = r.levels[static_cast<size_t>(p)];
      EXPECT_EQ(lr.num_active, 0);
      EXPECT_EQ(lr.iterations, 0);
      if (reachable) EXPECT_LT(lr.residual, 1e-16 * (1.0 + L[static_cast<size_t>(p)].b.squaredNorm()));
      EXPECT_TRUE(lr.kkt.computed);
      EXPECT_LE(lr.kkt.primal, 1e-8) << "trial " << trial << " level " << p;
    }
    // The last level holds the rows of every level: its multipliers prove its optimum,
    // x_L ∝ A₄ᵀ(A₄x − b₄) + Σ λ_a D_aᵀ ∈ row space of levels 1–3's tasks (checked by projecting
    // onto their null space), λ ≥ 0 at an upper bound, ≤ 0 at a lower one.
    const auto& last = r.levels[3];
    deferred_active += last.num_active > 0;
    Eigen::MatrixXd Dall(5, N);
    Dall << L[0].D, L[1].D, L[2].D;
    Eigen::MatrixXd Ahigh(6, N);
    Ahigh << L[0].A, L[1].A, L[2].A;
    Eigen::VectorXd grad = L[3].A.transpose() * (L[3].A * r.x - L[3].b);
    double scale = (L[3].A.transpose() * L[3].A).norm() * r.x.norm() + L[3].b.norm();
    for (int a = 0; a < last.num_active; ++a) {
      const double lam = last.multiplier[static_cast<size_t>(a)];
      const int row = last.active_row[static_cast<size_t>(a)];
      EXPECT_GE(last.active_upper[static_cast<size_t>(a)] ? lam : -lam, -1e-9 * (1.0 + std::abs(lam)));
      grad += lam * Dall.row(row).transpose();
      scale += std::abs(lam) * Dall.row(row).norm();
    }
    const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(N, N) -
                              Ahigh.completeOrthogonalDecomposition().pseudoInverse() * Ahigh;
    EXPECT_LT((P * grad).lpNorm<Eigen::Infinity>(), 1e-9 * (1.0 + scale)) << "trial " << trial;
  }
  EXPECT_GE(deferred, 75);        // all reachable trials, and some of the far ones
  EXPECT_GE(cascade, 40);         // far targets pressed against rows: the cascade ran
  EXPECT_GE(deferred_active, 40); // the last level really held rows of the levels above
}

// After a failed deferred attempt the cascade keeps that attempt's decompositions of Â_p for
// the levels above the last (the same matrices). Only that solve's: a solve on new data that
// makes no deferred attempt factors every level anew. Checked against a fresh solver on the
// same data, and the cascade after a failed attempt against the brute-force cascade.
TEST(HqpInequality, CascadeReusesOnlyItsOwnDeferredAttemptsDecompositions) {
  std::mt19937 g(61);
  static Wbc wbc, fresh;
  fresh.setDeferConstraints(false);
  int failed_attempts = 0;
  for (int trial = 0; trial < 60; ++trial) {
    Eigen::VectorXd x0;
    auto L = makeLevels(trial % 4, g, &x0);
    const bool reachable = trial % 2 == 0;  // the deferred path holds; else it mostly fails
    if (reachable)
      for (int p = 0; p < 3; ++p) L[static_cast<size_t>(p)].b = L[static_cast<size_t>(p)].A * x0;
    wbc.setDeferConstraints(true);
    fill(wbc, L);
    wbc.resetWarmStart();
    wbc.solve();
    ASSERT_TRUE(wbc.result().deferred_tried) << "trial " << trial;
    if (reachable) ASSERT_TRUE(wbc.result().deferred) << "trial " << trial;
    if (!wbc.result().deferred) {
      ++failed_attempts;
      const auto ref = hqp::testing::bruteForceCascade(L, N);
      for (int p = 0; p < 4; ++p) {
        const double res = ref.residual[static_cast<size_t>(p)];
        EXPECT_NEAR(wbc.result().levels[static_cast<size_t>(p)].residual, res, 1e-8 * (1.0 + res))
            << "trial " << trial << " level " << p;
      }
    }
    // New data, no deferred attempt: the same x as a solver that never saw the first.
    const auto L2 = makeLevels(trial % 4, g);
    wbc.setDeferConstraints(false);
    fill(wbc, L2);
    wbc.resetWarmStart();
    fill(fresh, L2);
    fresh.resetWarmStart();
    const hqp::QpStatus s = wbc.solve(), s_fresh = fresh.solve();
    EXPECT_EQ(s, s_fresh) << "trial " << trial;
    const double xs = std::max(1.0, fresh.result().x.lpNorm<Eigen::Infinity>());
    EXPECT_LT((wbc.result().x - fresh.result().x).lpNorm<Eigen::Infinity>() / xs, 1e-12)
        << "trial " << trial;
  }
  EXPECT_GE(failed_attempts, 10);
}

// The deferred path's last level when its unconstrained minimizer meets every row: no row is
// formed in its variables, the level ends with none active (docs/hqp.md, "Deferred
// constraints"). Every target near a point strictly inside every row (no equality rows), so
// that the minimizer lands inside, or, for some trials, just outside one row: the same x as
// the cascade either way, the brute-force residuals, every row held.
TEST(HqpInequality, DeferredLastLevelFreeStepGivesTheCascadesOptimum) {
  std::mt19937 g(53);
  static Wbc on, off;
  off.setDeferConstraints(false);
  int free = 0, held = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Eigen::VectorXd x0;
    auto L = makeLevels(0, g, &x0);
    const double reach = trial % 2 == 0 ? 0.01 : 0.5;  // near x0, or far enough to press a row
    for (auto& l : L) {
      const Eigen::VectorXd d0 = l.D * x0;
      for (int i = 0; i < l.D.rows(); ++i)
        if (l.lower(i) == l.upper(i)) l.lower(i) = d0(i) - 0.3, l.upper(i) = d0(i) + 0.3;
    }
    for (int p = 0; p < 3; ++p) L[static_cast<size_t>(p)].b = L[static_cast<size_t>(p)].A * x0;
    L[3].b = L[3].A * (x0 + reach * randn(N, 1, g));
    const auto ref = hqp::testing::bruteForceCascade(L, N);
    fill(on, L);
    fill(off, L);
    on.resetWarmStart();
    off.resetWarmStart();
    ASSERT_EQ(on.solve(), hqp::QpStatus::Optimal) << "trial " << trial;
    ASSERT_EQ(off.solve(), hqp::QpStatus::Optimal) << "trial " << trial;
    const auto& r = on.result();
    ASSERT_TRUE(r.deferred) << "trial " << trial;
    (r.levels[3].num_active == 0 ? free : held) += 1;
    for (int p = 0; p < 4; ++p) {
      const double res = ref.residual[static_cast<size_t>(p)];
      EXPECT_NEAR(r.levels[static_cast<size_t>(p)].residual, res, 1e-8 * (1.0 + res))
          << "trial " << trial << " level " << p;
    }
    EXPECT_LT(maxViolation(L, r.x, std::vector<bool>(4)), 1e-8) << "trial " << trial;
    const double xs = std::max(1.0, off.result().x.lpNorm<Eigen::Infinity>());
    EXPECT_LT((r.x - off.result().x).lpNorm<Eigen::Infinity>() / xs, 1e-8) << "trial " << trial;
  }
  EXPECT_GE(free, 40);  // the near targets
  EXPECT_GE(held, 20);  // a row pressed: the dual method over every row
  std::printf("deferred last level: %d free, %d with rows active\n", free, held);
}

// When the deferred path is tried (docs/hqp.md): only while no level above the last holds a
// working set. A cascade that a row held away from a higher level's minimum leaves that row
// there, so the next warm solve of the same problem skips the attempt; a cascade whose higher
// levels end at their minima empties their working sets, and the next solve tries again.
TEST(HqpInequality, DeferredPathIsRetriedOnlyAfterAFreeCascade) {
  std::mt19937 g(53);
  static Wbc wbc;
  int checked = 0;
  for (int trial = 0; trial < 40 && checked < 10; ++trial) {
    Eigen::VectorXd x0;
    auto far = makeLevels(0, g, &x0);
    auto near = far;
    for (int p = 0; p < 3; ++p) near[static_cast<size_t>(p)].b = near[static_cast<size_t>(p)].A * x0;
    wbc.resetWarmStart();
    fill(wbc, far);
    wbc.solve();
    if (wbc.result().deferred) continue;  // far targets that happen to be reachable
    ASSERT_TRUE(wbc.result().deferred_tried);
    const Eigen::VectorXd x_far = wbc.result().x;
    int held = 0;  // rows left in the higher levels' working sets
    for (int p = 0; p < 3; ++p) held += wbc.result().levels[static_cast<size_t>(p)].num_active;
    ASSERT_GT(held, 0);
    wbc.solve();  // the same problem, warm: the attempt would fail again
    EXPECT_FALSE(wbc.result().deferred_tried) << "trial " << trial;
    EXPECT_LT((wbc.result().x - x_far).lpNorm<Eigen::Infinity>(), 1e-9 * std::max(1.0, x_far.norm()));
    fill(wbc, near);
    wbc.solve();  // still skipped: the far problem's rows are in the working sets
    EXPECT_FALSE(wbc.result().deferred_tried) << "trial " << trial;
    const Eigen::VectorXd x_near = wbc.result().x;
    wbc.solve();  // that cascade ended every higher level at its minimum: tried, and it holds
    EXPECT_TRUE(wbc.result().deferred_tried) << "trial " << trial;
    EXPECT_TRUE(wbc.result().deferred) << "trial " << trial;
    EXPECT_LT((wbc.result().x - x_near).lpNorm<Eigen::Infinity>(), 1e-9 * std::max(1.0, x_near.norm()));
    ++checked;
  }
  EXPECT_EQ(checked, 10);
}

// Degenerate vertices (the anti-cycling rule of ActiveSetQp, docs/active-set-qp.md "Iteration
// bound"): random hierarchies, each from its own seed, with a duplicated level-2 row and a
// level-3 row through the sum of two higher rows' bounds. Before the rule, 17 of these 30000
// (cold, -O3) hit IterationLimit at level 3: two blocking rows, both dependent on the working
// set at a vertex, took turns blocking a rounding-size step. The seeds depend on rounding
// (-march=native gives another 17, sharing 4504, 19604, 22620); those of the test build are
// re-checked against the brute-force cascade. A warm sweep (each hierarchy warm-started from
// the previous one's working set) stalled the same way in 3 of 30000 (10 with -march=native).
namespace {
std::vector<hqp::testing::RefLevel> makeDegenerateLevels(int trial) {
  std::mt19937 g(static_cast<unsigned>(1000003 + 2 * 7777777 + trial));
  auto L = makeLevels(trial % 4, g);
  L[1].D.row(1) = L[1].D.row(0);
  L[1].lower(1) = L[1].lower(0);
  L[1].upper(1) = L[1].upper(0);
  L[2].D.row(0) = L[0].D.row(0) + L[1].D.row(0);
  L[2].upper(0) = L[0].upper(0) + L[1].upper(0);
  L[2].lower(0) = -hqp::kInf;
  return L;
}
}  // namespace

TEST(HqpInequality, DegenerateVerticesDoNotCycle) {
  static Wbc wbc;
  wbc.setWarmStart(false);
  const int kTrials = 30000;
  std::vector<int> limited;
  for (int trial = 0; trial < kTrials; ++trial) {
    fill(wbc, makeDegenerateLevels(trial));
    wbc.solve();
    for (int p = 0; p < 4; ++p)
      if (wbc.result().levels[static_cast<size_t>(p)].status == hqp::QpStatus::IterationLimit) {
        limited.push_back(trial);
        break;
      }
  }
  std::string list;
  for (int t : limited) list += std::to_string(t) + " ";
  EXPECT_TRUE(limited.empty()) << limited.size() << " of " << kTrials
                               << " hierarchies hit IterationLimit: " << list;
  // The seeds that cycled before: the strict-priority answer of the brute-force cascade.
  for (int trial : {4504, 4560, 6328, 8476, 8916, 9172, 14432, 17260, 19604, 22620}) {
    const auto L = makeDegenerateLevels(trial);
    const auto ref = hqp::testing::bruteForceCascade(L, N);
    fill(wbc, L);
    wbc.solve();
    for (int p = 0; p < 4; ++p) {
      const auto& lr = wbc.result().levels[static_cast<size_t>(p)];
      const double r = ref.residual[static_cast<size_t>(p)];
      EXPECT_NE(lr.status, hqp::QpStatus::IterationLimit) << "trial " << trial << " level " << p;
      EXPECT_NEAR(lr.residual, r, 1e-8 * (1.0 + r)) << "trial " << trial << " level " << p;
    }
  }
}

TEST(HqpInequality, StaleWarmStartsDoNotCycle) {
  static Wbc wbc;
  wbc.setWarmStart(true);
  const int kTrials = 30000;
  int limited = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::mt19937 g(static_cast<unsigned>(1000003 + 7777777 + trial));
    fill(wbc, makeLevels(trial % 4, g));
    wbc.solve();
    for (int p = 0; p < 4; ++p)
      limited += wbc.result().levels[static_cast<size_t>(p)].status == hqp::QpStatus::IterationLimit;
  }
  EXPECT_EQ(limited, 0);
}

TEST(HqpInequality, WarmStartGivesTheColdSolution) {
  // Ticks of slightly perturbed data: warm and cold solves agree level by level.
  std::mt19937 g(77);
  static Wbc warm, cold;
  cold.setWarmStart(false);
  auto L = makeLevels(0, g);
  for (int tick = 0; tick < 50; ++tick) {
    for (auto& l : L) {
      l.A += 1e-3 * randn(static_cast<int>(l.A.rows()), N, g);
      l.b += 1e-3 * randn(static_cast<int>(l.b.size()), 1, g);
    }
    fill(warm, L);
    fill(cold, L);
    ASSERT_EQ(warm.solve(), cold.solve());
    for (int p = 0; p < 4; ++p)
      EXPECT_NEAR(warm.result().levels[static_cast<size_t>(p)].residual,
                  cold.result().levels[static_cast<size_t>(p)].residual,
                  1e-9 * (1.0 + cold.result().levels[static_cast<size_t>(p)].residual));
  }
}

TEST(HqpInequality, InfeasibleLevelKeepsHigherLevelsAndReportsIt) {
  std::mt19937 g(5);
  static Wbc wbc;
  for (int trial = 0; trial < 20; ++trial) {
    auto L = makeLevels(3, g);  // level 1 (0-based) contradicts level 0's task
    fill(wbc, L);
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Infeasible);
    const auto& res = wbc.result();
    EXPECT_EQ(res.failed_level, 1);
    EXPECT_EQ(res.levels[1].status, hqp::QpStatus::Infeasible);
    EXPECT_TRUE(res.levels[1].constraints_dropped);
    EXPECT_TRUE(res.x.allFinite());
    // The higher level's residual is the one it has alone (its target is reachable: 0).
    EXPECT_LT(res.levels[0].residual, 1e-16 * (1.0 + L[0].b.squaredNorm()));
    // Lower levels are still solved: same residuals as the reference that drops level 1's rows.
    const auto ref = hqp::testing::bruteForceCascade(L, N);
    for (int p = 0; p < 4; ++p)
      EXPECT_NEAR(res.levels[static_cast<size_t>(p)].residual, ref.residual[static_cast<size_t>(p)],
                  1e-8 * (1.0 + ref.residual[static_cast<size_t>(p)]));
    // Making the level feasible again leaves level 0's residual unchanged.
    wbc.level<1>().constraint<0>().lower.setConstant(-hqp::kInf);
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
    EXPECT_LT(wbc.result().levels[0].residual, 1e-16 * (1.0 + L[0].b.squaredNorm()));
  }
}

// Unit vector e_i of R^N as a row.
Eigen::RowVectorXd unitRow(int i) { return Eigen::RowVectorXd::Unit(N, i); }

// The cascade (level 1 solves with its rows), without warm starts: where the routes of the
// least-distance and dual-start tests are tried.
void cascadeCold(Wbc& w) {
  w.setDeferConstraints(false);
  w.setWarmStart(false);
}

// Level 1 (index 0) fixes x0 = x1 = 1. Level 2 (index 1): x4 = 1, x5 = 1 with x2 + x3 ≥ 2; its
// unconstrained minimum-norm step (x2 = x3 = x6 = 0) breaks the row, and its null space
// (x2, x3, x6) fits the last level's dual solver (3 variables: the last level's task rows).
// The least-distance step moves only those: argmin ‖(x2, x3, x6)‖ s.t. x2 + x3 ≥ 2 is
// x2 = x3 = 1, one dual iteration. The lower levels have zero tasks and rows far away, so
// x = (1, 1, 1, 1, 1, 1, 0): the level QP's minimum-norm optimum, which the QP itself returns
// with the step turned off.
std::vector<hqp::testing::RefLevel> leastDistanceLevels(bool reachable) {
  std::vector<hqp::testing::RefLevel> L(4);
  for (int p = 0; p < 4; ++p) {
    auto& l = L[static_cast<size_t>(p)];
    l.A = Eigen::MatrixXd::Zero(kTaskRows[p], N);
    l.b = Eigen::VectorXd::Zero(kTaskRows[p]);
    l.D = Eigen::MatrixXd::Zero(kConRows[p], N);
    l.lower = Eigen::VectorXd::Constant(kConRows[p], -100.0);
    l.upper = Eigen::VectorXd::Constant(kConRows[p], 100.0);
  }
  L[0].A << unitRow(0), unitRow(1);
  L[0].b << 1.0, 1.0;
  L[0].D << unitRow(0), unitRow(1);
  L[1].A << unitRow(4), unitRow(5);
  L[1].b << 1.0, 1.0;
  if (reachable) {
    L[1].D << unitRow(2) + unitRow(3), unitRow(2) - unitRow(3);
    L[1].lower << 2.0, -hqp::kInf;
    L[1].upper << hqp::kInf, 10.0;
  } else {
    // x4 + x5 + x2 ≤ 1 with x2 ≥ 0: no point with x4 = x5 = 1 meets both; the QP's optimum
    // is x4 = x5 = 0.5, x2 = 0 (residual 0.25 + 0.25).
    L[1].D << unitRow(4) + unitRow(5) + unitRow(2), unitRow(2);
    L[1].lower << -hqp::kInf, 0.0;
    L[1].upper << 1.0, hqp::kInf;
  }
  L[2].D << unitRow(6);
  return L;
}

TEST(HqpInequality, LeastDistanceStepGivesTheLevelsMinimumNormOptimum) {
  static Wbc with, without;
  cascadeCold(with);
  cascadeCold(without);
  without.setLeastDistanceStep(false);
  Eigen::Matrix<double, N, 1> expect;
  expect << 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0;
  const auto L = leastDistanceLevels(true);
  fill(with, L);
  fill(without, L);
  ASSERT_EQ(with.solve(), hqp::QpStatus::Optimal);
  ASSERT_EQ(without.solve(), hqp::QpStatus::Optimal);
  EXPECT_FALSE(with.result().levels[0].least_distance);  // its free step meets every row
  const auto& a = with.result().levels[1];
  EXPECT_TRUE(a.least_distance);
  EXPECT_EQ(a.iterations, 1);
  EXPECT_EQ(a.num_active, 0);  // the row holds with multiplier 0: the level sits at its minimum
  EXPECT_LT(a.residual, 1e-28);
  EXPECT_LE((with.result().x - expect).cwiseAbs().maxCoeff(), 1e-14);
  // The QP reaches the same point by its own route.
  EXPECT_FALSE(without.result().levels[1].least_distance);
  EXPECT_GT(without.result().levels[1].iterations, 0);
  EXPECT_LE((without.result().x - expect).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(HqpInequality, LeastDistanceStepLeavesAnInconsistentLevelToItsQp) {
  static Wbc wbc;
  wbc.setDeferConstraints(false);
  wbc.setWarmStart(false);
  fill(wbc, leastDistanceLevels(false));
  ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
  const auto& l = wbc.result().levels[1];
  EXPECT_FALSE(l.least_distance);
  EXPECT_GT(l.iterations, 0);  // the step's failed try, then the QP's
  EXPECT_NEAR(l.residual, 0.5, 1e-14);
  Eigen::Matrix<double, N, 1> expect;
  expect << 1.0, 1.0, 0.0, 0.0, 0.5, 0.5, 0.0;
  EXPECT_LE((wbc.result().x - expect).cwiseAbs().maxCoeff(), 1e-14);
}

// Solves L with `with` (a route switched on) and `without` (switched off) from empty working
// sets and checks that the route changes nothing: status per level, per-level residuals and x
// to rounding, and (check_ref) the residuals against the brute-force cascade.
void expectSameAnswer(Wbc& with, Wbc& without, const std::vector<hqp::testing::RefLevel>& L,
                      int trial, bool check_ref) {
  fill(with, L);
  fill(without, L);
  with.resetWarmStart();  // the routes are tried on empty working sets only
  without.resetWarmStart();
  ASSERT_EQ(with.solve(), without.solve()) << "trial " << trial;
  const auto ref = hqp::testing::bruteForceCascade(L, N);
  for (int p = 0; p < 4; ++p) {
    const size_t q = static_cast<size_t>(p);
    const auto &a = with.result().levels[q], &b = without.result().levels[q];
    EXPECT_EQ(a.status, b.status) << "trial " << trial << " level " << p;
    EXPECT_NEAR(a.residual, b.residual, 1e-9 * (1.0 + b.residual)) << "trial " << trial;
    if (check_ref)
      EXPECT_NEAR(a.residual, ref.residual[q], 1e-8 * (1.0 + ref.residual[q]))
          << "trial " << trial << " level " << p;
  }
  EXPECT_LE((with.result().x - without.result().x).cwiseAbs().maxCoeff(),
            1e-8 * (1.0 + without.result().x.cwiseAbs().maxCoeff())) << "trial " << trial;
}

// On random hierarchies (cascade, cold) the step changes the route, not the answer: the
// per-level residuals and x agree with the QPs' to rounding, and the brute-force reference.
TEST(HqpInequality, LeastDistanceStepAgreesWithTheLevelQps) {
  std::mt19937 g(31);
  static Wbc with, without;
  cascadeCold(with);
  cascadeCold(without);
  without.setLeastDistanceStep(false);
  int steps = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::VectorXd inside;
    auto L = makeLevels(trial % 3, g, &inside);
    // Every other trial, levels 1 and 2 can reach their targets (at a point inside every row):
    // then their free steps often break a row while an unconstrained minimizer meets them all.
    if (trial % 2 == 1)
      for (int p = 0; p < 2; ++p) L[static_cast<size_t>(p)].b = L[static_cast<size_t>(p)].A * inside;
    expectSameAnswer(with, without, L, trial, true);
    for (int p = 0; p < 4; ++p) {
      steps += with.result().levels[static_cast<size_t>(p)].least_distance;
      EXPECT_FALSE(without.result().levels[static_cast<size_t>(p)].least_distance);
    }
  }
  std::printf("least-distance steps taken: %d of 800 levels\n", steps);
  EXPECT_GE(steps, 50);  // the step was taken, not only tried
}

// Dual start: level 2's start x*_1 = 0 breaks its row x0 ≥ 1 and its target (3, 3) is out of
// reach of x0 + x1 ≤ 2, so its QP would run phase 1 (its null space of 5 does not fit the
// least-distance step's solver). Closed form: x0 = x1 = 1 (the projection of (3, 3) onto
// x0 + x1 = 2, which meets x0 ≥ 1), residual 2² + 2², multiplier 2.
TEST(HqpInequality, DualStartHandsTheQpTheLevelsActiveRows) {
  static Wbc with, without;
  cascadeCold(with);
  cascadeCold(without);
  without.setDualStart(false);
  auto L = leastDistanceLevels(true);
  for (auto& l : L) {  // only level 2 has rows: x = (1, 1, 0, …) by minimum norm
    l.A.setZero();
    l.b.setZero();
    l.D.setZero();
    l.lower.setConstant(-100.0);
    l.upper.setConstant(100.0);
  }
  L[1].A << unitRow(0), unitRow(1);
  L[1].b << 3.0, 3.0;
  L[1].D << unitRow(0) + unitRow(1), unitRow(0);
  L[1].lower << -hqp::kInf, 1.0;
  L[1].upper << 2.0, hqp::kInf;
  fill(with, L);
  fill(without, L);
  ASSERT_EQ(with.solve(), hqp::QpStatus::Optimal);
  ASSERT_EQ(without.solve(), hqp::QpStatus::Optimal);
  Eigen::Matrix<double, N, 1> expect = Eigen::Matrix<double, N, 1>::Zero();
  expect(0) = expect(1) = 1.0;
  const auto& a = with.result().levels[1];
  EXPECT_TRUE(a.dual_start);
  EXPECT_FALSE(without.result().levels[1].dual_start);
  EXPECT_NEAR(a.residual, 8.0, 1e-12);
  ASSERT_EQ(a.num_active, 1);  // x0 + x1 ≤ 2 (stacked row 2) at its upper bound
  EXPECT_EQ(a.active_row[0], 2);
  EXPECT_TRUE(a.active_upper[0]);
  EXPECT_NEAR(a.multiplier[0], 2.0, 1e-12);
  EXPECT_LE((with.result().x - expect).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LE((without.result().x - expect).cwiseAbs().maxCoeff(), 1e-14);
  // The dual method's one step replaces phase 1 and the primal steps.
  EXPECT_LT(a.iterations, without.result().levels[1].iterations);
}

// On random hierarchies (cascade, empty working sets, every kind including a dropped level)
// the dual start changes the route, not the answer: statuses, per-level residuals and x agree
// with the run without it, and the residuals with the brute-force reference.
TEST(HqpInequality, DualStartAgreesWithTheLevelQps) {
  std::mt19937 g(47);
  static Wbc with, without;
  cascadeCold(with);
  cascadeCold(without);
  without.setDualStart(false);
  int starts = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto L = makeLevels(trial % 4, g);
    expectSameAnswer(with, without, L, trial, trial % 4 != 3);  // the reference keeps a dropped level's rows
    for (int p = 0; p < 4; ++p) {
      starts += with.result().levels[static_cast<size_t>(p)].dual_start;
      EXPECT_FALSE(without.result().levels[static_cast<size_t>(p)].dual_start);
    }
  }
  std::printf("dual starts taken: %d of 600 levels (levels 2 and 3)\n", starts);
  EXPECT_GE(starts, 100);  // the start was taken, not only tried
}

TEST(HqpInequality, NanInputNeverGivesNan) {
  std::mt19937 g(8);
  static Wbc wbc;
  auto L = makeLevels(0, g);
  L[2].A(0, 0) = std::numeric_limits<double>::quiet_NaN();
  fill(wbc, L);
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_TRUE(wbc.x().allFinite());
  L = makeLevels(0, g);
  L[1].lower(0) = std::numeric_limits<double>::quiet_NaN();
  fill(wbc, L);
  EXPECT_EQ(wbc.solve(), hqp::QpStatus::InvalidInput);
  EXPECT_TRUE(wbc.x().allFinite());
}

TEST(HqpInequality, SlackViolatesOwnConstraintsMinimally) {
  // Level 1's own rows: one contradicts level 0's (locked) task, and the two rows
  // contradict each other along a free direction. With the slack option the violation
  // is the brute-force minimum and the rest of the cascade matches the reference that
  // relaxes the rows to the minimal-violation set.
  std::mt19937 g(12);
  static Wbc wbc;
  ASSERT_TRUE(wbc.setSlack(1, true));
  EXPECT_FALSE(wbc.setSlack(0, true));  // level 0 was not declared with the option
  int checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    auto L = makeLevels(0, g);
    if (trial % 2 == 0) {
      L[1].D.row(0) = L[0].A.row(0);
      L[1].lower(0) = -hqp::kInf;
      L[1].upper(0) = L[0].b(0) - 0.7;  // level 0 reaches its target unless its rows bind
      L[0].D *= 1e-3;                    // level 0's rows hardly bind
    } else {
      L[1].D.row(1) = L[1].D.row(0);
      L[1].lower(0) = 1.0;
      L[1].upper(0) = hqp::kInf;
      L[1].lower(1) = -hqp::kInf;
      L[1].upper(1) = -1.0;
    }
    std::vector<double> viol;
    const auto ref = hqp::testing::bruteForceCascade(L, N, 1e-9, {false, true, false, false}, &viol);
    fill(wbc, L);
    wbc.solve();
    const auto& res = wbc.result();
    ASSERT_TRUE(res.x.allFinite());
    EXPECT_EQ(res.failed_level, 1) << "trial " << trial;
    EXPECT_TRUE(res.levels[1].slack_used);
    EXPECT_FALSE(res.levels[1].constraints_dropped);
    ASSERT_GT(viol[1], 1e-3);
    EXPECT_NEAR(res.levels[1].violation, viol[1], 1e-8 * (1.0 + viol[1])) << "trial " << trial;
    for (int p = 0; p < 4; ++p)
      EXPECT_NEAR(res.levels[static_cast<size_t>(p)].residual, ref.residual[static_cast<size_t>(p)],
                  1e-7 * (1.0 + ref.residual[static_cast<size_t>(p)]))
          << "trial " << trial << " level " << p;
    ++checked;
  }
  EXPECT_EQ(checked, 40);
  wbc.setSlack(1, false);
}

// Both solvers: the dual method (default, the weighted rows have full column rank in almost
// every trial) and ActiveSetQp.
TEST(WqpWbc, EqualsBruteForceWeightedQp) {
 for (const bool dual_method : {true, false}) {
  std::mt19937 g(21);
  static Wqp wqp;
  wqp.setDualMethod(dual_method);
  wqp.resetWarmStart();
  int with_active = 0, dual = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const auto L = makeLevels(trial % 3, g);
    const double ratio = trial % 2 == 0 ? 10.0 : 100.0;
    wqp.setPriorityRatio(ratio);
    wqp.level<1>().task<0>().setWeight(trial % 3 == 0 ? 2.0 : 1.0);
    fill(wqp, L);
    ASSERT_EQ(wqp.solve(), hqp::QpStatus::Optimal) << "trial " << trial;
    // The single weighted QP, stacked independently.
    Eigen::MatrixXd A(9, N), C(5, N);
    Eigen::VectorXd b(9), lo(5), up(5);
    int r = 0, c = 0;
    double lambda = 1.0;
    for (int p = 0; p < 4; ++p) {
      const double w = (p == 1 && trial % 3 == 0) ? 2.0 : 1.0;
      const double s = std::sqrt(lambda * w);
      const auto& l = L[static_cast<size_t>(p)];
      A.middleRows(r, l.A.rows()) = s * l.A;
      b.segment(r, l.b.size()) = s * l.b;
      r += static_cast<int>(l.A.rows());
      C.middleRows(c, l.D.rows()) = l.D;
      lo.segment(c, l.D.rows()) = l.lower;
      up.segment(c, l.D.rows()) = l.upper;
      c += static_cast<int>(l.D.rows());
      lambda /= ratio;
    }
    const auto bf = hqp::testing::bruteForceQp(A, b, Eigen::MatrixXd(0, N), Eigen::VectorXd(0), C, lo, up);
    ASSERT_TRUE(bf.feasible);
    EXPECT_NEAR(wqp.result().objective, 2.0 * bf.objective, 1e-9 * (1.0 + bf.objective));
    EXPECT_LT((wqp.x() - bf.x).norm(), 1e-7 * (1.0 + bf.x.norm())) << "trial " << trial;
    with_active += wqp.result().num_active > 0;
    dual += wqp.result().dual;
  }
  EXPECT_GT(with_active, 30);
  if (dual_method) EXPECT_GT(dual, 50);
  else EXPECT_EQ(dual, 0);
 }
}

TEST(WqpWbc, HugeRatioApproachesTheHierarchy) {
  // Conflicting tasks without binding constraints: the residuals of the weighted
  // solution tend to the strict ones as the ratio grows, the gap shrinking with the ratio.
  std::mt19937 g(44);
  static Wqp wqp;
  static Wbc wbc;
  int checked = 0;
  for (int trial = 0; trial < 10; ++trial) {
    auto L = makeLevels(0, g);
    L[1].A.row(0) = L[0].A.row(1);  // exact conflicts with a higher level, other targets
    L[2].A.row(1) = L[1].A.row(1);
    L[3].A.row(0) = L[0].A.row(0);
    for (auto& l : L) {
      l.lower.setConstant(-1e3);
      l.upper.setConstant(1e3);
    }
    fill(wbc, L);
    ASSERT_EQ(wbc.solve(), hqp::QpStatus::Optimal);
    fill(wqp, L);
    double prev_gap = hqp::kInf;
    for (double ratio : {1e2, 1e4, 1e6}) {
      wqp.setPriorityRatio(ratio);
      ASSERT_EQ(wqp.solve(), hqp::QpStatus::Optimal);
      double gap = 0.0;
      for (int p = 0; p < 3; ++p)
        gap = std::max(gap, std::abs(wqp.result().residual[static_cast<size_t>(p)] -
                                     wbc.result().levels[static_cast<size_t>(p)].residual) /
                                (1.0 + wbc.result().levels[static_cast<size_t>(p)].residual));
      EXPECT_LT(gap, prev_gap + 1e-12);
      prev_gap = gap;
    }
    EXPECT_LT(prev_gap, 1e-4) << "trial " << trial;
    // the top level is (nearly) as good as in the hierarchy and never better
    EXPECT_GE(wqp.result().residual[0] + 1e-9, wbc.result().levels[0].residual);
    ++checked;
  }
  EXPECT_EQ(checked, 10);
}
