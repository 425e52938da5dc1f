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

// Text from the file as it appears in a message: control characters (a newline inside an
// attribute or a name) as C escapes, so that every message stays one line, and at most 60
// characters.
inline std::string printable(const std::string& s, std::size_t max_length = 60) {
  std::string out;
  for (unsigned char c : s) {
    if (out.size() >= max_length) return out + "...";
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c == '\r') out += "\\r";
    else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

inline std::string quote(const std::string& s) { return "'" + printable(s) + "'"; }

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
