// Firmware build of the model layer: compiled with -fno-exceptions -fno-rtti
// (tests/model/CMakeLists.txt). Runs calcWbcDependence on the hand-written
// floating tree and fails (exit 1) on a non-finite or non-positive result.

#include <cmath>

#include "model/robot_dynamics.hpp"
#include "model/support/hand_robots.hpp"

int main() {
  using R = hand_test::FloatingTree;
  static hqp::model::RobotDynamics<R, 2> dyn({R::Frames::tip, R::Frames::foot});
  hqp::model::Data<R>::VectorQ q = hqp::model::neutralConfiguration<R>();
  hqp::model::Data<R>::VectorV v = hqp::model::Data<R>::VectorV::Constant(0.3);
  q = hqp::model::integrate<R>(q, v, 1.0);
  dyn.calcWbcDependence(q, v);
  const bool ok = dyn.valid() && dyn.M().allFinite() && dyn.h().allFinite() &&
                  dyn.J(0).allFinite() && dyn.dJv(1).allFinite() && dyn.Ag().allFinite() &&
                  dyn.M()(0, 0) > 0.0 && std::abs(dyn.mass() - R::total_mass) < 1e-12;
  return ok ? 0 : 1;
}
