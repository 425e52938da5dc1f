#pragma once
// Excitation trajectory of §V-B: a finite Fourier series per joint (Swevers et
// al. 1997) with L harmonics of the base frequency f (the paper: L = 5,
// f = 0.1 Hz, so one period lasts 10 s), written so that the robot starts
// and ends at rest at q0:
//   q(t)  = q0 + Σ_l [ a_l/(ω_l) sin(ω_l t) − b_l/(ω_l) (cos(ω_l t) − 1) ],  ω_l = 2π f l
//   q̇(t)  = Σ_l [ a_l cos(ω_l t) + b_l sin(ω_l t) ]
//   q̈(t)  = Σ_l ω_l [ −a_l sin(ω_l t) + b_l cos(ω_l t) ]
// Rest at t = 0 (and, by periodicity, at every multiple of the period):
// q̇(0) = Σ a_l = 0 and q̈(0) = 2π f Σ l b_l = 0. These two equalities are
// eliminated (a_1 = −Σ_{l≥2} a_l, b_1 = −Σ_{l≥2} l b_l), so the free
// coefficients per joint are x = [q0, a_2 … a_L, b_2 … b_L] (2L − 1 numbers)
// and every x gives a trajectory at rest at its ends.

#include <cmath>
#include <stdexcept>

#include <Eigen/Core>

namespace hqp::ident {

struct FourierSettings {
  int harmonics = 5;            // L (paper: 5)
  double base_frequency = 0.1;  // f in Hz (paper: 0.1 Hz)
};

class FourierTrajectory {
 public:
  FourierTrajectory(int joints, const FourierSettings& settings)
      : n_(joints), s_(settings), x_(Eigen::VectorXd::Zero(joints * freePerJoint(settings))) {
    if (joints < 1 || settings.harmonics < 1 || !(settings.base_frequency > 0.0)) {
      throw std::invalid_argument(
          "FourierTrajectory: need joints >= 1, harmonics >= 1, base_frequency > 0");
    }
  }

  static int freePerJoint(const FourierSettings& s) { return 2 * s.harmonics - 1; }
  int joints() const { return n_; }
  int numFree() const { return static_cast<int>(x_.size()); }
  double period() const { return 1.0 / s_.base_frequency; }
  const FourierSettings& settings() const { return s_; }

  // Free coefficients, joint after joint: [q0, a_2..a_L, b_2..b_L].
  const Eigen::VectorXd& free() const { return x_; }
  void setFree(const Eigen::VectorXd& x) {
    if (x.size() != x_.size()) throw std::invalid_argument("FourierTrajectory: wrong size");
    x_ = x;
  }
  double& q0(int j) { return x_[j * freePerJoint(s_)]; }
  double q0(int j) const { return x_[j * freePerJoint(s_)]; }

  // Full coefficients a_l, b_l (l = 1..L) of joint j.
  void coefficients(int j, Eigen::VectorXd& a, Eigen::VectorXd& b) const {
    const int L = s_.harmonics;
    const int o = j * freePerJoint(s_);
    a.resize(L);
    b.resize(L);
    a[0] = 0.0;
    b[0] = 0.0;
    for (int l = 2; l <= L; ++l) {
      a[l - 1] = x_[o + l - 1];
      b[l - 1] = x_[o + L + l - 2];
      a[0] -= a[l - 1];
      b[0] -= l * b[l - 1];
    }
  }

  // q, q̇, q̈ (each of size joints) at time t.
  template <class VQ, class VD, class VA>
  void evaluate(double t, VQ& q, VD& dq, VA& ddq) const {
    const int L = s_.harmonics;
    const double w = 2.0 * kPi * s_.base_frequency;
    Eigen::VectorXd a, b;
    for (int j = 0; j < n_; ++j) {
      coefficients(j, a, b);
      double p = q0(j), v = 0.0, acc = 0.0;
      for (int l = 1; l <= L; ++l) {
        const double wl = w * l;
        const double s = std::sin(wl * t), c = std::cos(wl * t);
        p += a[l - 1] / wl * s - b[l - 1] / wl * (c - 1.0);
        v += a[l - 1] * c + b[l - 1] * s;
        acc += wl * (-a[l - 1] * s + b[l - 1] * c);
      }
      q[j] = p;
      dq[j] = v;
      ddq[j] = acc;
    }
  }

  // Joint j's deviation from q0 and its rates are linear in (a, b): scaling
  // them by k scales q − q0, q̇, q̈ by k (used to start from a feasible guess).
  void scaleJoint(int j, double k) {
    const int o = j * freePerJoint(s_);
    for (int i = 1; i < freePerJoint(s_); ++i) x_[o + i] *= k;
  }

  static constexpr double kPi = 3.14159265358979323846;

 private:
  int n_;
  FourierSettings s_;
  Eigen::VectorXd x_;
};

}  // namespace hqp::ident
