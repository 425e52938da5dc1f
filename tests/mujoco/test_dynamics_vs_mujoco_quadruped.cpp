// Quadruped: our dynamics against MuJoCo 2.2.2 at 500 random states (tolerances and error
// measure: dynamics_crosscheck.hpp).
#include "quadruped_model.hpp"

#include "dynamics_crosscheck.hpp"

namespace {

using quadruped::Robot;

TEST(DynamicsVsMujoco, Quadruped) {
  const std::array<int, 3> frames = {0, Robot::nframes / 2, Robot::nframes - 1};
  hqp::test::crossCheckWithMujoco<Robot, 3>(HQP_SOURCE_DIR "/robots/quadruped/quadruped.urdf",
                                            frames, 500, 3002u);
}

}  // namespace
