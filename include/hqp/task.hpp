#pragma once
// A task of the paper's eq. (3): A x − b = 0, met in least squares at its level.

#include <Eigen/Core>

namespace hqp {

// Rows task rows over Nx variables, filled in place every tick (by the robot layer).
// Derived types (a robot's task with an update()) can be stacked in a Level as well:
// a Level needs only `rows`, `cols`, `A`, `b` and `weight`.
template <int Rows, int Nx>
struct Task {
  static_assert(Rows > 0 && Nx > 0, "a task has at least one row and one variable");
  static constexpr int rows = Rows;  // task dimension
  static constexpr int cols = Nx;    // number of optimization variables

  using MatrixA = Eigen::Matrix<double, Rows, Nx>;
  using VectorB = Eigen::Matrix<double, Rows, 1>;
  using VectorX = Eigen::Matrix<double, Nx, 1>;

  MatrixA A = MatrixA::Zero();        // task matrix A_i            (Rows x Nx)
  VectorB b = VectorB::Zero();        // task reference b_i         (Rows)
  VectorB weight = VectorB::Ones();   // w: the level minimizes Σ w_r (a_r x − b_r)²; 0 disables a row
  const char* name = "";              // for logs and reports
  int priority = 0;                   // informational: the level's place in HqpWbc is the priority

  void setWeight(double w) { weight.setConstant(w); }

  // ‖A x − b‖², unweighted.
  double residual(const VectorX& x) const { return (A * x - b).squaredNorm(); }
};

}  // namespace hqp
