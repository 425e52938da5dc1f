// The sizes of Walker3's solvers and Controller, printed for docs/hqp.md and docs/controller.md,
// and the reason those docs give for constructing them static or on the heap: each is larger
// than 64 kB, a common real-time thread stack. Class layouts only (no solver code is compiled).
#include <gtest/gtest.h>

#include <cstdio>

#include "tasks/controller.hpp"
#include "walker3_model.hpp"

namespace {

using Layout = hqp::tasks::ContactLayout<walker3::Robot, 2, 6>;
using Controller = hqp::tasks::Controller<Layout>;

TEST(ObjectSizes, Walker3SolversAndControllerAreTooLargeForAThreadStack) {
  const std::size_t hqp = sizeof(Controller::Hqp), wqp = sizeof(Controller::Wqp), ctrl = sizeof(Controller);
  std::printf("sizeof: HqpWbc %zu B (%.0f KiB), WqpWbc %zu B (%.0f KiB), Controller %zu B (%.0f KiB)\n", hqp,
              hqp / 1024.0, wqp, wqp / 1024.0, ctrl, ctrl / 1024.0);
  constexpr std::size_t kStack = 64 * 1024;
  EXPECT_GT(hqp, kStack);
  EXPECT_GT(wqp, kStack);
  EXPECT_GT(ctrl, hqp + wqp);  // the Controller holds both solvers
}

}  // namespace
