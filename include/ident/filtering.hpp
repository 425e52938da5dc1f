#pragma once
// Signal conditioning for identification (§V-B): measured q is low-pass
// filtered without phase lag, then differentiated twice to get q̇ and q̈; the
// measured torque goes through the same filter so that both sides of
// τ = Y(q, q̇, q̈) π see the same attenuation.
//
// - Butterworth low-pass of order N as a cascade of second-order sections
//   (plus one first-order section for odd N), designed by the bilinear
//   transform with frequency pre-warping, K = tan(π f_c / f_s).
// - Zero phase: the cascade runs forward, then backward (filtfilt), which
//   squares the magnitude response (−6 dB at f_c) and cancels the phase.
//   The ends are padded by odd reflection about the end values and each
//   section starts in its steady state for the first padded sample, so the
//   start-up transient is small.
// - Differentiation: central differences (x_{k+1} − x_{k−1}) / (2 dt),
//   second-order one-sided differences at the two ends.
// Offline code: allocates and throws on bad arguments.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>

namespace hqp::ident {

class ButterworthLowPass {
 public:
  ButterworthLowPass(int order, double cutoff_hz, double sample_hz) : order_(order) {
    if (order < 1 || order > 16) throw std::invalid_argument("Butterworth: order must be 1..16");
    if (!(sample_hz > 0.0) || !(cutoff_hz > 0.0) || !(cutoff_hz < 0.5 * sample_hz)) {
      throw std::invalid_argument("Butterworth: need 0 < cutoff < sample rate / 2");
    }
    constexpr double kPi = 3.14159265358979323846;
    const double K = std::tan(kPi * cutoff_hz / sample_hz);
    // Analog prototype poles in conjugate pairs at angles θ from the negative
    // real axis, θ = (2m − N − 1) π / (2N) for m = ⌊N/2⌋ + 1 … N (one real pole,
    // θ = 0, when N is odd); each pair is a section with Q = 1 / (2 cos θ).
    for (int m = order / 2 + 1 + order % 2; m <= order; ++m) {
      const double theta = kPi * (2.0 * m - order - 1.0) / (2.0 * order);
      const double Q = 1.0 / (2.0 * std::cos(theta));
      const double norm = 1.0 / (1.0 + K / Q + K * K);
      Section s;
      s.b0 = K * K * norm;
      s.b1 = 2.0 * s.b0;
      s.b2 = s.b0;
      s.a1 = 2.0 * (K * K - 1.0) * norm;
      s.a2 = (1.0 - K / Q + K * K) * norm;
      sections_.push_back(s);
    }
    if (order % 2 == 1) {  // the real pole: H(s) = 1 / (s + 1)
      const double norm = 1.0 / (1.0 + K);
      Section s;
      s.b0 = K * norm;
      s.b1 = s.b0;
      s.b2 = 0.0;
      s.a1 = (K - 1.0) * norm;
      s.a2 = 0.0;
      sections_.push_back(s);
    }
  }

  int order() const { return order_; }

  // One causal pass (direct form II transposed), starting at steady state for x[0].
  Eigen::VectorXd filter(const Eigen::VectorXd& x) const {
    Eigen::VectorXd y = x;
    if (x.size() == 0) return y;
    for (const Section& s : sections_) {
      // Steady state for a constant input u (DC gain 1): z2 = (b2 − a2) u, z1 = (b1 − a1) u + z2.
      const double u = y[0];
      double z2 = (s.b2 - s.a2) * u;
      double z1 = (s.b1 - s.a1) * u + z2;
      for (Eigen::Index k = 0; k < y.size(); ++k) {
        const double in = y[k];
        const double out = s.b0 * in + z1;
        z1 = s.b1 * in - s.a1 * out + z2;
        z2 = s.b2 * in - s.a2 * out;
        y[k] = out;
      }
    }
    return y;
  }

  // Zero-phase forward-backward filtering with odd-reflection padding.
  Eigen::VectorXd filtfilt(const Eigen::VectorXd& x) const {
    const Eigen::Index n = x.size();
    if (n < 2) return x;
    const Eigen::Index pad = std::min<Eigen::Index>(n - 1, 3 * (2 * order_ + 1) * 10);
    Eigen::VectorXd ext(n + 2 * pad);
    for (Eigen::Index k = 0; k < pad; ++k) {
      ext[k] = 2.0 * x[0] - x[pad - k];
      ext[n + pad + k] = 2.0 * x[n - 1] - x[n - 2 - k];
    }
    ext.segment(pad, n) = x;
    Eigen::VectorXd y = filter(ext);
    y.reverseInPlace();
    y = filter(y);
    y.reverseInPlace();
    return y.segment(pad, n);
  }

 private:
  struct Section {
    double b0, b1, b2, a1, a2;
  };
  int order_;
  std::vector<Section> sections_;
};

// dx/dt by central differences; second-order one-sided at the ends.
inline Eigen::VectorXd centralDifference(const Eigen::VectorXd& x, double dt) {
  if (!(dt > 0.0)) throw std::invalid_argument("centralDifference: dt must be positive");
  const Eigen::Index n = x.size();
  if (n < 3) throw std::invalid_argument("centralDifference: need at least 3 samples");
  Eigen::VectorXd d(n);
  for (Eigen::Index k = 1; k + 1 < n; ++k) d[k] = (x[k + 1] - x[k - 1]) / (2.0 * dt);
  d[0] = (-3.0 * x[0] + 4.0 * x[1] - x[2]) / (2.0 * dt);
  d[n - 1] = (3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) / (2.0 * dt);
  return d;
}

}  // namespace hqp::ident
