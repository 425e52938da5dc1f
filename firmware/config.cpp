// YAML loading, outside the tick and outside the -fno-exceptions unit (controller_tick.cpp).
#include "tasks/controller_config_yaml.hpp"
#include "walker3_firmware.hpp"

namespace hqp::firmware {

Config loadConfig(const std::string& path) { return hqp::tasks::loadControllerConfig<Robot>(path); }

}  // namespace hqp::firmware
