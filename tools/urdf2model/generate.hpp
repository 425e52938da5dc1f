#pragma once
// The whole generator from URDF text to header text: the strict scan, urdfdom's own parse
// (the file must stay a URDF that ROS tools and MuJoCo accept), the model and the header.
// Shared by hqp_urdf2model and the fuzzer (tests/fuzz). Throws UrdfError.

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <string>

#include "urdf2model/error.hpp"
#include "urdf2model/header_writer.hpp"
#include "urdf2model/tree_model.hpp"
#include "urdf2model/xml_scan.hpp"

namespace hqp::tools {

namespace detail {

// Keeps urdfdom's first error instead of letting it print several lines.
class FirstError : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && message.empty()) message = text;
  }
  std::string message;
};

}  // namespace detail

// The model of `xml`, checked; `model_out` (optional) receives it. Throws UrdfError.
inline std::string generate(const std::string& xml, const Options& opt, const std::string& ns_opt,
                            Model* model_out = nullptr) {
  const RawRobot raw = scanUrdf(xml);

  detail::FirstError errors;
  console_bridge::useOutputHandler(&errors);
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
  const urdf::ModelInterfaceSharedPtr um = urdf::parseURDF(xml);
  console_bridge::noOutputHandler();
  // urdfdom's message may quote the file's text, newlines included: kept on one line.
  if (!um) {
    throw UrdfError("urdfdom: " + (errors.message.empty() ? "cannot parse the file" : printable(errors.message, 300)));
  }

  const Model model = buildModel(raw, opt);
  const std::string ns = ns_opt.empty() ? sanitize(model.name) : ns_opt;
  if (!isNamespace(ns)) throw UrdfError("--namespace: " + quote(ns) + " is not a C++ namespace name");
  if (model_out) *model_out = model;
  return writeHeader(model, ns);
}

}  // namespace hqp::tools
