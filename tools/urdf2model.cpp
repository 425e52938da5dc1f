// hqp_urdf2model: URDF -> constexpr C++ robot header (docs/generated-model.md).
//   hqp_urdf2model <urdf> -o <header> [--floating-base] [--namespace ns] [--frames f1,f2,...]
// Exit code 0 on success, 1 with one message "<file>: <element>: <problem>" on
// stderr when the URDF is rejected (docs/adding-a-robot.md lists the rules).

#include <CLI/CLI.hpp>
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "urdf2model/error.hpp"
#include "urdf2model/header_writer.hpp"
#include "urdf2model/tree_model.hpp"
#include "urdf2model/xml_scan.hpp"

namespace {

// Keeps urdfdom's first error instead of letting it print several lines.
class FirstError : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && message.empty()) message = text;
  }
  std::string message;
};

std::string generate(const std::string& xml, const hqp::tools::Options& opt, const std::string& ns_opt) {
  using namespace hqp::tools;
  const RawRobot raw = scanUrdf(xml);

  FirstError errors;
  console_bridge::useOutputHandler(&errors);
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
  const urdf::ModelInterfaceSharedPtr um = urdf::parseURDF(xml);
  console_bridge::noOutputHandler();
  if (!um) throw UrdfError("urdfdom: " + (errors.message.empty() ? "cannot parse the file" : errors.message));

  const Model model = buildModel(raw, opt);
  const std::string ns = ns_opt.empty() ? sanitize(model.name) : ns_opt;
  if (!isNamespace(ns)) throw UrdfError("--namespace: '" + ns + "' is not a C++ namespace name");
  return writeHeader(model, ns);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a constexpr C++ robot description (hqp::model) from a URDF."};
  std::string urdf_path, out_path, ns;
  hqp::tools::Options opt;
  app.add_option("urdf", urdf_path, "URDF file")->required();
  app.add_option("-o,--output", out_path, "header to write")->required();
  app.add_flag("--floating-base", opt.floating_base, "the root link is a free-floating body");
  app.add_option("--namespace", ns, "namespace of the Robot struct (default: the robot name)");
  app.add_option("--frames", opt.frames, "frames to emit besides each body's own link (default: all links)")
      ->delimiter(',');
  CLI11_PARSE(app, argc, argv);
  opt.frames_given = app.count("--frames") > 0;

  std::ifstream in(urdf_path, std::ios::binary);
  if (!in) {
    std::cerr << urdf_path << ": cannot open the file\n";
    return 1;
  }
  std::stringstream buf;
  buf << in.rdbuf();

  std::string header;
  try {
    header = generate(buf.str(), opt, ns);
  } catch (const hqp::tools::UrdfError& e) {
    std::remove(out_path.c_str());   // no stale header that would let a build pass
    std::cerr << urdf_path << ": " << e.what() << "\n";
    return 1;
  }

  // Write next to the target and rename, so a reader never sees half a header.
  const std::string tmp = out_path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << header;
    if (!out) {
      std::cerr << out_path << ": cannot write the file\n";
      return 1;
    }
  }
  if (std::rename(tmp.c_str(), out_path.c_str()) != 0) {
    std::cerr << out_path << ": cannot write the file\n";
    return 1;
  }
  return 0;
}
