// Walker3 standing still, from an installed hqp_wbc (tests/install/install_test.cmake):
// the controller from its YAML (argv[1]) ticks on the sensor readings of a robot at rest in a
// crouch, each sole carrying half the weight at its centre. The readings come from the model
// layer alone. Prints "ok: 10 ticks" when every command is finite and the controller
// balances (no safe mode).
#include <cmath>
#include <cstdio>
#include <memory>

#include "hqp/version.hpp"
#include "model/configuration.hpp"
#include "model/robot_dynamics.hpp"
#include "tasks/controller.hpp"
#include "tasks/controller_config_yaml.hpp"   // start-up only (yaml-cpp)
#include "walker3_model.hpp"

using Robot = walker3::Robot;
using Controller = hqp::tasks::Controller<hqp::tasks::ContactLayout<Robot, 2, 6>>;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: stand controller.yaml\n");
    return 2;
  }
  using F = Robot::Frames;
  using J = Robot::Joints;

  // The crouch of robots/walker3/README.md (hip -0.3, knee 0.6, ankle -0.3), base upright,
  // lowered until the soles are on z = 0.
  auto q = hqp::model::neutralConfiguration<Robot>();
  for (int j : {J::l_hip_pitch, J::r_hip_pitch, J::l_ankle_pitch, J::r_ankle_pitch}) q(7 + j) = -0.3;
  for (int j : {J::l_knee, J::r_knee}) q(7 + j) = 0.6;
  const Eigen::Matrix<double, Robot::nv, 1> v = Eigen::Matrix<double, Robot::nv, 1>::Zero();
  hqp::model::RobotDynamics<Robot, 5> dyn({F::l_sole, F::r_sole, F::imu, F::l_ft_sensor, F::r_ft_sensor});
  dyn.calcWbcDependence(q, v);
  q(2) -= 0.5 * (dyn.placement(0).translation().z() + dyn.placement(1).translation().z());
  dyn.calcWbcDependence(q, v);

  // What the sensors of that robot at rest read: encoders, the IMU (gravity's specific force),
  // and each F/T sensor the wrench of m g / 2 pushing up at its sole's centre.
  Controller::Sensors sensors;
  sensors.q = q.tail<Robot::nj>();
  const Eigen::Matrix3d R_imu = dyn.placement(2).linear();
  sensors.imu_orientation = Eigen::Quaterniond(R_imu);
  sensors.imu_accel = R_imu.transpose() * Eigen::Vector3d(0, 0, hqp::model::kGravity);
  for (int c = 0; c < 2; ++c) {
    const Eigen::Vector3d f(0, 0, 0.5 * Robot::total_mass * hqp::model::kGravity);
    const Eigen::Isometry3d& sensor = dyn.placement(3 + c);
    const Eigen::Vector3d m = (dyn.placement(c).translation() - sensor.translation()).cross(f);
    sensors.ft[c].head<3>() = sensor.linear().transpose() * f;
    sensors.ft[c].tail<3>() = sensor.linear().transpose() * m;
  }

  auto config = hqp::tasks::loadControllerConfig<Robot>(argv[1]);
  config.planner.com_height = dyn.com().z();   // the planner's C for this pose
  // On the heap, once: the controller holds both solvers (about 1 MB, docs/controller.md);
  // its tick never allocates.
  auto ctrl = std::make_unique<Controller>(config, std::array<int, 2>{F::l_sole, F::r_sole},
                                           std::array<int, 2>{F::l_ft_sensor, F::r_ft_sensor}, F::imu);
  Controller::Command command;
  const int ticks = 10;
  for (int k = 0; k < ticks; ++k) {
    sensors.time = k * config.dt;
    ctrl->tick(sensors, command);
    const bool finite = command.torque.allFinite() && command.current.allFinite();
    if (!finite || command.safe_mode || ctrl->diagnostics().mode != hqp::tasks::ControllerMode::Balance) {
      std::printf("tick %d: finite %d, safe mode %d\n", k, finite, command.safe_mode);
      return 1;
    }
  }
  std::printf("hqp %s, %s: knee torques %.2f %.2f N m\n", HQP_VERSION_STRING, Robot::name,
              command.torque(J::l_knee), command.torque(J::r_knee));
  std::printf("ok: %d ticks\n", ticks);
  return 0;
}
