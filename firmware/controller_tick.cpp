// The firmware's only translation unit that instantiates the Controller (compiled with
// -fno-exceptions -fno-rtti: the whole tick builds as robot firmware would build it).
#include "tasks/contact_layout.hpp"
#include "tasks/controller.hpp"
#include "walker3_firmware.hpp"

namespace hqp::firmware {

using Layout = hqp::tasks::ContactLayout<Robot, kContacts, 6>;

struct FirmwareController::Impl {
  explicit Impl(const Config& c)
      : controller(c, {Robot::Frames::l_sole, Robot::Frames::r_sole},
                   {Robot::Frames::l_ft_sensor, Robot::Frames::r_ft_sensor}, Robot::Frames::imu) {}
  hqp::tasks::Controller<Layout> controller;
};

FirmwareController::FirmwareController(const Config& config) : impl_(new Impl(config)) {}
FirmwareController::~FirmwareController() { delete impl_; }

void FirmwareController::tick(const Sensors& s, Command& cmd) noexcept { impl_->controller.tick(s, cmd); }
void FirmwareController::reset() noexcept { impl_->controller.reset(); }

TickInfo FirmwareController::info() const noexcept {
  const auto& d = impl_->controller.diagnostics();
  TickInfo t;
  t.safe_mode = d.mode == hqp::tasks::ControllerMode::Safe;
  t.safe_reason = static_cast<int>(d.reason);
  t.cut_level = d.cut_level;
  t.budget_cuts = d.budget_cuts;
  for (const auto& l : d.levels) t.iterations += l.iterations;
  t.solve_us = d.time_us[static_cast<int>(hqp::tasks::Stage::Solve)];
  return t;
}

}  // namespace hqp::firmware
