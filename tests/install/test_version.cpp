// hqp/version.hpp (generated from project(VERSION)) against the version CMake itself parsed,
// passed in as HQP_EXPECTED_VERSION_{MAJOR,MINOR,PATCH} and _STRING.
#include <cstdio>
#include <cstring>
#include <string>

#include "hqp/version.hpp"

int main() {
  int failures = 0;
  auto check = [&](bool ok, const char* what) {
    if (!ok) {
      std::printf("FAILED: %s\n", what);
      ++failures;
    }
  };
  check(HQP_VERSION_MAJOR == HQP_EXPECTED_VERSION_MAJOR, "major");
  check(HQP_VERSION_MINOR == HQP_EXPECTED_VERSION_MINOR, "minor");
  check(HQP_VERSION_PATCH == HQP_EXPECTED_VERSION_PATCH, "patch");
  check(std::strcmp(HQP_VERSION_STRING, HQP_EXPECTED_VERSION_STRING) == 0, "string");
  // The string is the three numbers joined by dots, and the macro and constexpr forms agree.
  const std::string joined = std::to_string(HQP_EXPECTED_VERSION_MAJOR) + "." +
                             std::to_string(HQP_EXPECTED_VERSION_MINOR) + "." +
                             std::to_string(HQP_EXPECTED_VERSION_PATCH);
  check(joined == hqp::kVersionString, "string = major.minor.patch");
  check(HQP_VERSION == HQP_EXPECTED_VERSION_MAJOR * 10000 + HQP_EXPECTED_VERSION_MINOR * 100 +
                           HQP_EXPECTED_VERSION_PATCH, "HQP_VERSION");
  check(hqp::kVersionMajor == HQP_VERSION_MAJOR && hqp::kVersionMinor == HQP_VERSION_MINOR &&
            hqp::kVersionPatch == HQP_VERSION_PATCH, "constexpr");
  std::printf("hqp %s\n", hqp::kVersionString);
  return failures == 0 ? 0 : 1;
}
