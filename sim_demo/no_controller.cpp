// Builds without the balance controller (HQP_SIM_WITH_CONTROLLER off): the PD stand-in only.
#include "recording.hpp"
#include "run.hpp"

namespace hqp::sim {

std::unique_ptr<Driver> makeBalanceController(const std::string&, bool, const ControllerOverrides&) {
  return nullptr;
}
bool balanceControllerAvailable() { return false; }
bool startRecording(Driver&, const RecordOptions&) { return false; }
std::size_t finishRecording(Driver&) { return 0; }

}  // namespace hqp::sim
