// Random kinematic trees (tools/random_urdf.cpp; trees 0-3 floating, tree 4 fixed-base with
// revolute, continuous, prismatic and fixed joints): our dynamics against MuJoCo 2.2.2 at 300
// random states each (tolerances and error measure: dynamics_crosscheck.hpp).
#include "random_tree0_model.hpp"
#include "random_tree1_model.hpp"
#include "random_tree2_model.hpp"
#include "random_tree3_model.hpp"
#include "random_tree4_model.hpp"

#include "dynamics_crosscheck.hpp"

namespace {

template <class Robot>
void checkTree(int k) {
  static_assert(Robot::nframes >= 1, "a tree has frames");
  const std::array<int, 3> frames = {0, Robot::nframes / 2, Robot::nframes - 1};
  const std::string urdf = std::string(HQP_RANDOM_TREE_DIR) + "/tree" + std::to_string(k) + ".urdf";
  hqp::test::crossCheckWithMujoco<Robot, 3>(urdf, frames, 300, 4000u + static_cast<unsigned>(k));
}

TEST(DynamicsVsMujoco, RandomTree0) { checkTree<random_tree0::Robot>(0); }
TEST(DynamicsVsMujoco, RandomTree1) { checkTree<random_tree1::Robot>(1); }
TEST(DynamicsVsMujoco, RandomTree2) { checkTree<random_tree2::Robot>(2); }
TEST(DynamicsVsMujoco, RandomTree3) { checkTree<random_tree3::Robot>(3); }
TEST(DynamicsVsMujoco, RandomTree4FixedBase) {
  static_assert(!random_tree4::Robot::floating_base, "tree 4 is the fixed-base tree");
  checkTree<random_tree4::Robot>(4);
}

}  // namespace
