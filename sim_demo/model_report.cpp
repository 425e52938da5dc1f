// The main job until the MuJoCo scenarios exist: a report on the Walker3 model generated from
// robots/walker3/walker3.urdf — size, mass, CoM, gravity torques and the cost of one dynamics update.
#include <CLI/CLI.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "model/robot_dynamics.hpp"
#include "walker3_model.hpp"

namespace {

using Robot = walker3::Robot;
using Dynamics = hqp::model::RobotDynamics<Robot, 2>;
using VectorQ = hqp::model::Data<Robot>::VectorQ;
using VectorV = hqp::model::Data<Robot>::VectorV;

// Standing pose: knees bent by `knee` rad, hip and ankle pitch sharing the bend so the feet stay flat.
VectorQ standingPose(double knee) {
  VectorQ q = hqp::model::neutralConfiguration<Robot>();
  for (const char* side : {"l_", "r_"}) {
    const std::string s(side);
    q[7 + Robot::jointIndex(s + "hip_pitch")] = -0.5 * knee;
    q[7 + Robot::jointIndex(s + "knee")] = knee;
    q[7 + Robot::jointIndex(s + "ankle_pitch")] = -0.5 * knee;
  }
  return q;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Walker3 model report: DoF, mass, CoM, gravity torques, dynamics update time"};
  double knee = 0.6;
  int iterations = 20000;
  app.add_option("--knee", knee, "knee bend of the standing pose (rad)")->capture_default_str();
  app.add_option("--iterations", iterations, "dynamics updates to time")->capture_default_str()
      ->check(CLI::Range(100, 10000000));
  CLI11_PARSE(app, argc, argv);

  const int l_sole = Robot::frameIndex("l_sole");
  const int r_sole = Robot::frameIndex("r_sole");
  Dynamics dyn({l_sole, r_sole});

  // Place the base so that both soles touch z = 0.
  VectorQ q = standingPose(knee);
  const VectorV v = VectorV::Zero();
  dyn.calcWbcDependence(q, v);
  q[2] -= 0.5 * (dyn.placement(0).translation().z() + dyn.placement(1).translation().z());
  dyn.calcWbcDependence(q, v);

  std::printf("Walker3 model report (generated from robots/walker3/walker3.urdf)\n");
  std::printf("  degrees of freedom : nq = %d, nv = %d (6 floating base + %d joints), %d bodies, %d frames\n",
              Robot::nq, Robot::nv, Robot::nj, Robot::nb, Robot::nframes);
  std::printf("  total mass         : %.3f kg\n", dyn.mass());
  std::printf("  standing pose      : knee %.2f rad, base height %.4f m\n", knee, q[2]);
  std::printf("  CoM                : (%.4f, %.4f, %.4f) m, height %.4f m above the soles\n",
              dyn.com().x(), dyn.com().y(), dyn.com().z(), dyn.com().z());

  // Gravity torques. (a) Hung by the torso: the joint part of G. (b) Standing: the feet carry the
  // weight; the contact wrenches of least norm that balance the base rows of eq. (1),
  // S_f (G - J^T F) = 0, give tau = S_a (G - J^T F).
  hqp::model::Data<Robot> data;
  const VectorV g = hqp::model::computeGravity(data, q);
  Eigen::Matrix<double, 12, Robot::nv> Jc;
  Jc << dyn.J(0), dyn.J(1);
  const Eigen::Matrix<double, 6, 12> base_rows = Jc.leftCols<6>().transpose();
  const Eigen::Matrix<double, 12, 1> F =
      base_rows.completeOrthogonalDecomposition().solve(g.head<6>());
  const Eigen::Matrix<double, Robot::nj, 1> tau_stand =
      g.tail<Robot::nj>() - Jc.rightCols<Robot::nj>().transpose() * F;

  std::printf("  foot forces        : left fz %.1f N, right fz %.1f N (m g = %.1f N)\n", F[2], F[8],
              dyn.mass() * 9.81);
  std::printf("\n  %-16s %10s %10s %12s %12s\n", "joint", "limit N m", "Coulomb", "G hung N m",
              "stand N m");
  for (int j = 0; j < Robot::nj; ++j) {
    const auto& b = Robot::bodies[j + 1];
    std::printf("  %-16s %10.1f %10.2f %12.3f %12.3f\n", b.joint, b.effort, b.friction,
                g[6 + j], tau_stand[j]);
  }

  // Cost of one calcWbcDependence at a non-zero state: median over batches.
  VectorV vr = VectorV::Zero();
  for (int i = 0; i < Robot::nv; ++i) vr[i] = 0.3 * std::sin(1.0 + i);
  constexpr int batch = 100;
  std::vector<double> per_call;
  per_call.reserve(iterations / batch + 1);
  for (int b = 0; b < iterations / batch; ++b) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < batch; ++i) dyn.calcWbcDependence(q, vr);
    const auto t1 = std::chrono::steady_clock::now();
    per_call.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / batch);
  }
  std::sort(per_call.begin(), per_call.end());
  std::printf("\n  calcWbcDependence  : median %.2f us, min %.2f us, max %.2f us per call"
              " (%d calls; M, h, 2 sole J and Jdot v, CoM, A_G)\n",
              per_call[per_call.size() / 2], per_call.front(), per_call.back(),
              static_cast<int>(per_call.size()) * batch);
  std::printf("  budget             : %.2f %% of the 1 ms control tick\n",
              100.0 * per_call[per_call.size() / 2] / 1000.0);
  return 0;
}
