// hqp_urdf2model: URDF -> constexpr C++ robot header (docs/generated-model.md).
//   hqp_urdf2model <urdf> -o <header> [--floating-base] [--namespace ns] [--frames f1,f2,...]
// Exit code 0 on success, 1 with one message "<file>: <element>: <problem>" on
// stderr when the URDF is rejected (docs/adding-a-robot.md lists the rules).

#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "urdf2model/generate.hpp"

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
    header = hqp::tools::generate(buf.str(), opt, ns);
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
