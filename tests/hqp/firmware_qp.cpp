// Firmware build check: compiled with -fno-exceptions -fno-rtti, includes the QP
// and solves one problem; exit code 0 on the expected answer.
// min ½‖x − (2, 2)‖² s.t. x1 + x2 = 1, 0 ≤ x1 ≤ 0.25  ⇒  x = (0.25, 0.75).
#include <cmath>

#include "hqp/active_set_qp.hpp"

int main() {
  static hqp::ActiveSetQp<2, 2, 1, 1> qp;
  qp.resize(2, 2, 1, 1);
  qp.A().setIdentity();
  qp.b() << 2.0, 2.0;
  qp.E() << 1.0, 1.0;
  qp.e() << 1.0;
  qp.C() << 1.0, 0.0;
  qp.lower() << 0.0;
  qp.upper() << 0.25;
  if (qp.solve(false) != hqp::QpStatus::Optimal) return 1;
  if (std::abs(qp.x()(0) - 0.25) > 1e-12 || std::abs(qp.x()(1) - 0.75) > 1e-12) return 2;
  if (qp.numActive() != 1 || !qp.activeAtUpper(0)) return 3;
  return 0;
}
