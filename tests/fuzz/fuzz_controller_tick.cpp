// libFuzzer harness: the Walker3 Controller::tick (HQP solver) on arbitrary sensor data
// (docs/fuzzing.md). Each input is a short run (1–6 ticks) from reset(); every tick's sensors
// are the resting robot's (tests/support/walker3_standing.hpp) with input-chosen changes:
// joint angles and rates, IMU orientation (small rotations, arbitrary 4-vectors, zero, tiny,
// huge), gyro, accelerometer, F/T wrenches, ±inf and NaN anywhere.
// Checks on every tick:
//  - the output currents and torques are finite;
//  - a non-finite sensor value or an IMU quaternion of norm ≤ 1e-6 gives the safe mode;
//  - an IMU tilt beyond SafeModeParameters::max_tilt (+ 0.05 rad) gives the safe mode;
//  - the safe mode latches until reset().
#include <algorithm>
#include <cmath>
#include <memory>

#include "fuzz_common.hpp"
#include "support/walker3_controller.hpp"
#include "support/walker3_standing.hpp"

namespace {

using Controller = hqp::testing::Walker3Controller;
using Sensors = Controller::Sensors;

struct Fixture {
  hqp::testing::Walker3Standing standing = hqp::testing::walker3Standing();
  Sensors rest;
  std::unique_ptr<Controller> ctrl;
  Fixture() {
    const double half = 0.5 * walker3::Robot::total_mass * 9.81;
    rest = hqp::testing::walker3RestingSensors(standing, {half, half},
                                               {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
    ctrl = hqp::testing::makeWalker3Controller(
        hqp::testing::walker3Config(Controller::Config::Solver::Hqp, standing.com_height));
  }
};

// Perturbs v: kept, small, large, or one entry special.
template <class V>
void perturb(FuzzedDataProvider& in, V&& v, double small, double large) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: return;
    case 1:
      for (int i = 0; i < v.size(); ++i) v(i) += small * hqp::fuzz::number(in) / 16.0;
      return;
    case 2:
      for (int i = 0; i < v.size(); ++i) v(i) += large * hqp::fuzz::number(in) / 16.0;
      return;
    default: {
      const int i = in.ConsumeIntegralInRange<int>(0, static_cast<int>(v.size()) - 1);
      v(i) = hqp::fuzz::number(in, true);
      return;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Fixture f;
  FuzzedDataProvider in(data, size);
  Controller& ctrl = *f.ctrl;
  ctrl.reset();
  const int ticks = in.ConsumeIntegralInRange<int>(1, 6);
  const double max_tilt = ctrl.config().safe.max_tilt;
  bool safe_before = false;
  for (int k = 0; k < ticks; ++k) {
    Sensors s = f.rest;
    s.time = k * ctrl.config().dt;
    perturb(in, s.q, 0.05, 1.0);
    perturb(in, s.dq, 0.5, 20.0);
    perturb(in, s.imu_gyro, 0.2, 10.0);
    perturb(in, s.imu_accel, 1.0, 50.0);
    for (auto& w : s.ft) perturb(in, w, 20.0, 500.0);
    Eigen::Vector4d qc = s.imu_orientation.coeffs();  // x y z w
    switch (in.ConsumeIntegralInRange<int>(0, 6)) {
      case 0: break;
      case 1: {  // a small or large rotation
        const Eigen::Vector3d axis(hqp::fuzz::number(in), hqp::fuzz::number(in), hqp::fuzz::number(in));
        const double angle = hqp::fuzz::number(in) / 8.0;
        if (axis.norm() > 0) qc = (s.imu_orientation * Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()))).coeffs();
        break;
      }
      case 2:
        for (int i = 0; i < 4; ++i) qc(i) = hqp::fuzz::number(in);
        break;
      case 3: qc *= std::pow(10.0, in.ConsumeIntegralInRange<int>(-12, 3)); break;  // not unit length
      case 4: qc *= std::pow(10.0, in.ConsumeIntegralInRange<int>(150, 300)); break;  // huge
      case 5: qc.setZero(); break;
      default: qc(in.ConsumeIntegralInRange<int>(0, 3)) = hqp::fuzz::number(in, true); break;
    }
    s.imu_orientation.coeffs() = qc;

    bool finite = s.q.allFinite() && s.dq.allFinite() && s.imu_gyro.allFinite() && s.imu_accel.allFinite() &&
                  qc.allFinite();
    for (const auto& w : s.ft) finite = finite && w.allFinite();
    const double qmax = finite ? qc.cwiseAbs().maxCoeff() : 0.0;
    const double qnorm = qmax > 0 ? qmax * (qc / qmax).norm() : 0.0;  // no overflow
    double tilt = 0.0;
    if (finite && qnorm > 1e-6) {
      const Eigen::Quaterniond u(Eigen::Vector4d(qc / qnorm));
      tilt = std::acos(std::clamp(u.toRotationMatrix()(2, 2), -1.0, 1.0));
    }

    Controller::Command cmd;
    ctrl.tick(s, cmd);
    if (std::getenv("HQP_FUZZ_VERBOSE"))
      std::fprintf(stderr, "tick %d finite %d |q| %g tilt %g safe %d reason %s\n", k, finite, qnorm, tilt,
                   cmd.safe_mode, hqp::tasks::toString(ctrl.diagnostics().reason));
    HQP_FUZZ_CHECK(cmd.current.allFinite());
    HQP_FUZZ_CHECK(cmd.torque.allFinite());
    if (!finite || !(qnorm > 1e-6)) HQP_FUZZ_CHECK2(cmd.safe_mode, qnorm, static_cast<double>(k));
    if (finite && qnorm > 1e-6 && tilt > max_tilt + 0.05) HQP_FUZZ_CHECK2(cmd.safe_mode, tilt, static_cast<double>(k));
    if (safe_before) HQP_FUZZ_CHECK(cmd.safe_mode);
    safe_before = cmd.safe_mode;
  }
  return 0;
}
