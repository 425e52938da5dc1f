// Built against an installed hqp_wbc by tests/install/install_test.cmake (step 5).
#include <cstdio>

#include "my_robot_model.hpp"

static_assert(my_robot::Robot::nv == 7, "fused_pair.urdf: free base + one joint");
static_assert(my_robot::Robot::Frames::tip == 2, "FRAMES tip: bodies first, then tip");

int main() {
  std::printf("nv=%d nframes=%d\n", my_robot::Robot::nv, my_robot::Robot::nframes);
  return 0;
}
