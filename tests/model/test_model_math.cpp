// Small numeric kernels of include/model/spatial.hpp against libm and closed forms.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include "model/spatial.hpp"

namespace {

namespace hm = hqp::model;

// sinCos agrees with std::sin / std::cos to one rounding of a result in [−1, 1]
// (absolute 2^-53 ≈ 1.1e-16, tested at 2.3e-16) over the range joints use and beyond.
TEST(ModelMath, SinCosMatchesLibm) {
  std::mt19937_64 rng(3);
  for (double range : {0.5, 3.2, 10.0, 1000.0, 99999.0}) {
    std::uniform_real_distribution<double> u(-range, range);
    double worst = 0.0;
    for (int i = 0; i < 200000; ++i) {
      const double x = u(rng);
      double s, c;
      hm::sinCos(x, s, c);
      worst = std::max({worst, std::abs(s - std::sin(x)), std::abs(c - std::cos(x))});
    }
    EXPECT_LE(worst, 2.3e-16) << "range " << range;
  }
  // Tiny angles keep full relative accuracy of sin.
  for (double x : {1e-300, -1e-12, 3e-8, -2e-5}) {
    double s, c;
    hm::sinCos(x, s, c);
    EXPECT_NEAR(s, std::sin(x), 2.3e-16 * std::abs(x));
    EXPECT_EQ(c, std::cos(x));
  }
}

TEST(ModelMath, SinCosFallsBackOutsideRange) {
  for (double x : {1e5, -3e7, 1e300, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    double s, c;
    hm::sinCos(x, s, c);
    if (std::isfinite(x)) {
      EXPECT_EQ(s, std::sin(x));
      EXPECT_EQ(c, std::cos(x));
    } else {
      EXPECT_TRUE(std::isnan(s) && std::isnan(c));
    }
  }
}

// axisRotation is Eigen's AngleAxis; rotations about coordinate axes and a general one.
TEST(ModelMath, AxisRotationMatchesAngleAxis) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  for (int i = 0; i < 1000; ++i) {
    Eigen::Vector3d a(u(rng), u(rng), u(rng));
    a.normalize();
    const double th = u(rng);
    const Eigen::Matrix3d R = hm::axisRotation(a, th);
    const Eigen::Matrix3d ref = Eigen::AngleAxisd(th, a).toRotationMatrix();
    EXPECT_LE((R - ref).norm(), 1e-14);
  }
}

}  // namespace
