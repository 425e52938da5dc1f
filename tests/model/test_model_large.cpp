// nv > 128: a 200-joint chain on a floating base (nv = 206, written by tests/model/CMakeLists.txt).
// Its M is 206 x 206 doubles (332 KiB), above Eigen's limit for fixed-size objects, so Data
// stores it as a MappedMatrix. The model layer must compile for it and agree with MuJoCo.
#include <gtest/gtest.h>

#include <memory>
#include <type_traits>

#include "chain200_model.hpp"
#include "mujoco/dynamics_crosscheck.hpp"

namespace {

using Robot = chain200::Robot;
using Data = hqp::model::Data<Robot>;
static_assert(Robot::nv == 206 && Robot::nb == 201);
static_assert(std::is_same_v<Data::MatrixV, hqp::model::MappedMatrix<206, 206>>);

// Every quantity of the model layer at a few random states (each state is O(nv^2) per frame).
TEST(LargeModel, Chain200AgreesWithMujoco) {
  const std::array<int, 2> frames = {Robot::frameIndex("tip"), Robot::frameIndex("l100")};
  hqp::test::crossCheckWithMujoco<Robot, 2>(HQP_CHAIN_URDF, frames, 4, 7001u);
}

// A copy of Data owns its own M: writing the original leaves the copy as it was.
TEST(LargeModel, DataCopyOwnsItsMassMatrix) {
  auto a = std::make_unique<Data>();
  Data::VectorQ q = hqp::model::neutralConfiguration<Robot>();
  hqp::model::crba(*a, q);
  const Eigen::MatrixXd M = a->M;
  ASSERT_GT(M.cwiseAbs().maxCoeff(), 0.0);
  auto b = std::make_unique<Data>(*a);
  EXPECT_NE(b->M.data(), a->M.data());
  a->M.setZero();
  EXPECT_EQ(Eigen::MatrixXd(b->M), M);
  *a = *b;
  EXPECT_NE(a->M.data(), b->M.data());
  EXPECT_EQ(Eigen::MatrixXd(a->M), M);
}

}  // namespace
