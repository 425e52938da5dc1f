#pragma once
// The one error type of the generator. The message names the element
// ("joint 'knee_l': ...", "link 'foot': ..."); main() prefixes the file name.

#include <cstdio>
#include <stdexcept>
#include <string>

namespace hqp::tools {

struct UrdfError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

inline std::string quote(const std::string& s) { return "'" + s + "'"; }

// A number for a message: short, but tiny inertias stay readable.
inline std::string show(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

inline UrdfError jointError(const std::string& joint, const std::string& what) {
  return UrdfError("joint " + quote(joint) + ": " + what);
}

inline UrdfError linkError(const std::string& link, const std::string& what) {
  return UrdfError("link " + quote(link) + ": " + what);
}

}  // namespace hqp::tools
