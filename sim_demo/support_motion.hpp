#pragma once
// Moving supports (seesaw, skateboards; docs/scenarios.md): the target of one board
// servo over time. A sinusoid about an offset, faded in and out by a raised-cosine window so the
// board starts and stops without a velocity step. Not real-time code (the simulator side).

#include <algorithm>
#include <cmath>
#include <string>

namespace hqp::sim {

struct SupportMotion {
  std::string axis;        // the scene's <position> actuator (seesaw, r_board_x, ...)
  double amplitude = 0.0;  // m (slides) or rad (hinges)
  double frequency = 1.0;  // Hz
  double start = 1.5;      // s, the window opens here
  double duration = 4.0;   // s, window length including both ramps
  double offset = 0.0;     // m or rad, held while the window is open (ramped like the sinusoid)
  double phase = 0.0;      // rad, of the sinusoid at `start`
  double ramp = 0.5;       // s, each raised-cosine ramp

  bool active() const { return amplitude != 0.0 || offset != 0.0; }
  // The sinusoid's peak rate |A| 2 pi f (the window is 1 between the ramps).
  double peakVelocity() const { return std::abs(amplitude) * 2.0 * M_PI * frequency; }
  // Its peak acceleration |A| (2 pi f)^2: what a hand on the board must produce.
  double peakAcceleration() const { return peakVelocity() * 2.0 * M_PI * frequency; }
};

// Target position q and velocity dq at time t: q = w(t) (offset + A sin(2 pi f (t - start) + phase)),
// w rising 0 -> 1 over `ramp` as 0.5 (1 - cos(pi s / ramp)) and falling symmetrically at the end;
// dq is its exact derivative (w' is continuous, so the target velocity has no step).
inline void supportTarget(const SupportMotion& m, double t, double& q, double& dq) {
  q = dq = 0.0;
  const double s = t - m.start;
  if (!(s > 0.0) || !(s < m.duration)) return;
  const double ramp = std::min(m.ramp, 0.5 * m.duration);
  double w = 1.0, dw = 0.0;
  const double edge = std::min(s, m.duration - s);  // time from the nearer window end
  if (ramp > 0.0 && edge < ramp) {
    w = 0.5 * (1.0 - std::cos(M_PI * edge / ramp));
    dw = 0.5 * M_PI / ramp * std::sin(M_PI * edge / ramp) * (s < m.duration - s ? 1.0 : -1.0);
  }
  const double om = 2.0 * M_PI * m.frequency;
  const double x = m.offset + m.amplitude * std::sin(om * s + m.phase);
  const double dx = m.amplitude * om * std::cos(om * s + m.phase);
  q = w * x;
  dq = dw * x + w * dx;
}

}  // namespace hqp::sim
