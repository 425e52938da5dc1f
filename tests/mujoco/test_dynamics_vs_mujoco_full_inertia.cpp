// full_inertia_tree.urdf: full inertia tensors in rotated inertial frames, masses on links fused
// by fixed joints, oblique axes, every joint type; as a floating and as a fixed-base robot.
// Our dynamics against MuJoCo 2.2.2 at 200 random states each (dynamics_crosscheck.hpp).
#include "mj_full_inertia_fixed_model.hpp"
#include "mj_full_inertia_model.hpp"

#include "dynamics_crosscheck.hpp"

namespace {

template <class Robot>
void check(unsigned seed, bool exact_inertia = true, double tol = hqp::test::kCrossCheckTol) {
  const std::array<int, 3> frames = {Robot::frameIndex("tip"), Robot::frameIndex("battery"),
                                     Robot::frameIndex("hand")};
  hqp::test::crossCheckWithMujoco<Robot, 3>(HQP_MJ_TEST_DIR "/full_inertia_tree.urdf", frames, 200,
                                            seed, exact_inertia, tol);
}

TEST(DynamicsVsMujoco, FullInertiaFloating) { check<mj_full_inertia::Robot>(5001u); }
TEST(DynamicsVsMujoco, FullInertiaFixedBase) { check<mj_full_inertia_fixed::Robot>(5002u); }
// Against MuJoCo's own principal inertias (its eigen-solver is good to ~1e-7 relative here).
TEST(DynamicsVsMujoco, FullInertiaFloatingMujocoOwnInertia) {
  check<mj_full_inertia::Robot>(5003u, false, 1e-6);
}

}  // namespace
