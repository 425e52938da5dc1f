#pragma once
// WqpWbc: the same levels as HqpWbc, solved as ONE weighted QP (the paper's WqpWbc, Sec. IV-A):
//   min_x Σ_p λ_p Σ_{rows r of level p} w_r (a_r x − b_r)²
//   s.t.  lower_k ≤ D_k x ≤ upper_k   for every constraint of every level (all hard).
// Priorities become level weights λ_p (default λ_0 = 1, λ_{p+1} = λ_p / priority_ratio);
// task weights w act inside a level as in HqpWbc. Soft priority only: a higher level's
// residual is traded against lower ones at the rate 1/ratio (docs/hqp.md).

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "hqp/active_set_qp.hpp"
#include "hqp/constraint.hpp"
#include "hqp/dual_active_set_qp.hpp"
#include "hqp/hierarchy_qps.hpp"
#include "hqp/hqp_types.hpp"
#include "hqp/level.hpp"
#include "hqp/task.hpp"

namespace hqp {

template <int Nx, int NumLevels, int MaxActive>
struct WqpResult {
  Eigen::Matrix<double, Nx, 1> x = Eigen::Matrix<double, Nx, 1>::Zero();
  QpStatus status = QpStatus::Optimal;
  int iterations = 0;
  bool dual = false;                            // solved by DualActiveSetQp (setDualMethod)
  double objective = 0.0;                       // Σ_p λ_p Σ w (a x − b)² at x
  std::array<double, NumLevels> residual{};     // ‖A_p x − b_p‖² per level (unweighted)
  int num_active = 0;
  std::array<int, MaxActive> active_row{};      // index into the stacked constraint rows
  std::array<bool, MaxActive> active_upper{};
};

template <int Nx, class... Levels>
class WqpWbc {
  static_assert(sizeof...(Levels) > 0, "at least one level");
  static_assert(((Levels::nx == Nx) && ...), "every level has Nx variables");

 public:
  static constexpr int nx = Nx;
  static constexpr int num_levels = static_cast<int>(sizeof...(Levels));
  static constexpr int total_task_rows = (0 + ... + Levels::task_rows);
  static constexpr int total_constraint_rows = (0 + ... + Levels::constraint_rows);
  static constexpr std::array<int, sizeof...(Levels) + 1> task_offset =
      detail::rowOffsets<Levels::task_rows...>();
  static constexpr std::array<int, sizeof...(Levels) + 1> constraint_offset =
      detail::rowOffsets<Levels::constraint_rows...>();
  static constexpr int max_active = capacity(total_constraint_rows);

  using VectorX = Eigen::Matrix<double, Nx, 1>;
  using Result = WqpResult<Nx, num_levels, max_active>;
  // HqpWbc's types for the same levels (hierarchy_qps.hpp).
  using Qp = typename detail::HierarchyQps<Nx, Levels...>::Qp;
  // Stacked weighted rows of full column rank make the QP strictly convex: the dual method.
  using DualQp = std::conditional_t<(total_task_rows >= Nx && total_constraint_rows > 0),
                                    typename detail::HierarchyQps<Nx, Levels...>::DualQp,
                                    detail::NoQp>;
  template <int P>
  using LevelType = std::tuple_element_t<P, std::tuple<Levels...>>;

  explicit WqpWbc(const QpSettings& settings = {}, double priority_ratio = 1e3) : qp_(settings) {
    setPriorityRatio(priority_ratio);
  }

  template <int P>
  LevelType<P>& level() { return std::get<P>(levels_); }
  template <int P>
  const LevelType<P>& level() const { return std::get<P>(levels_); }

  // λ_p = ratio^(−p): each level counts `ratio` times more than the next one.
  void setPriorityRatio(double ratio) {
    double l = 1.0;
    for (auto& w : level_weight_) {
      w = l;
      l /= ratio;
    }
  }
  void setLevelWeight(int p, double lambda) {
    if (p >= 0 && p < num_levels) level_weight_[static_cast<std::size_t>(p)] = lambda;
  }
  double levelWeight(int p) const { return level_weight_[static_cast<std::size_t>(p)]; }
  void setWarmStart(bool on) { warm_start_ = on; }
  // Solve with DualActiveSetQp (on by default) when the weighted task rows have full column
  // rank (1/‖R⁻¹‖_F > √T · rank_tol · ‖A‖_F with the QP's rank_tol), ActiveSetQp otherwise.
  void setDualMethod(bool on) { dual_method_ = on; }
  void resetWarmStart() { qp_.resetWorkingSet(); }

  // One QP with all tasks (weighted) and all constraints; no heap, no exceptions.
  QpStatus solve() noexcept {
    stackAll(std::make_index_sequence<sizeof...(Levels)>{});
    // The input contract (docs/hqp.md, "Contracts"), as HqpWbc: finite data with magnitudes
    // ≤ max_magnitude, w ≥ 0, bounds ±inf only on their own side, finite level weights ≥ 0.
    const double mx = qp_.settings().max_magnitude;
    bool valid = detail::withinMagnitude(A_, mx) && detail::withinMagnitude(b_, mx) &&
                 detail::withinMagnitude(w_, mx) && detail::withinMagnitude(D_, mx) &&
                 (w_.array() >= 0.0).all();
    for (int r = 0; r < total_constraint_rows; ++r)
      valid = valid && detail::boundsValid(lower_(r), upper_(r), mx);
    for (double l : level_weight_) valid = valid && std::isfinite(l) && l >= 0.0 && l <= mx;
    if (!valid) {
      result_ = Result{};
      result_.status = QpStatus::InvalidInput;
      return result_.status;
    }
    qp_.resize(Nx, total_task_rows, 0, total_constraint_rows);
    qp_.A() = A_.topRows(total_task_rows);
    qp_.b() = b_.head(total_task_rows);
    scaleRows(std::make_index_sequence<sizeof...(Levels)>{});
    if constexpr (total_constraint_rows > 0) {
      qp_.C() = D_.topRows(total_constraint_rows);
      qp_.lower() = lower_.head(total_constraint_rows);
      qp_.upper() = upper_.head(total_constraint_rows);
    }
    result_.dual = dual_method_ && solveDual();
    if (!result_.dual) {
      result_.status = qp_.solve(warm_start_);
      result_.iterations = qp_.iterations();
    }
    if (result_.dual) {
      result_.x = dual_.x();
    } else if (qp_.x().size() == Nx && qp_.x().allFinite()) {
      result_.x = qp_.x();
    } else {
      result_.x.setZero();
      if (result_.status == QpStatus::Optimal) result_.status = QpStatus::NumericalFailure;
    }
    result_.objective = (qp_.A() * result_.x - qp_.b()).squaredNorm();
    residuals(std::make_index_sequence<sizeof...(Levels)>{});
    if (!result_.dual) {
      result_.num_active = std::min(qp_.numActive(), max_active);
      for (int a = 0; a < result_.num_active; ++a) {
        result_.active_row[static_cast<std::size_t>(a)] = qp_.activeRow(a);
        result_.active_upper[static_cast<std::size_t>(a)] = qp_.activeAtUpper(a);
      }
    }
    return result_.status;
  }

  const Result& result() const { return result_; }
  const VectorX& x() const { return result_.x; }
  const Qp& qp() const { return qp_; }

 private:
  // The dual method on the QP's data, warm from the QP's working set (its active set is handed
  // back as that working set), then its order-free route. False: ActiveSetQp decides
  // (rank-deficient rows, infeasible, iteration cap).
  bool solveDual() {
    if constexpr (std::is_same_v<DualQp, detail::NoQp>) {
      return false;
    } else {
      const double min_sigma = std::sqrt(static_cast<double>(total_task_rows)) *
                               qp_.settings().rank_tol * qp_.A().norm();
      if (!dual_.factorize(qp_.A(), qp_.b(), total_task_rows, Nx, min_sigma)) return false;
      const int prefer = warm_start_ ? DualQp::preferredRows(qp_, Nx, prefer_) : 0;
      QpStatus s = dual_.solve(qp_.C(), qp_.lower(), qp_.upper(), total_constraint_rows,
                               qp_.settings(), prefer_.data(), prefer);
      // Nearly dependent rows in this order: the routes that depend on none (docs/hqp.md).
      if (s == QpStatus::NumericalFailure || s == QpStatus::IterationLimit)
        s = dual_.solveOrderFree(qp_.C(), qp_.lower(), qp_.upper(), total_constraint_rows,
                                 qp_.settings());
      if (s != QpStatus::Optimal) return false;
      result_.status = s;
      result_.iterations = dual_.iterations();
      result_.num_active = std::min(dual_.numActive(), max_active);
      for (int a = 0; a < result_.num_active; ++a) {
        result_.active_row[static_cast<std::size_t>(a)] = dual_.activeRow(a);
        result_.active_upper[static_cast<std::size_t>(a)] = dual_.activeAtUpper(a);
      }
      qp_.setWorkingSet(result_.num_active, result_.active_row.data(), result_.active_upper.data());
      return true;
    }
  }

  template <std::size_t... I>
  void stackAll(std::index_sequence<I...>) {
    ((std::get<I>(levels_).stackTasks(A_, b_, w_, task_offset[I]),
      std::get<I>(levels_).stackConstraints(D_, lower_, upper_, constraint_offset[I])),
     ...);
  }
  // Rows of level p scaled by √(λ_p w_r).
  template <std::size_t... I>
  void scaleRows(std::index_sequence<I...>) {
    ((scaleLevel<static_cast<int>(I)>()), ...);
  }
  template <int P>
  void scaleLevel() {
    constexpr int r = LevelType<P>::task_rows;
    constexpr int t0 = task_offset[P];
    for (int i = 0; i < r; ++i) {
      const double s = std::sqrt(level_weight_[static_cast<std::size_t>(P)] * w_(t0 + i));
      qp_.A().row(t0 + i) *= s;
      qp_.b()(t0 + i) *= s;
    }
  }
  template <std::size_t... I>
  void residuals(std::index_sequence<I...>) {
    ((result_.residual[I] = (A_.template middleRows<LevelType<static_cast<int>(I)>::task_rows>(task_offset[I]) *
                                 result_.x -
                             b_.template segment<LevelType<static_cast<int>(I)>::task_rows>(task_offset[I]))
                                .squaredNorm()),
     ...);
  }

  std::tuple<Levels...> levels_;
  Qp qp_;
  DualQp dual_;
  std::array<int, Nx> prefer_{};
  std::array<double, sizeof...(Levels)> level_weight_{};
  bool warm_start_ = true;
  bool dual_method_ = true;
  Eigen::Matrix<double, capacity(total_task_rows), Nx> A_ = decltype(A_)::Zero();
  Eigen::Matrix<double, capacity(total_task_rows), 1> b_ = decltype(b_)::Zero();
  Eigen::Matrix<double, capacity(total_task_rows), 1> w_ = decltype(w_)::Ones();
  Eigen::Matrix<double, capacity(total_constraint_rows), Nx> D_ = decltype(D_)::Zero();
  Eigen::Matrix<double, capacity(total_constraint_rows), 1> lower_ =
      decltype(lower_)::Constant(-kInf);
  Eigen::Matrix<double, capacity(total_constraint_rows), 1> upper_ = decltype(upper_)::Constant(kInf);
  Result result_{};
};

}  // namespace hqp
