// Model-layer benchmarks on Walker3 at a seeded random non-zero state, with
// MuJoCo 2.2.2 doing the equivalent work on the same URDF in the same binary.
//   BM_Hqp_*    include/model (this project)
//   BM_MuJoCo_* MuJoCo components (mj_kinematics, mj_comPos, mj_crb, ...)
// Pairs: CalcWbcDependence ~ WholeUpdate, Crba ~ Crba, NonLinearEffects ~ Rne,
// SoleJacobians ~ SoleJacobians. Run:
//   bench_model --benchmark_repetitions=10 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <array>
#include <random>
#include <string>
#include <vector>

#include "model/robot_dynamics.hpp"
#include "support/urdf_to_mujoco.hpp"
#include "walker3_model.hpp"

namespace {

namespace hm = hqp::model;
using Robot = walker3::Robot;
using VectorQ = hm::Data<Robot>::VectorQ;
using VectorV = hm::Data<Robot>::VectorV;

// Seeded random state: base within 1 m, any orientation, joints within ±1 rad,
// rates within ±1 (non-zero everywhere, so every term is exercised).
struct State {
  VectorQ q;
  VectorV v;
  State() {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    q = hm::neutralConfiguration<Robot>();
    q.head<3>() << u(rng), u(rng), 0.8 + 0.1 * u(rng);
    Eigen::Quaterniond quat(1.0, 0.2 * u(rng), 0.2 * u(rng), 0.2 * u(rng));
    quat.normalize();
    q[3] = quat.w();
    q[4] = quat.x();
    q[5] = quat.y();
    q[6] = quat.z();
    for (int i = 7; i < Robot::nq; ++i) q[i] = u(rng);
    for (int i = 0; i < Robot::nv; ++i) v[i] = u(rng);
  }
};
const State& state() {
  static const State s;
  return s;
}

const std::array<int, 3>& taskFrames() {
  static const std::array<int, 3> f = {Robot::frameIndex("l_sole"), Robot::frameIndex("r_sole"),
                                       Robot::frameIndex("torso")};
  return f;
}

void BM_Hqp_CalcWbcDependence(benchmark::State& st) {
  hm::RobotDynamics<Robot, 3> dyn(taskFrames());
  const State& s = state();
  for (auto _ : st) {
    dyn.calcWbcDependence(s.q, s.v);
    benchmark::DoNotOptimize(dyn.M().data());
    benchmark::DoNotOptimize(dyn.dAg_v().data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Hqp_CalcWbcDependence);

void BM_Hqp_Crba(benchmark::State& st) {
  hm::Data<Robot> d;
  const State& s = state();
  for (auto _ : st) {
    hm::crba(d, s.q);
    benchmark::DoNotOptimize(d.M.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Hqp_Crba);

void BM_Hqp_NonLinearEffects(benchmark::State& st) {
  hm::Data<Robot> d;
  const State& s = state();
  for (auto _ : st) {
    hm::nonLinearEffects(d, s.q, s.v);
    benchmark::DoNotOptimize(d.h.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Hqp_NonLinearEffects);

// Placements, then the two sole Jacobians.
void BM_Hqp_SoleJacobians(benchmark::State& st) {
  hm::Data<Robot> d;
  hm::Data<Robot>::Jacobian Jl, Jr;
  const State& s = state();
  const int l = taskFrames()[0];
  const int r = taskFrames()[1];
  for (auto _ : st) {
    hm::forwardKinematics(d, s.q);
    hm::frameJacobian(d, l, Jl);
    hm::frameJacobian(d, r, Jr);
    benchmark::DoNotOptimize(Jl.data());
    benchmark::DoNotOptimize(Jr.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Hqp_SoleJacobians);

// ---- MuJoCo on the same URDF (floating base wrapper, no fusing, URDF inertias) ----
struct Mujoco {
  hqp::test::MjModelPtr m;
  hqp::test::MjDataPtr d;
  std::vector<mjtNum> M, jac_l, jac_r, jac_t, jacr_l, jacr_r, jacr_t, jac_com, bias;
  int l = -1, r = -1, t = -1;
  Mujoco() {
    const std::string urdf = std::string(HQP_SOURCE_DIR) + "/robots/walker3/walker3.urdf";
    m = hqp::test::loadUrdfFileIntoMujoco(urdf, true);
    d.reset(mj_makeData(m.get()));
    const int nv = m->nv;
    M.resize(static_cast<std::size_t>(nv * nv));
    for (auto* v : {&jac_l, &jac_r, &jac_t, &jacr_l, &jacr_r, &jacr_t, &jac_com}) {
      v->resize(static_cast<std::size_t>(3 * nv));
    }
    bias.resize(static_cast<std::size_t>(nv));
    l = mj_name2id(m.get(), mjOBJ_BODY, "l_sole");
    r = mj_name2id(m.get(), mjOBJ_BODY, "r_sole");
    t = mj_name2id(m.get(), mjOBJ_BODY, "torso");
    // Same state, mapped by joint name; MuJoCo's free joint takes the world linear velocity.
    const State& s = state();
    const Eigen::Quaterniond quat(s.q[3], s.q[4], s.q[5], s.q[6]);
    const Eigen::Vector3d vw = quat.toRotationMatrix() * s.v.head<3>();
    for (int k = 0; k < 7; ++k) d->qpos[k] = s.q[k];
    for (int k = 0; k < 3; ++k) {
      d->qvel[k] = vw[k];
      d->qvel[3 + k] = s.v[3 + k];
    }
    for (int i = 1; i < Robot::nb; ++i) {
      const hm::BodyDesc& b = Robot::bodies[static_cast<std::size_t>(i)];
      const int j = mj_name2id(m.get(), mjOBJ_JOINT, b.joint);
      d->qpos[m->jnt_qposadr[j]] = s.q[b.idx_q];
      d->qvel[m->jnt_dofadr[j]] = s.v[b.idx_v];
    }
  }
};
Mujoco& mujoco() {
  static Mujoco mj;
  return mj;
}

void BM_MuJoCo_WholeUpdate(benchmark::State& st) {
  Mujoco& mj = mujoco();
  if (mj.l < 0 || mj.r < 0 || mj.t < 0) st.SkipWithError("sole/torso bodies not found in MuJoCo");
  const mjModel* m = mj.m.get();
  mjData* d = mj.d.get();
  for (auto _ : st) {
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_crb(m, d);
    mj_fullM(m, mj.M.data(), d->qM);
    mj_comVel(m, d);
    mj_rne(m, d, 0, mj.bias.data());
    mj_jacBody(m, d, mj.jac_l.data(), mj.jacr_l.data(), mj.l);
    mj_jacBody(m, d, mj.jac_r.data(), mj.jacr_r.data(), mj.r);
    mj_jacBody(m, d, mj.jac_t.data(), mj.jacr_t.data(), mj.t);
    mj_jacSubtreeCom(m, d, mj.jac_com.data(), 0);
    mj_subtreeVel(m, d);
    benchmark::DoNotOptimize(mj.M.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MuJoCo_WholeUpdate);

void BM_MuJoCo_Crba(benchmark::State& st) {
  Mujoco& mj = mujoco();
  const mjModel* m = mj.m.get();
  mjData* d = mj.d.get();
  for (auto _ : st) {
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_crb(m, d);
    mj_fullM(m, mj.M.data(), d->qM);
    benchmark::DoNotOptimize(mj.M.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MuJoCo_Crba);

void BM_MuJoCo_Rne(benchmark::State& st) {
  Mujoco& mj = mujoco();
  const mjModel* m = mj.m.get();
  mjData* d = mj.d.get();
  for (auto _ : st) {
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_comVel(m, d);
    mj_rne(m, d, 0, mj.bias.data());
    benchmark::DoNotOptimize(mj.bias.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MuJoCo_Rne);

void BM_MuJoCo_SoleJacobians(benchmark::State& st) {
  Mujoco& mj = mujoco();
  const mjModel* m = mj.m.get();
  mjData* d = mj.d.get();
  for (auto _ : st) {
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_jacBody(m, d, mj.jac_l.data(), mj.jacr_l.data(), mj.l);
    mj_jacBody(m, d, mj.jac_r.data(), mj.jacr_r.data(), mj.r);
    benchmark::DoNotOptimize(mj.jac_l.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MuJoCo_SoleJacobians);

}  // namespace

BENCHMARK_MAIN();
