#pragma once
// Strip kernels for the small orthogonal updates of the QP and the null space.
// Y ← Y H_first ⋯ H_{last−1} for a column-major Y, with H_i = I − τ_i v_i v_iᵀ and
// v_i = [0 (i entries); 1; V(i+1 : cols, i)] (Eigen's / LAPACK's reflector storage).
// Used for the rows below a level (HqpWbc, via NullSpace) and the QP's working-set rows.
// At these sizes (≤ 66 x 31) a reflector per call of Eigen's gemv + rank-1 update is
// dominated by call overhead, and dot products of one row end in horizontal reductions.
// Here 8 rows at a time are copied into a local block and every reflector is fixed-size
// 8-vector FMAs (one AVX-512 register, two AVX2 registers) on L1 data, with four
// independent accumulators for t = Y v so the sum is not one serial FMA chain. A last strip
// of 1–4 rows gets a block of its own height (an 8-row block costs as much for 1 row as for
// 8); each row is summed on its own, so results do not depend on the strip height.

#include <Eigen/Core>

#include <algorithm>
#include <type_traits>

namespace hqp::detail {

// t = strip v_i for the reflector v_i = [1; V(i+1 : cols, i)] (columns i.. of the strip), in
// four accumulators: t0 gets column i, then j ≡ i+1 (mod 4) and the tail past the last full
// group of 4; t1..t3 the others.
template <int MaxCols, class Strip, class MatV>
inline Eigen::Matrix<double, Strip::RowsAtCompileTime, 1> stripDot(const Strip& strip, int cols,
                                                                   const MatV& V, int i) {
  using Vec = Eigen::Matrix<double, Strip::RowsAtCompileTime, 1>;
  Vec t0 = strip.col(i), t1 = Vec::Zero(), t2 = Vec::Zero(), t3 = Vec::Zero();
  int j = i + 1;
  for (; j + 3 < cols; j += 4) {
    t0.noalias() += V(j, i) * strip.col(j);
    t1.noalias() += V(j + 1, i) * strip.col(j + 1);
    t2.noalias() += V(j + 2, i) * strip.col(j + 2);
    t3.noalias() += V(j + 3, i) * strip.col(j + 3);
  }
  for (; j < cols; ++j) t0.noalias() += V(j, i) * strip.col(j);
  return (t0 + t1) + (t2 + t3);
}

// strip ← strip H_first ⋯ H_{last−1} on the columns [first, cols) of a local S-row block.
// t = strip v of the next reflector is summed while this one updates the columns, so each
// column is loaded once per reflector; every sum keeps its accumulator and order (t0 gets
// column i, then j ≡ i+1, and the tail past the last full group of 4; t1..t3 the others),
// so the result is bit for bit that of a dot pass and an update pass.
template <int MaxCols, class Strip, class MatV, class VecTau>
inline void reflectStrip(Strip& strip, int cols, const MatV& V, const VecTau& tau, int first,
                         int last) {
  using Vec = Eigen::Matrix<double, Strip::RowsAtCompileTime, 1>;
  int i = first;
  while (i < last && tau(i) == 0.0) ++i;
  if (i >= last) return;
  Vec sum = stripDot<MaxCols>(strip, cols, V, i);
  while (i < last) {
    const Vec t = tau(i) * sum;
    int n = i + 1;  // the next reflector that does something
    while (n < last && tau(n) == 0.0) ++n;
    strip.col(i) -= t;
    int j;
    if (n >= last) {
      for (j = i + 1; j < cols; ++j) strip.col(j).noalias() -= V(j, i) * t;
      return;
    }
    for (j = i + 1; j < n; ++j) strip.col(j).noalias() -= V(j, i) * t;
    strip.col(n).noalias() -= V(n, i) * t;
    Vec t0 = strip.col(n), t1 = Vec::Zero(), t2 = Vec::Zero(), t3 = Vec::Zero();
    for (j = n + 1; j + 3 < cols; j += 4) {
      strip.col(j).noalias() -= V(j, i) * t;
      t0.noalias() += V(j, n) * strip.col(j);
      strip.col(j + 1).noalias() -= V(j + 1, i) * t;
      t1.noalias() += V(j + 1, n) * strip.col(j + 1);
      strip.col(j + 2).noalias() -= V(j + 2, i) * t;
      t2.noalias() += V(j + 2, n) * strip.col(j + 2);
      strip.col(j + 3).noalias() -= V(j + 3, i) * t;
      t3.noalias() += V(j + 3, n) * strip.col(j + 3);
    }
    for (; j < cols; ++j) {
      strip.col(j).noalias() -= V(j, i) * t;
      t0.noalias() += V(j, n) * strip.col(j);
    }
    sum = (t0 + t1) + (t2 + t3);
    i = n;
  }
}

// strip ← strip H_{last−1} ⋯ H_first: the same reflectors in reverse order (Y Qᵀ where the
// above gives Y Q). One dot pass and one update pass per reflector.
template <int MaxCols, class Strip, class MatV, class VecTau>
inline void reflectStripBackward(Strip& strip, int cols, const MatV& V, const VecTau& tau,
                                 int first, int last) {
  using Vec = Eigen::Matrix<double, Strip::RowsAtCompileTime, 1>;
  for (int i = last - 1; i >= first; --i) {
    if (tau(i) == 0.0) continue;
    const Vec t = tau(i) * stripDot<MaxCols>(strip, cols, V, i);
    strip.col(i) -= t;
    for (int j = i + 1; j < cols; ++j) strip.col(j).noalias() -= V(j, i) * t;
  }
}

// dst.segment(d0, h) = src.segment(s0, h) for h < S as fixed-size copies: GCC turns the
// dynamic-size copy into `rep movs`, whose start-up costs more than these few elements (a third
// of the rows-below rotation of level 1, 15 rows = 8 + 7, was spent there).
template <int S, class Dst, class Src>
inline void copySegment(Dst&& dst, int d0, const Src& src, int s0, int h) {
  if constexpr (S > 1) {
    if (h == S - 1) {
      dst.template segment<S - 1>(d0) = src.template segment<S - 1>(s0);
      return;
    }
    copySegment<S - 1>(dst, d0, src, s0, h);
  } else if (h == 1) {
    dst(d0) = src(s0);
  }
}

// Rows [r0, r0 + h) of X, columns [first, cols), into an S-row strip (h ≤ S; zero-padded
// below h), and back from a strip into Y's columns shifted by `shift`. Fixed-size copies need
// a matrix that can hold S rows (the edge-size QPs have 1-row G).
template <class Strip, class MatX>
inline void loadStrip(Strip& strip, const MatX& X, int r0, int h, int first, int cols) {
  constexpr int S = Strip::RowsAtCompileTime;
  constexpr int MaxRowsX = MatX::MaxRowsAtCompileTime;
  constexpr bool kFull = MaxRowsX == Eigen::Dynamic || MaxRowsX >= S;
  for (int j = first; j < cols; ++j) {
    if constexpr (kFull) {
      if (h == S) {
        strip.col(j) = X.col(j).template segment<S>(r0);
        continue;
      }
    }
    strip.col(j).setZero();
    copySegment<S>(strip.col(j), 0, X.col(j), r0, h);
  }
}
template <class Strip, class MatY>
inline void storeStrip(const Strip& strip, MatY& Y, int r0, int h, int first, int cols,
                       int shift = 0) {
  constexpr int S = Strip::RowsAtCompileTime;
  constexpr int MaxRowsY = std::decay_t<MatY>::MaxRowsAtCompileTime;
  constexpr bool kFull = MaxRowsY == Eigen::Dynamic || MaxRowsY >= S;
  for (int j = first; j < cols; ++j) {
    if constexpr (kFull) {
      if (h == S) {
        Y.col(j + shift).template segment<S>(r0) = strip.col(j);
        continue;
      }
    }
    copySegment<S>(Y.col(j + shift), r0, strip.col(j), 0, h);
  }
}

// X Zᵀ into the last n of the cols columns of Y, for rows [0, rows) of column-major X and Y,
// with Zt (n x cols, n ≤ cols): 8 rows at a time are copied out, so Y may be X (in place).
template <int MaxCols, class MatX, class MatY, class MatZ>
inline void multiplyRowStrips(const MatX& X, MatY&& Y, int rows, int cols, const MatZ& Zt,
                              int n) {
  constexpr int S = 8;
  Eigen::Matrix<double, S, MaxCols> strip, out;
  for (int r0 = 0; r0 < rows; r0 += S) {
    const int h = std::min(S, rows - r0);
    loadStrip(strip, X, r0, h, 0, cols);
    using Vec = Eigen::Matrix<double, S, 1>;
    for (int j = 0; j < n; ++j) {  // four independent sums per column of the output
      Vec a0 = Vec::Zero(), a1 = Vec::Zero(), a2 = Vec::Zero(), a3 = Vec::Zero();
      int l = 0;
      for (; l + 3 < cols; l += 4) {
        a0.noalias() += Zt(j, l) * strip.col(l);
        a1.noalias() += Zt(j, l + 1) * strip.col(l + 1);
        a2.noalias() += Zt(j, l + 2) * strip.col(l + 2);
        a3.noalias() += Zt(j, l + 3) * strip.col(l + 3);
      }
      for (; l < cols; ++l) a0.noalias() += Zt(j, l) * strip.col(l);
      out.col(j) = (a0 + a1) + (a2 + a3);
    }
    storeStrip(out, Y, r0, h, 0, n, cols - n);
  }
}

// Rows [r0, r0 + h) of Y (h ≤ S) through the reflectors in a local S-row strip, zero-padded;
// reflectors first.. touch only columns ≥ first.
template <int S, int MaxCols, bool Backward, class MatY, class MatV, class VecTau>
inline void reflectRows(MatY& Y, int r0, int h, int cols, const MatV& V, const VecTau& tau,
                        int first, int last) {
  Eigen::Matrix<double, S, MaxCols, S == 1 ? Eigen::RowMajor : Eigen::ColMajor> strip;
  loadStrip(strip, Y, r0, h, first, cols);
  if constexpr (Backward) reflectStripBackward<MaxCols>(strip, cols, V, tau, first, last);
  else reflectStrip<MaxCols>(strip, cols, V, tau, first, last);
  storeStrip(strip, Y, r0, h, first, cols);
}

// Y ← Y H_first ⋯ H_{last−1} (Backward: Y H_{last−1} ⋯ H_first) on rows [0, rows), 8 rows
// at a time, a last strip of 1–4 rows at its own height (Walker3: the 9th row of Zᵀ, the 3
// task rows carried below the second level).
template <int MaxCols, bool Backward = false, class MatY, class MatV, class VecTau>
inline void reflectRowStrips(MatY&& Y, int rows, int cols, const MatV& V, const VecTau& tau,
                             int first, int last) {
  if (first >= last || rows <= 0) return;
  for (int r0 = 0; r0 < rows; r0 += 8) {
    const int h = std::min(8, rows - r0);
    if (h == 1) reflectRows<1, MaxCols, Backward>(Y, r0, h, cols, V, tau, first, last);
    else if (h == 2) reflectRows<2, MaxCols, Backward>(Y, r0, h, cols, V, tau, first, last);
    else if (h == 3) reflectRows<3, MaxCols, Backward>(Y, r0, h, cols, V, tau, first, last);
    else if (h == 4) reflectRows<4, MaxCols, Backward>(Y, r0, h, cols, V, tau, first, last);
    else reflectRows<8, MaxCols, Backward>(Y, r0, h, cols, V, tau, first, last);
  }
}

// A chain of plane rotations of the columns of a column-major Y (rows [0, rows)), each
// rotation sharing one column with the next (x' = c x + s y, y' = −s x + c y for the
// pair (x, y)). The shared column stays in registers, 8 rows at a time, so each rotation
// costs one load and one store per 8 rows instead of two of each (and no call per
// rotation):
//   Up:      pairs (j, j + 1) for j = first, …, last − 1   (c(j), s(j))
//   UpShift: as Up, but column j is stored at j + 1 and the final column last at first
//            (the rotated columns shifted right by one, the last one moved to the front).
enum class RotationChain { Up, UpShift };

template <RotationChain K, int L, class MatY, class VecCs>
inline void rotationChainBlock(MatY& Y, int r0, int first, int last, const VecCs& c,
                               const VecCs& s) {
  using Vec = Eigen::Matrix<double, L, 1>;
  constexpr int shift = K == RotationChain::UpShift ? 1 : 0;
  Vec x = Y.col(first).template segment<L>(r0);  // carried: column j
  for (int j = first; j < last; ++j) {
    const Vec y = Y.col(j + 1).template segment<L>(r0);
    Y.col(j + shift).template segment<L>(r0) = c(j) * x + s(j) * y;
    x = c(j) * y - s(j) * x;
  }
  Y.col(shift ? first : last).template segment<L>(r0) = x;
}

template <RotationChain K, class MatY, class VecCs>
inline void rotationChain(MatY& Y, int rows, int first, int last, const VecCs& c,
                          const VecCs& s) {
  constexpr int MaxRowsY = MatY::MaxRowsAtCompileTime;
  int r0 = 0;
  if constexpr (MaxRowsY == Eigen::Dynamic || MaxRowsY >= 8)
    for (; r0 + 8 <= rows; r0 += 8) rotationChainBlock<K, 8>(Y, r0, first, last, c, s);
  if constexpr (MaxRowsY == Eigen::Dynamic || MaxRowsY >= 4)
    for (; r0 + 4 <= rows; r0 += 4) rotationChainBlock<K, 4>(Y, r0, first, last, c, s);
  for (; r0 < rows; ++r0) rotationChainBlock<K, 1>(Y, r0, first, last, c, s);
}

}  // namespace hqp::detail
