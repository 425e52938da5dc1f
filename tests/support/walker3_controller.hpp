#pragma once
// The Walker3 balance controller as the tests and the benchmark build it: the shipped
// robots/walker3/controller.yaml with the solver and the planner's C chosen by the caller,
// wired to the soles, the F/T sensors and the IMU. Needs HQP_SOURCE_DIR and yaml-cpp.

#include <array>
#include <memory>

#include "tasks/controller.hpp"
#include "tasks/controller_config_yaml.hpp"
#include "walker3_model.hpp"

namespace hqp::testing {

using Walker3Controller = hqp::tasks::Controller<hqp::tasks::ContactLayout<walker3::Robot, 2, 6>>;

inline Walker3Controller::Config walker3Config(Walker3Controller::Config::Solver solver,
                                               double com_height) {
  auto cfg = hqp::tasks::loadControllerConfig<walker3::Robot>(HQP_SOURCE_DIR "/robots/walker3/controller.yaml");
  cfg.solver = solver;
  cfg.planner.com_height = com_height;  // C of Sec. III-A for the pose under test
  return cfg;
}

// On the heap: the controller holds both solvers (about 1 MB, docs/controller.md).
inline std::unique_ptr<Walker3Controller> makeWalker3Controller(const Walker3Controller::Config& cfg) {
  using R = walker3::Robot;
  return std::make_unique<Walker3Controller>(
      cfg, std::array<int, 2>{R::Frames::l_sole, R::Frames::r_sole},
      std::array<int, 2>{R::Frames::l_ft_sensor, R::Frames::r_ft_sensor}, R::Frames::imu);
}

}  // namespace hqp::testing
