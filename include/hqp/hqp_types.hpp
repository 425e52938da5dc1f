#pragma once
// Storage types shared by the hierarchy headers: fixed capacity, run-time size, never heap.

#include <Eigen/Core>

#include <limits>

namespace hqp {

// A run-time sized matrix with a compile-time capacity of MaxRows x MaxCols (no heap).
// Eigen requires row-major storage when the capacity is a single row.
template <int MaxRows, int MaxCols>
using MaxMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic,
                  (MaxRows == 1 && MaxCols != 1) ? Eigen::RowMajor : Eigen::ColMajor, MaxRows,
                  MaxCols>;

// A run-time sized column vector with capacity MaxRows (no heap).
template <int MaxRows>
using MaxVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, MaxRows, 1>;

// Bound value for an absent side of a two-sided constraint.
inline constexpr double kInf = std::numeric_limits<double>::infinity();

// Capacity of an Eigen max-size dimension that may be empty: at least 2, which keeps
// 1-row capacities (which Eigen forbids for column-major storage) out of the QP's types.
constexpr int capacity(int n) { return n < 2 ? 2 : n; }

}  // namespace hqp
