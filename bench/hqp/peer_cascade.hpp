#pragma once
// The peer of HqpWbc in the benchmarks and the corpus check: the paper's literal projector
// cascade on dynamic-size Eigen, for any stacked hierarchy (rows of level p from the offsets).
// Level p: min_u ‖W_p^½ (A_p (x + N u) − b_p)‖² s.t. all constraints ≤ p on x + N u, u ∈ R^n;
// then x += N u and N ← N (I − Â⁺ Â) with Â = W_p^½ A_p N, Â⁺ from Eigen's COD (allocates).
// Same QP code (ActiveSetQp, one type sized for the largest level) but no null-space basis, so
// every level's QP keeps n variables, and no preallocation of the cascade's matrices.
// Shared by BM_PeerWarm (bench_hqp.cpp), BM_Corpus (bench_corpus.cpp) and tools/hqp_corpus.cpp,
// so that the peer figure of every benchmark is one solver.
#include <Eigen/Dense>

#include <array>
#include <vector>

#include "hqp/active_set_qp.hpp"
#include "hqp/hqp_types.hpp"
#include "hqp/qp_status.hpp"

namespace hqp::bench {

// N variables, L levels, at most MaxRows task rows in a level, MaxC constraint rows in all.
template <int N, int L, int MaxRows, int MaxC>
class PeerCascade {
 public:
  using Qp = ActiveSetQp<N, MaxRows, 2, MaxC>;
  using Offsets = std::array<int, L + 1>;
  // A warm start given to level p's QP (rows index the stacked constraint rows, as in HqpWbc).
  struct WorkingSet {
    int count = 0;
    const int* rows = nullptr;
    const bool* upper = nullptr;
  };

  // Stacked rows: A (T × N), b, w (T), D (C × N), lower, upper (C); level p's task rows from
  // task_offset[p], its constraint rows from constraint_offset[p]. warm: each level's QP keeps
  // its working set of the last solve; ws (if given): start level p from ws[p] instead.
  // Returns the number of levels whose QP did not end Optimal.
  template <class MA, class VA, class MD, class VD>
  int solve(const MA& A, const VA& b, const VA& w, const MD& D, const VD& lower, const VD& upper,
            const Offsets& task_offset, const Offsets& constraint_offset, bool warm,
            const WorkingSet* ws = nullptr) {
    Eigen::MatrixXd Nmat = Eigen::MatrixXd::Identity(N, N);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(N);
    int failures = 0;
    for (int p = 0; p < L; ++p) {
      const int t0 = task_offset[p], m = task_offset[p + 1] - t0;
      const int c = constraint_offset[p + 1], c0 = constraint_offset[p];
      const Eigen::VectorXd sw = w.segment(t0, m).cwiseSqrt();
      const Eigen::MatrixXd Ap = sw.asDiagonal() * A.middleRows(t0, m);
      const Eigen::VectorXd bp = sw.asDiagonal() * b.segment(t0, m);
      const Eigen::MatrixXd AN = Ap * Nmat;
      Qp& qp = qps_[static_cast<std::size_t>(p)];
      qp.resize(N, m, 0, c);
      qp.A() = AN;
      qp.b() = bp - Ap * x;
      if (c > 0) {
        const Eigen::MatrixXd Dc = D.topRows(c);
        qp.C() = Dc * Nmat;
        const Eigen::VectorXd dx = Dc * x;
        for (int i = 0; i < c; ++i) {
          // Higher rows: widened to contain 0, met by x (as in HqpWbc).
          const double lo = lower(i) - dx(i), up = upper(i) - dx(i);
          qp.lower()(i) = i < c0 ? std::min(lo, 0.0) : lo;
          qp.upper()(i) = i < c0 ? std::max(up, 0.0) : up;
        }
      }
      if (!warm) qp.resetWorkingSet();
      else if (ws != nullptr) qp.setWorkingSet(ws[p].count, ws[p].rows, ws[p].upper);
      typename Qp::VectorX hint = Qp::VectorX::Zero(N);
      failures += qp.solve(hint, warm) != QpStatus::Optimal;
      x += Nmat * qp.x();
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(AN);
      cod.setThreshold(1e-9);
      Nmat = Nmat * (Eigen::MatrixXd::Identity(N, N) - cod.pseudoInverse() * AN);
    }
    x_ = x;
    return failures;
  }
  const Eigen::VectorXd& x() const { return x_; }

 private:
  std::array<Qp, L> qps_;
  Eigen::VectorXd x_;
};

}  // namespace hqp::bench
