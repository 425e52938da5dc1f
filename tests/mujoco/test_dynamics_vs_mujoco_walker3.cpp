// Walker3: our dynamics against MuJoCo 2.2.2 at 1000 random states (tolerances and error
// measure: dynamics_crosscheck.hpp).
#include "walker3_model.hpp"

#include "dynamics_crosscheck.hpp"

namespace {

using walker3::Robot;

TEST(DynamicsVsMujoco, Walker3) {
  const std::array<int, 4> frames = {Robot::frameIndex("l_sole"), Robot::frameIndex("r_sole"),
                                     Robot::frameIndex("imu"), Robot::frameIndex("torso")};
  hqp::test::crossCheckWithMujoco<Robot, 4>(HQP_SOURCE_DIR "/robots/walker3/walker3.urdf", frames,
                                            1000, 3001u);
}

}  // namespace
