#pragma once
// PD feedback gains of an operational-space task (eq. 2): a = a_ff + kp e + kd ė.

namespace hqp::tasks {

struct PdGains {
  double kp = 0.0;  // 1/s² (position) or 1/s² (orientation)
  double kd = 0.0;  // 1/s
};

}  // namespace hqp::tasks
