#pragma once
// The Walker3 balance controller as the firmware loop drives it. The Controller itself is
// compiled in one translation unit (controller_tick.cpp) with -fno-exceptions -fno-rtti, as
// robot firmware builds it; the YAML loading (config.cpp) is a separate unit with exceptions,
// used before the loop starts only.

#include <string>

#include "tasks/controller_config.hpp"
#include "tasks/sensor_data.hpp"
#include "walker3_model.hpp"

namespace hqp::firmware {

using Robot = walker3::Robot;
constexpr int kJoints = Robot::nj;
constexpr int kContacts = 2;  // left, right sole
using Sensors = hqp::tasks::SensorData<kJoints, kContacts>;
using Command = hqp::tasks::ActuatorCommand<kJoints>;
using Config = hqp::tasks::ControllerConfig<kJoints>;

// What one tick did, for the loop's accounting (ControllerDiagnostics, abridged).
struct TickInfo {
  bool safe_mode = false;
  int safe_reason = 0;      // hqp::tasks::SafeModeReason
  int cut_level = -1;       // first level cut by the solver's budget this tick, −1: none
  long budget_cuts = 0;     // ticks cut so far
  int iterations = 0;       // QP iterations of all levels this tick
  double solve_us = 0.0;    // the solver stage's time this tick
};

// Loads robots/walker3/controller.yaml-style files; throws std::runtime_error naming the key.
Config loadConfig(const std::string& path);

class FirmwareController {
 public:
  // Set-up time: allocates the controller (about 1 MB, docs/controller.md) once.
  explicit FirmwareController(const Config& config);
  ~FirmwareController();
  FirmwareController(const FirmwareController&) = delete;
  FirmwareController& operator=(const FirmwareController&) = delete;

  // Controller::tick: no heap, no exceptions, no I/O; s as tasks/sensor_data.hpp describes.
  void tick(const Sensors& s, Command& cmd) noexcept;
  void reset() noexcept;
  TickInfo info() const noexcept;

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace hqp::firmware
