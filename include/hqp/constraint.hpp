#pragma once
// A constraint of the paper's eq. (3), two-sided: lower ≤ D x ≤ upper.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

#include "hqp/hqp_types.hpp"

namespace hqp {

// A bound of magnitude ≥ kInfBound is no bound: it is read as ±inf of its sign (the qpOASES /
// DAQP convention, so that data written for those solvers means the same here). Applied where
// the bounds enter the solvers, Level::stackConstraints (HqpWbc, WqpWbc, recorded instances);
// ActiveSetQp / DualActiveSetQp used on their own take ±inf only.
inline constexpr double kInfBound = 1e20;

// The bound as the solvers read it: ±inf if |v| ≥ kInfBound, else v (NaN stays NaN and is
// refused by the input contract; so is a lower bound ≥ kInfBound, read as +inf).
inline double interpretBound(double v) {
  return std::abs(v) >= kInfBound ? std::copysign(kInf, v) : v;
}

// Rows constraint rows over Nx variables, filled in place every tick. The paper's one-sided
// form D x − f ≤ 0 is lower = −inf, upper = f (setUpperBound); a side set to ±inf, or of
// magnitude ≥ kInfBound (1e20), is absent.
template <int Rows, int Nx>
struct Constraint {
  static_assert(Rows > 0 && Nx > 0, "a constraint has at least one row and one variable");
  static constexpr int rows = Rows;
  static constexpr int cols = Nx;

  using MatrixD = Eigen::Matrix<double, Rows, Nx>;
  using VectorF = Eigen::Matrix<double, Rows, 1>;
  using VectorX = Eigen::Matrix<double, Nx, 1>;

  MatrixD D = MatrixD::Zero();                   // constraint matrix D_i  (Rows x Nx)
  VectorF lower = VectorF::Constant(-kInf);      // lower bound            (Rows), −inf: none
  VectorF upper = VectorF::Constant(kInf);       // upper bound f_i        (Rows), +inf: none
  const char* name = "";
  int priority = 0;  // informational, as for Task

  // D x ≤ f, the form of eq. (3).
  void setUpperBound(const VectorF& f) {
    lower.setConstant(-kInf);
    upper = f;
  }

  // Largest bound violation max_r max(lower_r − d_r, d_r − upper_r, 0) at x (bounds read by
  // interpretBound, as the solvers read them).
  double violation(const VectorX& x) const {
    const VectorF d = D * x;
    double v = 0.0;
    for (int r = 0; r < Rows; ++r)
      v = std::max(v, std::max(interpretBound(lower(r)) - d(r), d(r) - interpretBound(upper(r))));
    return v;
  }
};

}  // namespace hqp
