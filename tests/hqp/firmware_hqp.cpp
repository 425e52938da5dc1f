// Firmware build check: the hierarchy headers compile and work with -fno-exceptions
// -fno-rtti. Solves a 3-level hierarchy whose strict solution is known in closed form.
#include <cmath>

// Per-level timing compiled out (time_us is 0 whatever HqpSettings::time_levels says).
#define HQP_NO_LEVEL_TIMING
#include "hqp/hqp_wbc.hpp"
#include "hqp/wqp_wbc.hpp"

namespace {

constexpr int N = 4;
using L1 = hqp::Level<N, hqp::TaskList<hqp::Task<2, N>>, hqp::ConstraintList<hqp::Constraint<1, N>>>;
using L2 = hqp::Level<N, hqp::TaskList<hqp::Task<2, N>>>;
using L3 = hqp::Level<N, hqp::TaskList<hqp::Task<1, N>>>;

// Level 1: x0 = 1, x1 = 2, and x2 ≤ 0.5.  Level 2: x2 = 1 (clipped by level 1's bound),
// x0 = 5 (conflicts with level 1: ignored).  Level 3: x3 − x2 = 1.
// Strict solution: x = (1, 2, 0.5, 1.5).
template <class W>
void fill(W& w) {
  auto& t1 = w.template level<0>().template task<0>();
  t1.A << 1, 0, 0, 0, 0, 1, 0, 0;
  t1.b << 1, 2;
  auto& c1 = w.template level<0>().template constraint<0>();
  c1.D << 0, 0, 1, 0;
  c1.setUpperBound(Eigen::Matrix<double, 1, 1>(0.5));
  auto& t2 = w.template level<1>().template task<0>();
  t2.A << 0, 0, 1, 0, 1, 0, 0, 0;
  t2.b << 1, 5;
  auto& t3 = w.template level<2>().template task<0>();
  t3.A << 0, 0, -1, 1;
  t3.b << 1;
}

hqp::HqpWbc<N, L1, L2, L3> g_hqp;  // static storage: large objects stay off the stack
hqp::WqpWbc<N, L1, L2, L3> g_wqp;

}  // namespace

int main() {
  fill(g_hqp);
  if (g_hqp.solve() != hqp::QpStatus::Optimal) return 1;
  const Eigen::Vector4d expected(1.0, 2.0, 0.5, 1.5);
  if ((g_hqp.x() - expected).norm() > 1e-9) return 2;
  const auto& r = g_hqp.result();
  if (r.levels[0].null_dim != 2 || r.levels[1].null_dim != 1 || r.levels[2].null_dim != 0) return 3;
  if (r.levels[1].num_active != 1 || r.levels[1].active_row[0] != 0 || !r.levels[1].active_upper[0])
    return 4;
  if (std::abs(r.levels[1].residual - (0.25 + 16.0)) > 1e-9) return 5;
  for (const auto& lr : r.levels)
    if (lr.time_us != 0.0) return 8;
  // Certificate of level 2: ½((x2 − 1)² + (x0 − 5)²) over x2, x3 (x0, x1 fixed by level 1), with
  // x2 ≤ 0.5 active: (x2 − 1) + λ = 0, λ = 0.5 ≥ 0 at the upper bound.
  if (std::abs(r.levels[1].multiplier[0] - 0.5) > 1e-9) return 9;
  g_hqp.setKktResiduals(true);
  fill(g_hqp);
  g_hqp.solve();
  for (const auto& lr : r.levels)
    if (!lr.kkt.computed || lr.kkt.stationarity > 1e-12 || lr.kkt.primal > 1e-12 ||
        lr.kkt.dual > 0.0 || lr.kkt.complementarity > 1e-12)
      return 10;

  // The weighted QP with a large ratio lands close to the strict solution.
  fill(g_wqp);
  g_wqp.setPriorityRatio(1e6);
  if (g_wqp.solve() != hqp::QpStatus::Optimal) return 6;
  if ((g_wqp.x() - expected).norm() > 1e-4) return 7;
  return 0;
}
