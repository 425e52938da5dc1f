// Compiled with only `pkg-config --cflags hqp` (tests/install/install_test.cmake).
#include <cstdio>

#include "hqp/version.hpp"
#include "model/spatial.hpp"   // the headers and Eigen are found through the same flags

int main() {
  const hqp::model::Vector6 v = hqp::model::Vector6::Zero();
  std::printf("hqp %s\n", v.norm() == 0.0 ? HQP_VERSION_STRING : "?");
  return 0;
}
