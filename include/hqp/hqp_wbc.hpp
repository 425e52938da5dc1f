#pragma once
// HqpWbc: the strict hierarchy of Section IV-A of the paper (eqs. 3 and 4).
//
// Level p (1-based in the paper, 0-based here) is solved in a null-space basis of all
// higher tasks: x = x*_{p−1} + Z_{p−1} u with Z_0 = I, x*_0 = 0, and
//   min_u ‖W_p^½ (A_p (x*_{p−1} + Z_{p−1} u) − b_p)‖²
//   s.t.  lower_k − D_k x*_{p−1} ≤ D_k Z_{p−1} u ≤ upper_k − D_k x*_{p−1}   for all k ≤ p,
// then x*_p = x*_{p−1} + Z_{p−1} u* and Z_p = Z_{p−1} null(Â_p), Â_p = W_p^½ A_p Z_{p−1} (eq. 4).
// A basis (not the projector N_p) makes every lower QP smaller: 30 → 24 → 12 → 9 variables
// for the paper's full-rank levels. Each level's QP is an ActiveSetQp sized at compile time
// for that level, owned here and warm-started from the previous tick.
// Deferred constraints (HqpSettings::defer_constraints): first the levels above the last take
// their unconstrained steps and the last level's QP holds every row; if it ends Optimal that is
// the same optimum (each higher level at its unconstrained minimum), else the cascade above runs.
// See docs/hqp.md for the guarantees, the infeasibility policy and the slack option.

#include <Eigen/Core>
#include <Eigen/QR>

#include <algorithm>
#include <array>
#include <chrono>
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
#include "hqp/null_space.hpp"
#include "hqp/task.hpp"

namespace hqp {

struct HqpSettings {
  QpSettings qp{};          // settings of every level's QP (iteration cap, tolerances)
  double rank_tol = 1e-9;   // Â_p pivots ≤ rank_tol · (largest weighted row norm of A_p) count as 0
  bool warm_start = true;   // reuse each level's working set from the previous solve
  // A last level whose Â_p has full column rank is a strictly convex QP: solve it with the
  // dual method (DualActiveSetQp) from its unconstrained minimizer instead of ActiveSetQp.
  bool dual_last_level = true;
  // Numerical health: after all levels are solved, level p's weighted residual ‖W^½(A_p x − b_p)‖
  // at the final x may exceed its value at x*_p by at most
  //   residual_rise_tol · (‖W^½ A_p‖_F · max(‖x*_p‖, 1) + ‖W^½ b_p‖);
  // a larger rise (lower levels' data so large that their rounding swamps a higher level) is
  // reported as HqpLevelResult::degraded and HqpResult::higher_level_degraded.
  double residual_rise_tol = 1e-6;
  // Deadline (docs/hqp.md, "Deadline-aware solving"): level p ≥ 1 is cut, i.e. it and every
  // lower level are skipped and x keeps x*_{p−1} (their part of x is the minimum-norm
  // completion, 0 in the null space of the levels solved), if starting it would exceed a budget:
  //   elapsed µs since solve() began + the level's µs in the last solve that ran it > budget_us,
  //   QP iterations so far + the level's iterations in that solve > budget_iterations
  // (each estimate halved on every solve that cut the level, so that it is tried again).
  // Level 0 is always solved. 0 (or any value not > 0) = no budget; off by default.
  double budget_us = 0.0;
  int budget_iterations = 0;
  // Per-level wall time (HqpLevelResult::time_us): two steady_clock reads per level. Off: no
  // clock is read unless budget_us > 0 (the time budget needs the clock; budget_iterations
  // does not), and time_us is 0. Compiling with HQP_NO_LEVEL_TIMING turns it off for good.
  bool time_levels = true;
  // KKT residuals of every level's QP (HqpLevelResult::kkt, docs/hqp.md, "Certificate"):
  // O((task rows + active rows) · n + constraint rows) per level, no factorization. Off by
  // default: a check for tests and diagnostics, not needed to use the answer. The multipliers
  // themselves are always reported (they are a copy).
  bool kkt_residuals = false;
  // Constraints deferred to the last level (docs/hqp.md, "Deferred constraints"): every level
  // above the last takes its unconstrained least-squares step without looking at a constraint,
  // and the last level's QP holds every constraint row. If that QP ends Optimal, each higher
  // level sits at its unconstrained minimum at a point meeting all rows, so x is the
  // lexicographic optimum; otherwise the cascade runs from the start (the attempt's work is
  // lost). Not tried with an iteration budget; with a time budget the cascade takes over where a
  // level would be cut.
  bool defer_constraints = true;
  // Least-distance step (docs/hqp.md, "Least-distance step"): a level above the last whose
  // unconstrained minimum-norm step breaks a row, and whose QP has no working set to start from,
  // first looks for the minimum-norm point among its unconstrained minimizers that meets every
  // row: u' = [y; v], v = argmin ‖v‖ over the rows, a strictly convex least-distance problem
  // for the dual method. If one exists it is the level's minimum-norm optimum (the level's
  // objective is at its unconstrained minimum there); if none does, the level's QP runs.
  bool least_distance_step = true;
  // Dual start (docs/hqp.md, "Dual start"): a level between the first and the last whose QP has
  // no working set and whose start u = 0 breaks a row (phase 1 would run, and the primal method
  // would then climb back from a far vertex) first solves the level with ½δ‖v‖² added on its
  // null-space part v (strictly convex, so the dual method applies) and hands that solution's
  // active rows to the QP as its working set. The QP then solves the level: the answer is the QP's.
  bool dual_start = true;
};

// KKT residuals of one level's QP (docs/hqp.md, "Certificate"), in its variables u (x = x*_{p−1}
// + Z u, Z orthonormal): min ½‖Â u − b̂‖², Â = W^½ A_p Z, b̂ = W^½ (b_p − A_p x*_{p−1}),
// s.t. lower_i ≤ D_i x ≤ upper_i for the constraint rows i of levels ≤ p.
struct HqpKkt {
  bool computed = false;          // HqpSettings::kkt_residuals on and the level solved
  // Stationarity ‖Âᵀ(Â u* − b̂) + Σ_a λ_a (D_a Z)ᵀ‖_∞, i.e. ‖Zᵀ(A_pᵀ W (A_p x*_p − b_p) + D_Wᵀ λ)‖_∞.
  double stationarity = 0.0;
  double stationarity_scale = 0.0;  // ‖Â‖_F ‖Â u* − b̂‖ + Σ_a |λ_a| ‖D_a Z‖: size of its terms
  // ‖Â‖_F (‖Â u*‖ + ‖b̂‖), the size of the gradient's own terms: unlike stationarity_scale
  // it does not grow with the multipliers, which a nearly dependent working set blows up
  // (docs/hqp.md, "Certificate").
  double gradient_scale = 0.0;
  double primal = 0.0;           // max over rows of levels ≤ p of the bound violation at x*_p / ‖D_i‖
  double dual = 0.0;             // max over active rows of the wrong-signed part of λ_a, times ‖D_a‖
  double complementarity = 0.0;  // max over active rows of |λ_a (D_a x*_p − its bound)|
};

// What happened at one level; MaxActive = capacity of the stacked constraint rows.
template <int MaxActive>
struct HqpLevelResult {
  QpStatus status = QpStatus::Optimal;
  double residual = 0.0;    // ‖A_p x* − b_p‖² over the level's tasks at the final x*
  double objective = 0.0;   // Σ w (a x* − b)², the weighted residual the level minimizes
  int rank = 0;             // rank of Â_p = W_p^½ A_p Z_{p−1}
  int null_dim = 0;         // dim of the null space left to lower levels (columns of Z_p)
  int variables = 0;        // size of this level's QP (columns of Z_{p−1})
  int iterations = 0;       // QP iterations (plus those of the slack QP)
  int num_active = 0;       // constraint rows at a bound in this level's QP
  std::array<int, MaxActive> active_row{};      // index into the stacked constraint rows
  std::array<bool, MaxActive> active_upper{};   // true: at upper, false: at lower
  bool constraints_dropped = false;  // infeasible own constraints were dropped (no slack)
  bool slack_used = false;           // own constraints were relaxed minimally (slack option)
  double violation = 0.0;            // Σ over own rows of squared bound violation at x*
  double time_us = 0.0;              // wall time of this level's solve (steady_clock), µs;
                                     // 0 with HqpSettings::time_levels off
  bool dual = false;                 // solved by DualActiveSetQp (HqpSettings::dual_last_level)
  // At the minimum-norm unconstrained minimizer that meets every row, found by the dual method
  // without the level's QP (HqpSettings::least_distance_step); iterations are that method's.
  bool least_distance = false;
  // The level's QP started from the dual start's working set (HqpSettings::dual_start);
  // iterations include the dual method's.
  bool dual_start = false;
  // The level's residual at the final x rose beyond HqpSettings::residual_rise_tol above its
  // value at x*_p: the lower levels degraded it (numerical health, docs/hqp.md).
  bool degraded = false;
  // Certificate: multiplier[a] is λ of active_row[a] in this level's QP (rows of this level and
  // of higher ones), for the objective ½‖W^½(A_p x − b_p)‖²: Zᵀ(A_pᵀ W (A_p x*_p − b_p) +
  // Σ_a λ_a D_aᵀ) = 0, λ_a ≥ 0 at an upper bound (active_upper), ≤ 0 at a lower bound. 0 unless
  // the level's QP ended Optimal (free steps, levels without constraints and, on the deferred
  // path, the levels above the last have none).
  std::array<double, MaxActive> multiplier{};
  HqpKkt kkt{};                      // its residuals (HqpSettings::kkt_residuals)
};
// A level cut by the budget has status BudgetCut, iterations 0, and residual / objective at the
// final x.

template <int Nx, int NumLevels, int MaxActive>
struct HqpResult {
  Eigen::Matrix<double, Nx, 1> x = Eigen::Matrix<double, Nx, 1>::Zero();  // x*
  QpStatus status = QpStatus::Optimal;  // first non-optimal level's status, else Optimal
  int failed_level = -1;                // 0-based index of that level, −1 if none
  // Some level's residual was degraded by the lower levels (HqpLevelResult::degraded): x is
  // finite but does not keep the priorities to tolerance. Treat as a solver failure.
  bool higher_level_degraded = false;
  // First level cut by the budget (HqpSettings::budget_us / budget_iterations), −1 if none.
  // If no higher level failed, status is then QpStatus::BudgetCut and failed_level == cut_level.
  int cut_level = -1;
  // The solve took the deferred path (HqpSettings::defer_constraints): the levels above the
  // last report no QP and no active row, the last level holds every constraint row.
  bool deferred = false;
  bool deferred_tried = false;  // it was tried (deferred false: it failed, the cascade ran)
  std::array<HqpLevelResult<MaxActive>, NumLevels> levels{};
};

namespace detail {

template <class... Levels>
constexpr int maxConstraintRows() {
  int m = 0;
  ((m = std::max(m, Levels::constraint_rows)), ...);
  return m;
}

template <class... Levels>
constexpr int maxSlackRows() {
  int m = 0;
  ((m = Levels::slack ? std::max(m, Levels::constraint_rows) : m), ...);
  return m;
}

}  // namespace detail

template <int Nx, class... Levels>
class HqpWbc {
  static_assert(sizeof...(Levels) > 0, "at least one level");
  static_assert(((Levels::nx == Nx) && ...), "every level has Nx variables");

 public:
  static constexpr int nx = Nx;
  static constexpr int num_levels = static_cast<int>(sizeof...(Levels));
  static constexpr int total_task_rows = (0 + ... + Levels::task_rows);
  static constexpr int total_constraint_rows = (0 + ... + Levels::constraint_rows);
  static constexpr int max_task_rows = detail::maxTaskRows<Levels...>();
  static constexpr int max_own_constraint_rows = detail::maxConstraintRows<Levels...>();
  // Level p's rows start at task_offset[p] / constraint_offset[p] in the stacked arrays;
  // level p's QP sees the constraint rows [0, constraint_offset[p + 1]).
  static constexpr std::array<int, sizeof...(Levels) + 1> task_offset =
      detail::rowOffsets<Levels::task_rows...>();
  static constexpr std::array<int, sizeof...(Levels) + 1> constraint_offset =
      detail::rowOffsets<Levels::constraint_rows...>();
  static constexpr int max_active = capacity(total_constraint_rows);

  using VectorX = Eigen::Matrix<double, Nx, 1>;
  using Result = HqpResult<Nx, num_levels, max_active>;
  template <int P>
  using LevelType = std::tuple_element_t<P, std::tuple<Levels...>>;
  // One QP object per level (each keeps its own warm start), all of one type: Nx variables,
  // all constraint rows, and (WqpWbc's type, hierarchy_qps.hpp) room for every task row. One
  // type instead of one per level, and the same as WqpWbc's, keeps compile times down (each
  // ActiveSetQp instantiation costs ~15 s of compiler time); the price is storage: on Table
  // I's hierarchy 27 kB per level QP more than sized for the largest level (docs/hqp.md).
  using Qp = typename detail::HierarchyQps<Nx, Levels...>::Qp;
  template <int P>
  using LevelQp = std::conditional_t<(constraint_offset[P + 1] > 0), Qp, detail::NoQp>;
  // Slack levels (Level<..., true>): minimal violation of one level's own rows, variables
  // [u; w] with w the clamped rows. Only compiled in when some level has the option.
  static constexpr bool has_slack_levels =
      ((Levels::slack && Levels::constraint_rows > 0) || ...);
  static constexpr int max_slack_rows = detail::maxSlackRows<Levels...>();
  // The dual method's solver, one object for its three uses, which never overlap within a level
  // and hand nothing on but rows copied out: the last level (HqpSettings::dual_last_level,
  // at most Nx variables and its task rows), the least-distance step (least_distance_step,
  // a level's null-space part) and the dual start (dual_start, a level's variables, its task
  // rows plus one per null-space variable). One type sized for the largest use, WqpWbc's
  // too: the method's code is compiled once (docs/hqp.md, "One copy of the dual method's code").
  static constexpr int last_task_rows = LevelType<sizeof...(Levels) - 1>::task_rows;
  using DualQp = std::conditional_t<
      (total_constraint_rows > 0 && (last_task_rows > 0 || sizeof...(Levels) > 2)),
      typename detail::HierarchyQps<Nx, Levels...>::DualQp, detail::NoQp>;
  using SlackQp = std::conditional_t<
      has_slack_levels,
      ActiveSetQp<Nx + capacity(max_slack_rows), capacity(max_slack_rows), 0,
                  capacity(total_constraint_rows)>,
      detail::NoQp>;

  explicit HqpWbc(const HqpSettings& settings = {})
      : settings_(settings),
        qps_(makeQps(settings.qp, std::make_index_sequence<sizeof...(Levels)>{})),
        slack_qp_(settings.qp) {}

  // Levels in priority order; fill their tasks and constraints in place before solve().
  template <int P>
  LevelType<P>& level() { return std::get<P>(levels_); }
  template <int P>
  const LevelType<P>& level() const { return std::get<P>(levels_); }

  // Slack option for level p's own constraints: available for levels declared with it
  // (Level<..., true> / SoftLevel; off by default, as in the paper); false if not available.
  bool setSlack(int p, bool on) {
    if (p < 0 || p >= num_levels || !slack_capable_[static_cast<std::size_t>(p)]) return false;
    slack_[static_cast<std::size_t>(p)] = on;
    return true;
  }
  bool slack(int p) const { return p >= 0 && p < num_levels && slack_[static_cast<std::size_t>(p)]; }

  const HqpSettings& settings() const { return settings_; }
  void setRankTolerance(double tol) { settings_.rank_tol = tol; }
  void setWarmStart(bool on) { settings_.warm_start = on; }
  void setDualLastLevel(bool on) { settings_.dual_last_level = on; }
  void setLevelTiming(bool on) { settings_.time_levels = on; }    // HqpSettings::time_levels
  void setKktResiduals(bool on) { settings_.kkt_residuals = on; }  // HqpSettings::kkt_residuals
  void setDeferConstraints(bool on) { settings_.defer_constraints = on; }
  void setLeastDistanceStep(bool on) { settings_.least_distance_step = on; }
  void setDualStart(bool on) { settings_.dual_start = on; }
  // Per-solve budget (HqpSettings::budget_us / budget_iterations; ≤ 0 = none).
  void setBudget(double us, int iterations) {
    settings_.budget_us = us;
    settings_.budget_iterations = iterations;
  }

  // Forget every level's working set (the next solve starts cold) and the budget's cost
  // estimates (HqpSettings::budget_us).
  void resetWarmStart() {
    std::apply([](auto&... qp) { (resetQp(qp), ...); }, qps_);
    resetQp(slack_qp_);
    last_time_us_.fill(0.0);
    last_iterations_.fill(0);
  }

  // Solves the hierarchy; no heap, no exceptions, bounded by the QPs' iteration caps.
  QpStatus solve() noexcept {
    if (settings_.budget_us > 0.0) solve_start_ = std::chrono::steady_clock::now();
    iterations_used_ = 0;
    result_.cut_level = -1;
    stackAll(std::make_index_sequence<sizeof...(Levels)>{});
    // Row norms, once per solve: ‖A_i‖² for every level's rank scale and checkHealth, ‖D_i‖.
    ha_.template head<total_task_rows>() =
        A_.template topRows<total_task_rows>().rowwise().squaredNorm();
    if constexpr (total_constraint_rows > 0)
      Dnorm_.head(total_constraint_rows) = D_.topRows(total_constraint_rows).rowwise().norm();
    const bool defer = deferAllowed();
    begin(defer);
    result_.higher_level_degraded = false;
    result_.deferred = false;
    result_.deferred_tried = false;
    if (!inputValid()) {
      for (auto& lr : result_.levels) lr = HqpLevelResult<max_active>{};
      result_.status = QpStatus::InvalidInput;
      result_.failed_level = 0;
      result_.levels[0].status = QpStatus::InvalidInput;
      result_.x = x_;
      return result_.status;
    }
    conflict_.count = 0;
    ns_deferred_.fill(false);
    if (defer) {
      result_.deferred_tried = true;
      deferred_ = true;
      aborted_ = false;
      solveLevels(std::make_index_sequence<sizeof...(Levels)>{});
      deferred_ = false;
      result_.deferred = !aborted_;
      if (aborted_) begin();  // the cascade from the start
      else resetHigherWorkingSets(std::make_index_sequence<sizeof...(Levels) - 1>{});
      aborted_ = false;
    }
    if (!result_.deferred) {
      higher_free_ = true;
      solveLevels(std::make_index_sequence<sizeof...(Levels)>{});
      // Every level above the last ended at its unconstrained minimum: the next solve tries the
      // deferred path (their working sets emptied). Otherwise they keep their warm starts.
      if (settings_.defer_constraints && higher_free_ && result_.cut_level < 0)
        resetHigherWorkingSets(std::make_index_sequence<sizeof...(Levels) - 1>{});
    }
    if (result_.deferred) deferredX();
    else reconstructX(num_levels);
    // Never a non-finite x: fall back to the last finite x*_p of the higher levels (or 0),
    // with a non-optimal status at the first level left out.
    if (!x_.allFinite()) {
      int p = num_levels - 1;
      for (; p > 0; --p) {
        reconstructX(p);
        if (x_.allFinite()) break;
      }
      if (p == 0) x_.setZero();
      if (result_.failed_level < 0 || result_.failed_level > p) {
        result_.failed_level = p;
        result_.status = QpStatus::NumericalFailure;
      }
      if (result_.levels[static_cast<std::size_t>(p)].status == QpStatus::Optimal)
        result_.levels[static_cast<std::size_t>(p)].status = QpStatus::NumericalFailure;
    } else {
      checkHealth();
      if (settings_.kkt_residuals) lastLevelPrimal();
    }
    result_.x = x_;
    return result_.status;
  }

  // Level p's QP as last solved (reduced variables u'), for inspection and diagnostics.
  template <int P>
  const LevelQp<P>& levelQp() const { return std::get<P>(qps_); }

  const Result& result() const { return result_; }
  const VectorX& x() const { return x_; }
  QpStatus status() const { return result_.status; }

  // The stacked problem of the last solve() (rows of level p from task_offset[p] /
  // constraint_offset[p]); for recording problem instances (hqp/problem_instance.hpp).
  // The bounds are not offered: solve() drops or relaxes an infeasible level's bounds in place.
  const Eigen::Matrix<double, capacity(total_task_rows), Nx>& stackedA() const { return A_; }
  const Eigen::Matrix<double, capacity(total_task_rows), 1>& stackedB() const { return b_; }
  const Eigen::Matrix<double, capacity(total_task_rows), 1>& stackedWeights() const { return w_; }
  const Eigen::Matrix<double, capacity(total_constraint_rows), Nx>& stackedD() const { return D_; }

  // Replay: level p's QP starts the next solve() from this working set (rows index the
  // stacked constraint rows, as HqpLevelResult::active_row), which belongs to a QP of
  // `variables` unknowns; if the level's QP then has another size, it starts cold, as in the
  // run. False for a level without a QP (no constraint up to it).
  bool setWorkingSet(int p, int variables, int count, const int* rows, const bool* upper) {
    return setWorkingSetOf(p, variables, count, rows, upper,
                           std::make_index_sequence<sizeof...(Levels)>{});
  }

 private:
  using MatrixM = MaxMatrix<capacity(max_task_rows), Nx>;
  using VectorM = MaxVector<capacity(max_task_rows)>;
  using VectorU = MaxVector<Nx>;
  using VectorC = Eigen::Matrix<double, capacity(total_constraint_rows), 1>;
  using LeastSquares = std::conditional_t<(constraint_offset[1] == 0),
                                          Eigen::HouseholderQR<MatrixM>, detail::NoQp>;
#ifdef HQP_NO_LEVEL_TIMING
  static constexpr bool kLevelTiming = false;  // HqpSettings::time_levels is ignored
#else
  static constexpr bool kLevelTiming = true;
#endif

  template <std::size_t... I>
  static std::tuple<LevelQp<static_cast<int>(I)>...> makeQps(const QpSettings& s,
                                                             std::index_sequence<I...>) {
    return std::tuple<LevelQp<static_cast<int>(I)>...>((static_cast<void>(I), s)...);
  }
  template <std::size_t... I>
  static auto qpTupleType(std::index_sequence<I...>) -> std::tuple<LevelQp<static_cast<int>(I)>...>;
  using QpTuple = decltype(qpTupleType(std::make_index_sequence<sizeof...(Levels)>{}));

  template <class Qp>
  static void resetQp(Qp& qp) {
    if constexpr (!std::is_same_v<Qp, detail::NoQp>) qp.resetWorkingSet();
  }

  template <std::size_t... I>
  bool setWorkingSetOf(int p, int variables, int count, const int* rows, const bool* upper,
                      std::index_sequence<I...>) {
    bool ok = false;
    const auto set = [&](auto& qp, int r, int c) {
      if constexpr (!std::is_same_v<std::remove_reference_t<decltype(qp)>, detail::NoQp>) {
        if (variables < 0 || variables > Nx) return;
        qp.resize(variables, r, 0, c);  // the sizes solveLevel() will ask for if n matches
        qp.setWorkingSet(count, rows, upper);
        ok = true;
      }
    };
    ((static_cast<int>(I) == p ? set(std::get<I>(qps_), LevelType<static_cast<int>(I)>::task_rows,
                                     constraint_offset[I + 1])
                               : void()),
     ...);
    return ok;
  }

  template <std::size_t... I>
  void stackAll(std::index_sequence<I...>) {
    ((std::get<I>(levels_).stackTasks(A_, b_, w_, task_offset[I]),
      std::get<I>(levels_).stackConstraints(D_, lower_, upper_, constraint_offset[I])),
     ...);
  }

  // The input contract (docs/hqp.md, "Contracts"): finite A, b, w, D with magnitudes
  // ≤ QpSettings::max_magnitude (NaN and ±inf fail the vectorized |v| ≤ max test), w ≥ 0,
  // bounds NaN-free and ±inf only on their own side. Never NaN out.
  // It reads the row norms solve() computed first: rows of norm ≤ max / 2 (NaN and ±inf fail
  // the test) hold only entries ≤ max, so A and D are scanned entry by entry only where some
  // row is longer (or (max / 2)² overflows).
  bool inputValid() const {
    const double mx = settings_.qp.max_magnitude;
    const double half = 0.5 * mx, half2 = half * half;
    constexpr int T = total_task_rows, C = total_constraint_rows;
    const bool fast = half >= 0.0 && half2 < kInf;
    const bool a_short = fast && (ha_.template head<T>().array() <= half2).all();
    const bool d_short = fast && (Dnorm_.template head<C>().array() <= half).all();
    if ((!a_short && !detail::withinMagnitude(A_, mx)) || !detail::withinMagnitude(b_, mx) ||
        !detail::withinMagnitude(w_, mx) || (!d_short && !detail::withinMagnitude(D_, mx)))
      return false;
    if (w_.minCoeff() < 0.0) return false;
    for (int r = 0; r < total_constraint_rows; ++r)
      if (!detail::boundsValid(lower_(r), upper_(r), mx)) return false;
    return true;
  }

  // Numerical health (HqpSettings::residual_rise_tol): every level's weighted residual at the
  // final x against its value at x*_p. ‖x*_p‖ ≤ Σ_{q ≤ p} ‖u'_q‖ (orthonormal bases).
  // O(total task rows · Nx) per solve.
  void checkHealth() {
    constexpr int T = total_task_rows;
    // All rows at once (column-major A_: one gemv and a column-wise sum, vectorized).
    he_.template head<T>().noalias() = A_.template topRows<T>() * x_;
    he_.template head<T>() -= b_.template head<T>();
    double xs = 0.0;  // bound of ‖x*_p‖
    for (int p = 0; p < num_levels; ++p) {
      const std::size_t ps = static_cast<std::size_t>(p);
      auto& lr = result_.levels[ps];
      if (var_[ps] > 0) xs += up_[ps].norm();
      const int t0 = task_offset[ps], r = task_offset[ps + 1] - t0;
      double an2 = 0.0, bn2 = 0.0, e2 = 0.0, e2u = 0.0;
      for (int i = t0; i < t0 + r; ++i) {
        const double w = w_(i);
        const double e = he_(i);
        an2 += w * ha_(i);
        bn2 += w * b_(i) * b_(i);
        e2 += w * e * e;
        e2u += e * e;
      }
      if (lr.status == QpStatus::BudgetCut) {  // not solved: report where x left it
        lr.objective = e2;
        lr.residual = e2u;
        continue;
      }
      const double tol = settings_.residual_rise_tol *
                         (std::sqrt(an2) * std::max(xs, 1.0) + std::sqrt(bn2));
      if (!(std::sqrt(e2) <= std::sqrt(lr.objective) + tol)) {
        lr.degraded = true;
        result_.higher_level_degraded = true;
      }
    }
  }

  // The state before level 0: Z_{−1} = I, x*_{−1} = 0. The deferred path copies only the task
  // rows of the levels above the last (deferredRows forms the others from A_ and D_).
  void begin(bool deferred = false) {
    bound_count_ = 0;
    result_.status = QpStatus::Optimal;
    result_.failed_level = -1;
    x_.setZero();
    n_ = Nx;
    // Working copy of all rows in the reduced coordinates of the current level (Z_{−1} = I),
    // and the reduced right-hand sides b − A x*, D x* (x*_{−1} = 0).
    constexpr int higher = task_offset[num_levels - 1];
    if (deferred) {
      W_.template topRows<higher>() = A_.template topRows<higher>();
      bt_.template head<higher>() = b_.template head<higher>();
      return;
    }
    W_.template topRows<total_task_rows>() = A_.template topRows<total_task_rows>();
    if constexpr (total_constraint_rows > 0) {
      W_.template middleRows<total_constraint_rows>(total_task_rows) =
          D_.template topRows<total_constraint_rows>();
      dx_.setZero();
    }
    bt_ = b_;
  }

  // HqpSettings::defer_constraints: worth trying only where some constraint row would be
  // checked above the last level, and only while no level above the last holds a working set:
  // a cascade keeps them only if a row held some level above the last away from its minimum
  // (else solve() empties them), and then the attempt would fail again. A rule on the working
  // sets alone, so that recorded instances replay exactly.
  bool deferAllowed() const {
    return num_levels > 1 && constraint_offset[num_levels - 1] > 0 &&
           settings_.defer_constraints && settings_.budget_iterations <= 0 &&
           higherWorkingSetsEmpty(std::make_index_sequence<sizeof...(Levels) - 1>{});
  }
  template <std::size_t... I>
  bool higherWorkingSetsEmpty(std::index_sequence<I...>) const {
    const auto empty = [](const auto& qp) {
      if constexpr (std::is_same_v<std::decay_t<decltype(qp)>, detail::NoQp>) return true;
      else return qp.numActive() == 0;
    };
    return (empty(std::get<I>(qps_)) && ...);
  }
  // After a deferred solve the levels above the last ran no QP: their working sets are empty,
  // as after a free step, so the warm state stays the working sets alone.
  template <std::size_t... I>
  void resetHigherWorkingSets(std::index_sequence<I...>) {
    (resetQp(std::get<I>(qps_)), ...);
  }
  // Rows from here on are the level's own (bounds not widened to contain 0, locked rows
  // checked): c0, or 0 on the deferred path, whose x*_{p−1} was never checked against a row.
  int ownBegin(int c0) const { return deferred_ ? 0 : c0; }

  template <std::size_t... I>
  void solveLevels(std::index_sequence<I...>) {
    (timedLevel<static_cast<int>(I)>(), ...);
  }

  // Per-level wall time for diagnostics: two vDSO clock reads (~40 ns) per level, only if
  // time_levels is on or a time budget needs them.
  template <int P>
  void timedLevel() {
    const bool timed = kLevelTiming && settings_.time_levels;
    const bool clock = timed || settings_.budget_us > 0.0;
    if (aborted_) return;  // the deferred path failed: the cascade starts over
    std::chrono::steady_clock::time_point start{};
    if (clock) start = std::chrono::steady_clock::now();
    const bool over = result_.cut_level < 0 && P > 0 && overBudget(P, start);
    if (deferred_ && over) {  // a cut is the cascade's to make
      aborted_ = true;
      return;
    }
    if (over) {
      result_.cut_level = P;
      // A cut level never refreshes its estimate: halve it, so that one slow solve cuts the
      // level for a few ticks, not for ever.
      last_time_us_[P] *= 0.5;
      last_iterations_[P] /= 2;
    }
    if (result_.cut_level >= 0) return skipLevel(P);
    solveLevel<P>();
    auto& lr = result_.levels[P];
    const double us =
        clock ? std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                    .count()
              : 0.0;
    lr.time_us = timed ? us : 0.0;
    iterations_used_ += lr.iterations;
    last_time_us_[P] = us;  // the next solve's estimate of this level
    last_iterations_[P] = lr.iterations;
  }

  // Would starting level p exceed the budget (HqpSettings::budget_us / budget_iterations)?
  // The level's cost is estimated by its cost in the last solve that ran it (warm-started
  // levels cost about the same from tick to tick), halved on every solve that cut it.
  template <class TimePoint>
  bool overBudget(int p, TimePoint now) const {
    const std::size_t ps = static_cast<std::size_t>(p);
    if (settings_.budget_iterations > 0 &&
        iterations_used_ + last_iterations_[ps] > settings_.budget_iterations)
      return true;
    if (!(settings_.budget_us > 0.0)) return false;
    const double elapsed = std::chrono::duration<double, std::micro>(now - solve_start_).count();
    return elapsed + last_time_us_[ps] > settings_.budget_us;
  }

  // A level cut by the budget: no contribution to x (reconstructX skips var_ = 0).
  void skipLevel(int p) {
    const std::size_t ps = static_cast<std::size_t>(p);
    auto& lr = result_.levels[ps];
    lr = HqpLevelResult<max_active>{};
    lr.status = QpStatus::BudgetCut;
    lr.variables = n_;
    lr.null_dim = n_;
    var_[ps] = 0;
    rank_[ps] = 0;
    noteStatus(p, QpStatus::BudgetCut);
  }

  void noteStatus(int p, QpStatus s) {
    if (s != QpStatus::Optimal && result_.failed_level < 0) {
      result_.failed_level = p;
      result_.status = s;
    }
  }

  // Row norms below this count as zero rows when scaling constraint violations.
  static double rowScale(double norm) { return norm > 1e-300 ? norm : 1.0; }

  // x* = Σ_p Z_{p−1} Q_p u'_p with Z_p = Z_{p−1} Q_p E_p, E_p = [0; I] (the null-space
  // columns): x* = Q_0 (u'_0 + E_0 Q_1 (u'_1 + E_1 Q_2 (…))), evaluated from the last level up
  // with each level's stored reflectors (vector work only; no Z is ever formed).
  // Levels [0, levels) only: x*_{levels−1} (the fallback of solve()).
  void reconstructX(int levels) {
    v_.resize(0);
    for (int p = levels - 1; p >= 0; --p) {
      const std::size_t ps = static_cast<std::size_t>(p);
      const int n = var_[ps];
      if (n == 0) continue;
      const int k = rank_[ps];
      q_ = up_[ps];
      if (n - k > 0 && v_.size() == n - k) q_.tail(n - k) += v_;
      if (!unrotated_[ps]) ns_[ps].applyQOnTheLeft(q_);
      v_ = q_;
    }
    if (v_.size() == Nx) x_ = v_;
    else x_.setZero();
  }

  template <int P>
  void solveLevel() {
    ld_rows_ = 0;  // only this level's failed least-distance step may seed its dual start
    const int bound_above = bound_count_;  // rows at their bounds at x*_{p−1}
    bound_count_ = 0;
    constexpr int r = LevelType<P>::task_rows;
    constexpr int t0 = task_offset[P];
    constexpr int c0 = constraint_offset[P];
    constexpr int c = constraint_offset[P + 1];
    constexpr int own = c - c0;
    // Rows below this level's tasks (lower tasks, then all constraint rows) in W_.
    constexpr int below = total_task_rows + total_constraint_rows - (t0 + r);
    constexpr bool last = P + 1 == num_levels;
    // The rows below that this level carries into its coordinates: all of them on the cascade;
    // above the last level on the deferred path only the task rows of the levels above the
    // last (the last level forms its own rows and the constraint rows: deferredRows).
    constexpr int higher_below = std::max(task_offset[num_levels - 1] - (t0 + r), 0);
    const int carried = deferred_ && !last ? higher_below : below;
    auto& lr = result_.levels[P];
    lr = HqpLevelResult<max_active>{};
    const int n = n_;
    const int col0 = Nx - n;  // W_ columns [col0, Nx) hold the rows times Z_{p−1}
    lr.variables = n;
    var_[P] = n;
    rank_[P] = 0;
    unrotated_[P] = false;

    if (n == 0) {
      if (deferred_) {  // rows would have to be checked here: left to the cascade
        aborted_ = true;
        return;
      }
      // Nothing left to move: only check the level's own constraints at x*.
      if constexpr (own > 0) ownRowsWithoutFreedom<P>(lr);
      lr.kkt.computed = settings_.kkt_residuals;  // no variables: stationarity is empty
      finishLevel<P>(lr, -bt_.template segment<r>(t0));
      return;
    }

    if constexpr (P + 1 == num_levels && P > 0) {
      if (deferred_) deferredRows<P>(n);
    }
    // Â_p = W^½ A_p Z_{p−1} (r x n) and its null space (eq. 4).
    const auto sw = w_.template segment<r>(t0).cwiseSqrt();
    M_ = W_.block(t0, col0, r, n);
    M_.array().colwise() *= sw.array();
    const double scale =
        std::sqrt((ha_.template segment<r>(t0).array() * w_.template segment<r>(t0).array())
                      .maxCoeff());
    if constexpr (P + 1 == num_levels && c > 0 && !std::is_same_v<DualQp, detail::NoQp>) {
      if (settings_.dual_last_level && r >= n && dualLastLevel<P>(n, col0, scale, lr)) return;
      if (aborted_) return;  // the deferred path's QP failed: no second try here
    }
    if constexpr (last) {
      if (deferred_) deferredConstraintRows(n);  // the general path reads them
    }
    auto& ns = ns_[P];
    // Â_p of a level above the last depends on the task rows and Q_0 … Q_{p−1} alone, not on
    // x*: the cascade after a failed deferred attempt factors the matrix that attempt factored
    // (bit for bit on the corpus), so it keeps that decomposition.
    if (last || deferred_ || !ns_deferred_[P]) ns.compute(M_, settings_.rank_tol * scale);
    ns_deferred_[P] = deferred_ && !last;
    const int k = ns.rank();
    // Every row below (lower tasks, all constraints) into the coordinates u = Q u':
    // u' = [row-space part (k); null part (n − k)], so Z_p is the last n − k columns.
    // The last level's rows below are only its QP's constraint rows: rotated only if the
    // QP runs (the free step below needs them only times a vector).
    bool rotated = false;
    auto rotateBelow = [&] {
      if (carried > 0) {
        auto rows_below = W_.block(t0 + r, col0, carried, n);
        ns.applyQOnTheRight(rows_below);
      }
      rotated = true;
    };
    if (!last) rotateBelow();
    bool direct = false;  // the QP below runs in u, not u' (last level only)
    bool weighted = false;  // the level's residual from Aq_ (deferred path above the last)
    ns.rotatedMatrix(Aq_);  // Â_p Q, truncated to rank k
    bq_ = bt_.template segment<r>(t0);
    bq_.array() *= sw.array();
    u_.setZero(n);

    if constexpr (c == 0) {
      // No constraint anywhere up to this level: the minimum-norm least-squares step,
      // u' = [argmin ‖L y − b'‖; 0] with L = Â_p Q₁ of full column rank.
      if (k > 0) {
        ls_.compute(Aq_.leftCols(k));
        u_.head(k) = ls_.solve(bq_);
      }
      lr.status = QpStatus::Optimal;
      if (settings_.kkt_residuals) kktStationarity(lr, Aq_, bq_, u_, Aq_);  // no active row
    } else if (!last && deferred_) {
      // Deferred path: the unconstrained minimum-norm step; the last level checks every row.
      if (!unconstrainedStep<P>(k)) {
        aborted_ = true;
        return;
      }
      u_.head(k) = ys_.head(k);
      lr.status = QpStatus::Optimal;
      if (settings_.kkt_residuals) kktStationarity(lr, Aq_, bq_, u_, Aq_);  // no active row
      // Its residual from Â_p Q u' = Aq_ [y; 0] (truncation only drops columns that meet 0s
      // of u'), unweighted by W^-½ where every weight is positive: no Q u' is formed.
      weighted = (sw.array() > 0.0).all();
    } else if (std::get<P>(qps_).numActive() == 0 &&
               freeStep<P>(n, k, col0, rotated, lr)) {
      // The unconstrained minimum-norm step meets every row, or (least-distance step) some
      // unconstrained minimizer does: the nearest to 0 is the QP's optimum, with multipliers
      // 0, so the QP (and the last level's rotation) is skipped. Both are tried when the
      // level's incoming working set is empty (after either the working set is emptied), so
      // the warm state is the working set alone and a recorded instance replays exactly
      // (docs/recording.md).
      std::get<P>(qps_).resetWorkingSet();
      lr.status = QpStatus::Optimal;
      if (settings_.kkt_residuals) kktStationarity(lr, Aq_, bq_, u_, Aq_);  // no active row
    } else {
      // The last level with Â_p of full column rank (no null space left, nothing truncated)
      // poses its QP in u itself: objective Â_p, constraint rows unrotated, u' = Qᵀ u after.
      direct = last && k == n;
      if (!rotated && !direct) rotateBelow();
      auto& qp = std::get<P>(qps_);
      qp.resize(n, r, 0, c);
      if (direct) qp.A() = M_;
      else qp.A() = Aq_;
      qp.b() = bq_;
      qp.C() = W_.block(total_task_rows, col0, c, n);
      qp.lower() = lower_.head(c) - dx_.head(c);
      qp.upper() = upper_.head(c) - dx_.head(c);
      typename std::remove_reference_t<decltype(qp)>::VectorX hint;
      hint.setZero(n);  // x*_{p−1} meets every higher constraint: u = 0 is feasible for them
      const bool locked_infeasible = neutralizeLockedRows(qp, c, ownBegin(c0));
      QpStatus s = QpStatus::Infeasible;
      bool warm = settings_.warm_start;
      if constexpr (P > 0 && !last && !std::is_same_v<DualQp, detail::NoQp>) {
        if (!locked_infeasible && !deferred_ && settings_.dual_start && qp.numActive() == 0 &&
            dualStart<P>(qp, n, k, c, lr))
          warm = true;  // the working set just set
      }
      if (!locked_infeasible) {
        // u = 0 (x*_{p−1}) holds the rows the level above ended on at their bounds: the
        // QP's first working set where it starts there (docs/hqp.md, "Start rows").
        if (bound_above > 0) qp.setStartRows(bound_above, bound_row_.data(), bound_upper_.data());
        s = qp.solve(hint, warm);  // the hint is used only if feasible
        lr.iterations += qp.iterations();  // after a failed least-distance step's, the dual start's
      }
      if (deferred_ && s != QpStatus::Optimal) {  // some level above is not at its minimum
        aborted_ = true;
        return;
      }
      if constexpr (own > 0) {
        if (s == QpStatus::Infeasible) {
          lr.status = QpStatus::Infeasible;
          bool relaxed = false;
          if constexpr (LevelType<P>::slack) {
            if (slack_[P]) relaxed = relaxOwnRows<P>(qp, n, lr, hint);
          }
          if (!relaxed) {
            // Drop the level's own rows here and in every lower level (docs/hqp.md).
            lower_.segment(c0, own).setConstant(-kInf);
            upper_.segment(c0, own).setConstant(kInf);
            qp.lower().segment(c0, own).setConstant(-kInf);
            qp.upper().segment(c0, own).setConstant(kInf);
            lr.constraints_dropped = true;
            hint.setZero(n);
          }
          neutralizeLockedRows(qp, c, c0);  // own rows now hold the hint (slack) or are free
          qp.resetWorkingSet();
          const QpStatus s2 = qp.solve(hint, false);
          lr.iterations += qp.iterations();
          // The level stays reported Infeasible; a failure of the retry is reported instead.
          if (s2 != QpStatus::Optimal) lr.status = s2;
        } else {
          lr.status = s;
        }
      } else {
        lr.status = s;
      }
      if (qp.x().size() == n && qp.x().allFinite()) u_ = qp.x();
      else if (lr.status == QpStatus::Optimal) lr.status = QpStatus::NumericalFailure;
      lr.num_active = std::min(qp.numActive(), max_active);
      for (int a = 0; a < lr.num_active; ++a) {
        const std::size_t as = static_cast<std::size_t>(a);
        lr.active_row[as] = qp.activeRow(a);
        lr.active_upper[as] = qp.activeAtUpper(a);
        lr.multiplier[as] = qp.activeAtUpper(a) ? qp.multiplier(a) : -qp.multiplier(a);
      }
      // Read by the next level only; not after dropped or relaxed own rows (not Optimal).
      if (!last && lr.status == QpStatus::Optimal) {
        bound_count_ = std::min(lr.num_active, static_cast<int>(bound_row_.size()));
        std::copy_n(lr.active_row.begin(), bound_count_, bound_row_.begin());
        std::copy_n(lr.active_upper.begin(), bound_count_, bound_upper_.begin());
      }
      // The QP's own data (u in its coordinates: u' or, direct, u) and its multipliers.
      if (settings_.kkt_residuals && qp.x().size() == n)
        kktStationarity(lr, qp.A(), qp.b(), qp.x(), qp.C());
      // Did a row hold this level away from its unconstrained minimum (a multiplier above
      // rounding)? If none did at any level above the last, solve() empties their working sets.
      if (!last && settings_.defer_constraints) {  // read only by the deferred path's rule
        const double tol = 1e-9 * scale * bq_.norm();
        bool free = lr.status == QpStatus::Optimal;
        for (int a = 0; a < lr.num_active; ++a)
          free = free && std::abs(lr.multiplier[static_cast<std::size_t>(a)]) *
                                 Dnorm_(lr.active_row[static_cast<std::size_t>(a)]) <= tol;
        higher_free_ = higher_free_ && free;
      }
    }

    // x*_p = x*_{p−1} + Z_{p−1} Q u' (eq. 4): update the reduced right-hand sides of every
    // row below (in the new coordinates), and the level's own residual A_p x*_p − b_p =
    // (A_p Z_{p−1})(Q u') − (b_p − A_p x*_{p−1}) with its rows still in the old ones.
    if (direct) {  // u_ holds u = Q u'
      q_ = u_;
      ns.applyQTransposeOnTheLeft(u_);
    } else if (!weighted) {
      q_ = u_;
      ns.applyQOnTheLeft(q_);
    }
    up_[P] = u_;
    if (!last && carried > 0) {  // after the last level nobody reads bt_ or dx_
      // The carried rows: lower task rows first, then (cascade only) every constraint row.
      constexpr int task_below = below - total_constraint_rows;
      const int tasks = std::min(carried, task_below);
      tmp_.head(carried).noalias() = W_.block(t0 + r, col0, carried, n) * u_;
      if (tasks > 0) bt_.segment(t0 + r, tasks) -= tmp_.head(tasks);
      if (carried > tasks) dx_.head(carried - tasks) += tmp_.segment(tasks, carried - tasks);
    }
    Eigen::Matrix<double, r, 1> e;
    if (weighted) {
      e.noalias() = Aq_.leftCols(k) * u_.head(k);
      e = e.cwiseQuotient(sw) - bt_.template segment<r>(t0);
    } else {
      e.noalias() = W_.block(t0, col0, r, n) * q_;
      e -= bt_.template segment<r>(t0);
    }
    n_ = n - k;
    lr.rank = k;
    rank_[P] = k;
    finishLevel<P>(lr, e);
  }

  // The last level when Â_p = M_ has full column rank: min ½‖Â_p u − b̂‖² over the rows of
  // every level, a strictly convex QP in u itself (nothing is below, so no null space and no
  // rotation), solved by the dual method from the unconstrained minimizer; on the deferred
  // path that minimizer is first checked against every row in x (deferredFreeStep), and the
  // constraint rows are formed in u only if one breaks. The bounds are the ones ActiveSetQp
  // would get (neutralizeLockedRows). Returns false, having changed nothing the general path
  // reads but for forming those rows (which it needs too), if 1/‖R⁻¹‖_F ≤ √r · rank_tol · scale
  // (then NullSpace might find a rank below n; with σ_min above that bound its pivots all
  // pass, docs/hqp.md) or if the dual method ends without an optimum (e.g. infeasible own
  // rows: the general path handles them).
  template <int P>
  bool dualLastLevel(int n, int col0, double scale, HqpLevelResult<max_active>& lr) {
    constexpr int r = LevelType<P>::task_rows;
    constexpr int t0 = task_offset[P];
    constexpr int c = constraint_offset[P + 1];
    bq_ = bt_.template segment<r>(t0);
    bq_.array() *= w_.template segment<r>(t0).array().sqrt();
    const double min_sigma = std::sqrt(static_cast<double>(r)) * settings_.rank_tol * scale;
    if (!dual_.factorize(M_, bq_, r, n, min_sigma)) return false;
    // Past the rank test the general path would pose the same strictly convex QP: on the
    // deferred path a failure below means a row holds some higher level away from its minimum
    // (the cascade decides), not a reason to try the QP again.
    aborted_ = deferred_;
    const auto Cw = W_.block(total_task_rows, col0, c, n);
    auto& qp = std::get<P>(qps_);
    // The dual method's first order (any order of the violated rows is valid for it, and an
    // order that ends on nearly dependent rows, NumericalFailure, may be avoided by another):
    // on the cascade the level above's active set where it has one (its rows hold at
    // x*_{p−1}, and most of them stay active; the method takes the most violated of these rows
    // first, so their order does not matter), else the level's working set (the previous
    // tick's active set, or a recorded one). The working set is not added to the level above's
    // rows: where it is the optimum's own nearly dependent vertex (a controller's next tick on
    // an unchanged problem) the union ended NumericalFailure on 6 stress instances (203, 242:
    // ~150 µs through the order-free route), the level above's rows alone on 3
    // (docs/hqp-tuning.md, "The steady state"); on the recorded stress family the two take
    // 14.00 and 13.93 iterations.
    const auto& above = result_.levels[P > 0 ? P - 1 : 0];
    int own = 0;
    if (P > 0 && !deferred_ && above.num_active > 0) {
      own = std::min(above.num_active, static_cast<int>(prefer_.size()));
      std::copy_n(above.active_row.begin(), own, prefer_.begin());
    } else if (settings_.warm_start) {
      own = DualQp::preferredRows(qp, n, prefer_);
    }
    // The free step is tried unless the warm start holds rows (then the minimizer most likely
    // breaks one: the check would only add its products); decided by the working set alone,
    // so replays stay exact.
    if (deferred_ && own == 0 && deferredFreeStep()) {
      u_ = dual_.unconstrainedMinimizer();
      lr.iterations = 0;
      lr.num_active = 0;
    } else if (!solveDual<P>(n, col0, min_sigma, own, lr)) {
      return false;
    }
    aborted_ = false;
    lr.status = QpStatus::Optimal;
    lr.dual = true;
    if (settings_.kkt_residuals) kktStationarity(lr, M_, bq_, u_, Cw);  // Cw: active rows only
    // The level's ActiveSetQp starts from this active set if a later tick needs it.
    qp.resize(n, r, 0, c);
    qp.setWorkingSet(lr.num_active, lr.active_row.data(), lr.active_upper.data());
    up_[P] = u_;
    unrotated_[P] = true;
    const Eigen::Matrix<double, r, 1> e =
        W_.block(t0, col0, r, n) * u_ - bt_.template segment<r>(t0);
    n_ = 0;
    lr.rank = n;
    rank_[P] = n;
    finishLevel<P>(lr, e);
    return true;
  }

  // dualLastLevel's QP over every constraint row: bounds, then the dual method in the order
  // dualLastLevel put in prefer_[0..own), a second on the deferred path, the order-free route on
  // the cascade. On success u_ and the active set are in lr.
  template <int P>
  bool solveDual(int n, int col0, double min_sigma, int own, HqpLevelResult<max_active>& lr) {
    constexpr int r = LevelType<P>::task_rows;
    constexpr int c0 = constraint_offset[P];
    constexpr int c = constraint_offset[P + 1];
    if (deferred_) deferredConstraintRows(n);
    const auto Cw = W_.block(total_task_rows, col0, c, n);
    cnorm_.head(c) = Cw.rowwise().squaredNorm();
    const int own_begin = ownBegin(c0);
    for (int i = 0; i < c; ++i) {
      // An own row with an empty interval: infeasible, the general path applies the policy.
      if (i >= own_begin &&
          (lower_(i) - upper_(i)) / rowScale(Dnorm_(i)) > settings_.qp.feasibility_tol)
        return false;
      if (!dualRowBounds(i, own_begin, 0.0, cnorm_(i), i >= own_begin)) return false;
    }
    // On the deferred path the method's own order (most violated first) is the second; on the
    // cascade a failed first order goes to routes that depend on no order
    // (DualActiveSetQp::solveOrderFree), before the general path's ActiveSetQp, which can end
    // on such rows too: there another order met the same rows on every stress instance seen
    // (docs/hqp-tuning.md, "The stress tail by phase").
    QpStatus s = dual_.solve(Cw, dlo_, dup_, c, settings_.qp, prefer_.data(), own);
    if (s == QpStatus::NumericalFailure && own > 0 && deferred_ &&
        dual_.factorize(M_, bq_, r, n, min_sigma))
      s = dual_.solve(Cw, dlo_, dup_, c, settings_.qp);
    if ((s == QpStatus::NumericalFailure || s == QpStatus::IterationLimit) && !deferred_)
      s = dual_.solveOrderFree(Cw, dlo_, dup_, c, settings_.qp);
    if (s != QpStatus::Optimal) {
      // The deferred last level's rows conflict in Z_{p−1}, the null space of every higher
      // task: kept for the cascade's least-distance steps (conflictShown).
      if (deferred_ && s == QpStatus::Infeasible) conflict_ = dual_.certificate();
      return false;
    }
    u_ = dual_.x();
    lr.iterations = dual_.iterations();
    lr.num_active = std::min(dual_.numActive(), max_active);
    for (int a = 0; a < lr.num_active; ++a) {
      const std::size_t as = static_cast<std::size_t>(a);
      lr.active_row[as] = dual_.activeRow(a);
      lr.active_upper[as] = dual_.activeAtUpper(a);
      lr.multiplier[as] = dual_.activeAtUpper(a) ? dual_.multiplier(a) : -dual_.multiplier(a);
    }
    return true;
  }

  // The deferred path's last level: its task rows and every constraint row times Z_{p−1}
  // into W_, and their reduced right-hand sides b − A x*_{p−1}, D x*_{p−1}. The levels above
  // rotated only their own task rows; Z_{p−1} = Q_0 E_0 ⋯ Q_{p−1} E_{p−1} (E = [0; I], the
  // null-space columns) is formed once on its n columns, from the right, and multiplied in:
  // about half the flops of rotating these rows at every level (docs/hqp.md).
  template <int P>
  void deferredRows(int n) {
    constexpr int r = LevelType<P>::task_rows;
    constexpr int t0 = task_offset[P];
    constexpr int c = total_constraint_rows;
    // Zᵀ = E_{p−1}ᵀ Q_{p−1}ᵀ ⋯ E_0ᵀ Q_0ᵀ from the left: [0 I] in the last var_[q] columns,
    // times Q_qᵀ (n rows instead of every row below, 8 at a time). Row n carries x*_{p−1}ᵀ =
    // ((u'_{p−1}ᵀ Q_{p−1}ᵀ E_{p−2}ᵀ + u'_{p−2}ᵀ) Q_{p−2}ᵀ ⋯ + u'_0ᵀ) Q_0ᵀ through the same
    // passes (reconstructX's sum, one more row of the strips instead of a vector per reflector).
    Zt_.setZero(n + 1, Nx);
    Zt_.topRightCorner(n, n).setIdentity();
    for (int q = P - 1; q >= 0; --q) {
      const std::size_t qs = static_cast<std::size_t>(q);
      const int m = var_[qs];
      if (m == 0) continue;
      Zt_.row(n).segment(Nx - m, m) += up_[qs].transpose();
      auto cols = Zt_.block(0, Nx - m, n + 1, m);
      ns_[qs].applyQTransposeOnTheRight(cols);
    }
    // A_p Z into the last n columns of its rows in W_ (begin() copied only the higher task
    // rows); D Z only if the unconstrained minimizer breaks a row (deferredConstraintRows).
    {
      constexpr int rows = total_task_rows - t0;
      detail::multiplyRowStrips<Nx>(A_.template middleRows<rows>(t0),
                                    W_.template middleRows<rows>(t0), rows, Nx, Zt_, n);
    }
    x_ = Zt_.row(n).transpose();  // x*_{p−1}
    xd_ = x_;
    bt_.template segment<r>(t0) = b_.template segment<r>(t0);
    bt_.template segment<r>(t0).noalias() -= A_.template middleRows<r>(t0) * x_;
    constraint_rows_pending_ = c > 0;
  }

  // The deferred path's constraint rows D Z_{p−1} (in place, as deferredRows) and D x*_{p−1}.
  void deferredConstraintRows(int n) {
    constexpr int c = total_constraint_rows;
    if constexpr (c > 0) {
      if (!constraint_rows_pending_) return;
      constraint_rows_pending_ = false;
      detail::multiplyRowStrips<Nx>(D_.template topRows<c>(),
                                    W_.template middleRows<c>(total_task_rows), c, Nx, Zt_, n);
      dx_.template head<c>().noalias() = D_.template topRows<c>() * xd_;
    }
  }

  // The deferred path's last level at the unconstrained minimizer u0 of its objective: if
  // x = x*_{p−1} + Z_{p−1} u0 meets every bound (exactly, without the QP's tolerance), the
  // dual method would add no row (it adds one only past feasibility_tol) and end at u0, so
  // the constraint rows are not formed in u (most warm ticks: no row active at the last level).
  bool deferredFreeStep() {
    constexpr int c = total_constraint_rows;
    deferredX(dual_.unconstrainedMinimizer());
    if constexpr (c > 0) {
      kkt_d_.template head<c>().noalias() = D_.template topRows<c>() * x_;
      for (int i = 0; i < c; ++i)
        if (!(lower_(i) <= kkt_d_(i) && kkt_d_(i) <= upper_(i))) return false;
    }
    return true;
  }

  // The deferred path's x = x*_{p−1} + Z_{p−1} u of the last level p (deferredRows' Zᵀ and
  // x*_{p−1}): one product instead of the chain of every level's reflectors.
  void deferredX() {
    constexpr std::size_t L = num_levels - 1;
    q_ = up_[L];
    if (!unrotated_[L]) ns_[L].applyQOnTheLeft(q_);
    deferredX(q_);
  }
  template <class Vec>
  void deferredX(const Vec& u) {
    x_ = xd_;
    x_.noalias() += Zt_.topRows(u.size()).transpose() * u;
  }

  // e = A_p x*_p − b_p.
  template <int P, class Vec>
  void finishLevel(HqpLevelResult<max_active>& lr, const Vec& e) {
    constexpr int r = LevelType<P>::task_rows;
    constexpr int t0 = task_offset[P];
    lr.null_dim = n_;
    lr.residual = e.squaredNorm();
    lr.objective = (e.array().square() * w_.template segment<r>(t0).array()).sum();
    noteStatus(P, lr.status);
    // dx_ = D x*_p here, except after the last level (not updated): see lastLevelPrimal().
    // (On the deferred path dx_ is not kept above the last level: lastLevelPrimal checks.)
    if (lr.kkt.computed && P + 1 < num_levels && !deferred_)
      kktRows(lr, constraint_offset[P + 1], dx_);
  }

  // Certificate, stationarity (HqpKkt): s = Aᵀ(A u − b) + Σ_a λ_a C_aᵀ with the level's QP
  // objective (A, b) and constraint rows C in its variables u. O((r + active rows) · n).
  template <class MatA, class VecB, class VecU, class MatC>
  void kktStationarity(HqpLevelResult<max_active>& lr, const MatA& A, const VecB& b,
                       const VecU& u, const MatC& C) {
    kkt_e_.noalias() = A * u;
    kkt_e_ -= b;
    kkt_s_.noalias() = A.transpose() * kkt_e_;
    const double a_norm = A.norm();
    double scale = a_norm * kkt_e_.norm();
    lr.kkt.gradient_scale = a_norm * ((kkt_e_ + b).norm() + b.norm());
    for (int a = 0; a < lr.num_active; ++a) {
      const double l = lr.multiplier[static_cast<std::size_t>(a)];
      const auto c = C.row(lr.active_row[static_cast<std::size_t>(a)]);
      kkt_s_ += l * c.transpose();
      scale += std::abs(l) * c.norm();
    }
    lr.kkt.computed = true;
    lr.kkt.stationarity = kkt_s_.size() > 0 ? kkt_s_.cwiseAbs().maxCoeff() : 0.0;
    lr.kkt.stationarity_scale = scale;
  }

  // Certificate, rows (HqpKkt): primal feasibility of the rows [0, c) at d = D x*_p, the sign
  // of each multiplier (dual feasibility) and complementarity, against the bounds the level
  // solved with (its own rows dropped or relaxed if it was infeasible). O(c + active rows).
  template <class Vec>
  void kktRows(HqpLevelResult<max_active>& lr, int c, const Vec& d) {
    double primal = 0.0, dual = 0.0, comp = 0.0;
    for (int i = 0; i < c; ++i) {
      const double v = std::max(lower_(i) - d(i), d(i) - upper_(i));
      if (v > 0.0) primal = std::max(primal, v / rowScale(Dnorm_(i)));
    }
    for (int a = 0; a < lr.num_active; ++a) {
      const std::size_t as = static_cast<std::size_t>(a);
      const int j = lr.active_row[as];
      const double l = lr.multiplier[as];
      const bool up = lr.active_upper[as];
      dual = std::max(dual, (up ? -l : l) * rowScale(Dnorm_(j)));  // λ ≥ 0 at upper, ≤ 0 at lower
      comp = std::max(comp, std::abs(l * (d(j) - (up ? upper_(j) : lower_(j)))));
    }
    lr.kkt.primal = primal;
    lr.kkt.dual = dual;
    lr.kkt.complementarity = comp;
  }

  // The last level's rows at the final x (= x*_p of the last level; dx_ is not updated there).
  // On the deferred path the levels above are checked there too: their x*_p met no row, the
  // final x (the same residuals, every row held) is their certified optimum.
  void lastLevelPrimal() {
    constexpr int c = total_constraint_rows;
    auto& lr = result_.levels[static_cast<std::size_t>(num_levels - 1)];
    if constexpr (c > 0) {
      if (!lr.kkt.computed) return;
      kkt_d_.template head<c>().noalias() = D_.template topRows<c>() * x_;
      kktRows(lr, c, kkt_d_);
      for (int p = 0; result_.deferred && p + 1 < num_levels; ++p) {
        auto& lp = result_.levels[static_cast<std::size_t>(p)];
        if (lp.kkt.computed) kktRows(lp, constraint_offset[static_cast<std::size_t>(p) + 1], kkt_d_);
      }
    }
  }

  // The level's unconstrained minimum-norm step u' = [y; 0], y = argmin ‖L y − b'‖ with
  // L = Â_p Q₁ (full column rank k), if it meets every constraint row up to k ≤ p as the QP
  // would check it (rows scaled to unit norm, feasibility_tol; higher rows' bounds widened to
  // contain 0 as in neutralizeLockedRows). A feasible unconstrained minimizer is the
  // constrained one, and with an empty working set the QP returns exactly this point. If it
  // breaks a row, the least-distance step is tried. Sets u_ and returns true, or returns false
  // (u_ untouched) and the QP decides.
  template <int P>
  bool freeStep(int n, int k, int col0, bool rotated, HqpLevelResult<max_active>& lr) {
    constexpr int c0 = constraint_offset[P];
    constexpr int c = constraint_offset[P + 1];
    constexpr int rows0 = total_task_rows;  // first constraint row in W_
    if (!unconstrainedStep<P>(k)) return false;
    // Constraint rows times u': rotated rows see [y; 0]; unrotated ones Q [y; 0].
    auto Cw = W_.block(rows0, col0, c, n);
    if (rotated) {
      if (k > 0) tmp_.head(c).noalias() = Cw.leftCols(k) * ys_.head(k);
      else tmp_.head(c).setZero();
    } else {
      q_.setZero(n);
      q_.head(k) = ys_.head(k);
      ns_[P].applyQOnTheLeft(q_);
      tmp_.head(c).noalias() = Cw * q_;
    }
    const double tol2 = settings_.qp.feasibility_tol * settings_.qp.feasibility_tol;
    for (int i = 0; i < c; ++i) {
      double lo = lower_(i) - dx_(i), up = upper_(i) - dx_(i);
      widenHigherRow(i, ownBegin(c0), lo, up);
      const double v = tmp_(i);
      const double viol = std::max(lo - v, v - up);
      // The row's norm only where a bound is crossed (most rows are strictly inside).
      if (viol > 0.0 && viol * viol > tol2 * Cw.row(i).squaredNorm())
        return leastDistanceStep<P>(n, k, col0, lr);
    }
    u_.setZero(n);
    u_.head(k) = ys_.head(k);
    return true;
  }

  // After freeStep<P> found that u' = [y; 0] breaks a row (ys_ = y, tmp_ = C₁ y): the minimum-norm
  // point of the level's unconstrained minimizers {[y; v]} that meets every row of levels ≤ p,
  //   min ½‖v‖²  s.t.  lower − dx − C₁ y ≤ C₂ v ≤ upper − dx − C₁ y   (C = [C₁ C₂] rotated),
  // by the dual method from v = 0 (HqpSettings::least_distance_step). A row with no part in
  // v (locked: the higher levels fix it) must already hold. Above the last level only (its
  // rows below are rotated); not on the deferred path (its levels check no row). On success
  // u_ = [y; v], lr.iterations = the dual method's; false (u_ untouched, lr.iterations the
  // try's) if no such point exists or the method does not end Optimal: the level's QP decides.
  template <int P>
  bool leastDistanceStep(int n, int k, int col0, HqpLevelResult<max_active>& lr) {
    if constexpr (P + 1 == num_levels || std::is_same_v<DualQp, detail::NoQp>) {
      return false;
    } else {
      constexpr int c0 = constraint_offset[P];
      constexpr int c = constraint_offset[P + 1];
      const int m = n - k;
      if (!settings_.least_distance_step || deferred_ || m <= 0) return false;
      const auto Cw = W_.block(total_task_rows, col0, c, n);
      const auto Cv = Cw.middleCols(k, m);
      for (int i = 0; i < c; ++i)
        if (!dualRowBounds(i, ownBegin(c0), tmp_(i), Cv.row(i).squaredNorm(), true)) return false;
      if (conflictShown(Cv, c, m)) return false;
      if (!dual_.factorizeIdentity(m)) return false;
      const QpStatus s = dual_.solve(Cv, dlo_, dup_, c, settings_.qp);
      lr.iterations = dual_.iterations();
      if (s != QpStatus::Optimal) {
        // The dual start would retrace this path before it moves the task's part: it adds
        // these rows first (dualStart).
        ld_rows_ = std::min(dual_.numActive(), static_cast<int>(prefer_.size()));
        for (int a = 0; a < ld_rows_; ++a)
          prefer_[static_cast<std::size_t>(a)] = dual_.activeRow(a);
        return false;
      }
      u_.setZero(n);
      u_.head(k) = ys_.head(k);
      u_.segment(k, m) = dual_.x();
      lr.least_distance = true;
      bound_count_ = std::min(dual_.numActive(), static_cast<int>(bound_row_.size()));
      for (int a = 0; a < bound_count_; ++a) {
        bound_row_[static_cast<std::size_t>(a)] = dual_.activeRow(a);
        bound_upper_[static_cast<std::size_t>(a)] = dual_.activeAtUpper(a);
      }
      return true;
    }
  }

  // Would the least-distance step on the rows Cv (c rows, m columns; bounds dlo_/dup_) fail?
  // Yes if the certificate of the deferred attempt's failure proves them in conflict: that
  // attempt's last level saw every constraint row in the null space of all higher tasks, which
  // is level p's v-space where p is the level above the last (on the stress family's cascades
  // it saves level 3's failed step, 2.2 iterations per instance; docs/hqp.md).
  template <class MatV>
  bool conflictShown(const MatV& Cv, int c, int m) {
    if (conflict_.count == 0) return false;
    const auto rinv = [&](int j) { return DualQp::inverseRowNorm(Cv.row(j)); };
    return conflict_.proves(Cv, dlo_, dup_, c, m, settings_.qp.feasibility_tol, rinv, conflict_z_);
  }

  // The dual start (HqpSettings::dual_start) for level P's QP (its data set, hint u = 0): if
  // u = 0 breaks a row, min ½‖Â Q₁ y − b̂‖² + ½δ‖v‖² over u' = [y; v] s.t. the QP's rows, by the
  // dual method from its unconstrained minimizer; its active rows become the QP's working set.
  // √δ = 1e-4 ‖Â‖_F: cond of the stacked objective ~1e4 (the dual method's errors grow with its
  // square), and small enough that its active set is the level's on the measured instances.
  // After a failed least-distance step its active rows are added first (on the stress family's
  // level 2, 25–37 iterations become 17–27). True if the working set was set (lr.iterations
  // and lr.dual_start record the try).
  template <int P, class Qp>
  bool dualStart(Qp& qp, int n, int k, int c, HqpLevelResult<max_active>& lr) {
    constexpr int r = LevelType<P>::task_rows;
    const int from_ld = ld_rows_;
    ld_rows_ = 0;
    const double tol = settings_.qp.feasibility_tol;
    bool breaks = false;  // the QP's own test, on rows scaled to unit norm (cnorm_: their ‖·‖²)
    for (int i = 0; i < c && !breaks; ++i) {
      const double sc = std::sqrt(cnorm_(i));
      breaks = qp.lower()(i) > tol * sc || qp.upper()(i) < -tol * sc;
    }
    if (!breaks) return false;
    // qp.A() = Â Q with columns k.. zero (truncated to rank k): its first k columns are Â Q₁.
    const double an = qp.A().norm();
    const double sd = 1e-4 * (an > 0.0 ? an : 1.0);
    using Diagonal = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Nx, 1>;
    if (!dual_.factorizeBlockDiagonal(qp.A(), qp.b(), r, k, Diagonal::Constant(n - k, sd), 0.0))
      return false;
    const QpStatus s =
        dual_.solve(qp.C(), qp.lower(), qp.upper(), c, settings_.qp, prefer_.data(), from_ld);
    lr.iterations += dual_.iterations();
    if (s != QpStatus::Optimal || dual_.numActive() == 0) return false;
    const int cnt = std::min(dual_.numActive(), max_active);
    for (int a = 0; a < cnt; ++a) {
      start_row_[static_cast<std::size_t>(a)] = dual_.activeRow(a);
      start_upper_[static_cast<std::size_t>(a)] = dual_.activeAtUpper(a);
    }
    qp.setWorkingSet(cnt, start_row_.data(), start_upper_.data());
    lr.dual_start = true;
    return true;
  }

  // ys_(0:k) = argmin ‖L y − b'‖, L = Â_p Q₁ of full column rank k (NullSpace): the row-space
  // part of the level's unconstrained minimum-norm step. False if the solve failed.
  template <int P>
  bool unconstrainedStep(int k) {
    constexpr int r = LevelType<P>::task_rows;
    if (k == r) {
      // Â_p Q₁ = Π R₁ᵀ is square: forward substitution, row Π(l) gives y_l (NullSpace).
      const auto& R = ns_[P].matrixQR();
      for (int l = 0; l < k; ++l)
        ys_(l) = (bq_(ns_[P].permutation(l)) - R.col(l).head(l).dot(ys_.head(l))) / R(l, l);
    } else if (k > 0) {
      Ls_ = Aq_.leftCols(k);
      bs_ = bq_;
      if (detail::qpMinNormLeastSquares(Ls_, r, k, bs_, ys_, 0.0, ls_ws_) != k) return false;
    }
    return std::isfinite(ys_.head(k).sum());
  }

  // Higher rows: their shifted bounds are widened to contain 0 (see below).
  // Rows whose value the higher levels have locked (‖D_i Z_{p−1}‖ ≤ rank_tol ‖D_i‖) cannot
  // move any more: they are checked here at x*_{p−1} and handed to the QP as exact zero
  // rows without bounds, so the QP never sees a rounding-noise row. Returns true if one of
  // the rows from `own_begin` on is violated (the level is then infeasible).
  template <class Qp>
  bool neutralizeLockedRows(Qp& qp, int c, int own_begin) {
    bool infeasible = false;
    cnorm_.head(c) = qp.C().rowwise().squaredNorm();  // all rows at once (vectorized)
    for (int i = 0; i < c; ++i) {
      widenHigherRow(i, own_begin, qp.lower()(i), qp.upper()(i));
      if (!lockedRow(i, cnorm_(i))) continue;
      const bool ok = lockedRowHolds(i, qp.lower()(i), qp.upper()(i));
      qp.C().row(i).setZero();
      if (ok || i < own_begin) {
        qp.lower()(i) = -kInf;
        qp.upper()(i) = kInf;
      } else {
        infeasible = true;
      }
    }
    return infeasible;
  }

  // The rules every consumer of a level's shifted bounds (lower − D x*_{p−1}, upper − D x*_{p−1})
  // shares (neutralizeLockedRows, freeStep, dualLastLevel). A higher row (i < own_begin) is
  // widened to contain 0: x*_{p−1} met it up to the QP's tolerance, and a rounding-size empty
  // interval at a degenerate vertex would stall the QP.
  static void widenHigherRow(int i, int own_begin, double& lo, double& up) {
    if (i >= own_begin) return;
    lo = std::min(lo, 0.0);
    up = std::max(up, 0.0);
  }
  // Row i's bounds for a dual solve (dlo_, dup_): the QP's (shifted by D x*_{p−1}, higher rows
  // widened to contain 0), minus shift (the row's value at the dual method's origin); a
  // locked row (reduced squared norm rn2) is freed, and if must_hold it has to hold there:
  // false if it does not.
  bool dualRowBounds(int i, int own_begin, double shift, double rn2, bool must_hold) {
    double lo = lower_(i) - dx_(i), up = upper_(i) - dx_(i);
    widenHigherRow(i, own_begin, lo, up);
    lo -= shift;
    up -= shift;
    if (lockedRow(i, rn2)) {
      if (must_hold && !lockedRowHolds(i, lo, up)) return false;
      lo = -kInf;
      up = kInf;
    }
    dlo_(i) = lo;
    dup_(i) = up;
    return true;
  }
  // Row i is locked by the higher levels if its reduced row (squared norm rn2) is ≤ rank_tol ‖D_i‖.
  bool lockedRow(int i, double rn2) const { return std::sqrt(rn2) <= settings_.rank_tol * Dnorm_(i); }
  // A locked row holds at x*_{p−1} if its shifted bounds contain 0 up to the QP's tolerance.
  bool lockedRowHolds(int i, double lo, double up) const {
    const double sc = rowScale(Dnorm_(i)), tol = settings_.qp.feasibility_tol;
    return lo / sc <= tol && -up / sc <= tol;
  }

  // Own bound violation Σ over rows of max(lower − d, d − upper, 0)² for d = D_own x.
  template <int P, class Vec>
  double ownViolation(const Vec& d) const {
    constexpr int c0 = constraint_offset[P];
    constexpr int own = LevelType<P>::constraint_rows;
    double v = 0.0;
    for (int i = 0; i < own; ++i) {
      const double e = std::max(0.0, std::max(lower_(c0 + i) - d(i), d(i) - upper_(c0 + i)));
      v += e * e;
    }
    return v;
  }

  // Level with no freedom left: its own rows either hold at x* or are infeasible.
  template <int P>
  void ownRowsWithoutFreedom(HqpLevelResult<max_active>& lr) {
    constexpr int c0 = constraint_offset[P];
    constexpr int own = LevelType<P>::constraint_rows;
    const Eigen::Matrix<double, own, 1> d = dx_.template segment<own>(c0);  // D_own x*
    bool feasible = true;
    for (int i = 0; i < own; ++i) {
      const double s = rowScale(D_.row(c0 + i).norm());
      if ((lower_(c0 + i) - d(i)) / s > settings_.qp.feasibility_tol ||
          (d(i) - upper_(c0 + i)) / s > settings_.qp.feasibility_tol)
        feasible = false;
    }
    if (feasible) return;
    lr.status = QpStatus::Infeasible;
    if (slack_[P]) {
      lr.violation = ownViolation<P>(d);
      lr.slack_used = true;
      for (int i = 0; i < own; ++i) {
        lower_(c0 + i) = std::min(lower_(c0 + i), d(i));
        upper_(c0 + i) = std::max(upper_(c0 + i), d(i));
      }
    } else {
      lower_.segment(c0, own).setConstant(-kInf);
      upper_.segment(c0, own).setConstant(kInf);
      lr.constraints_dropped = true;
    }
  }

  // Slack option: first the least-squares violation of the level's own rows subject to all
  // higher constraints, min ‖D_own x − w‖² s.t. lower_own ≤ w ≤ upper_own (w: the clamped
  // rows); then the own rows are relaxed to contain d* = D_own x_slack, which leaves exactly
  // the minimal-violation points feasible (docs/hqp.md). Higher constraints get no slack.
  template <int P, class Qp, class Hint>
  bool relaxOwnRows(Qp& qp, int n, HqpLevelResult<max_active>& lr, Hint& hint) {
    if constexpr (std::is_same_v<SlackQp, detail::NoQp>) {
      return false;
    } else {
      constexpr int c0 = constraint_offset[P];
      constexpr int own = LevelType<P>::constraint_rows;
      constexpr int c = c0 + own;
      auto& sq = slack_qp_;
      sq.resize(n + own, own, 0, c);
      sq.A().setZero();
      sq.A().leftCols(n) = qp.C().middleRows(c0, own);
      sq.A().rightCols(own).diagonal().setConstant(-1.0);
      sq.b() = -dx_.segment(c0, own);
      sq.C().setZero();
      if (c0 > 0) sq.C().topLeftCorner(c0, n) = qp.C().topRows(c0);
      sq.C().bottomRightCorner(own, own).diagonal().setOnes();
      if (c0 > 0) {
        sq.lower().head(c0) = qp.lower().head(c0);
        sq.upper().head(c0) = qp.upper().head(c0);
      }
      sq.lower().tail(own) = lower_.segment(c0, own);
      sq.upper().tail(own) = upper_.segment(c0, own);
      typename SlackQp::VectorX start;
      start.setZero(n + own);
      for (int i = 0; i < own; ++i)
        start(n + i) = std::min(std::max(dx_(c0 + i), lower_(c0 + i)), upper_(c0 + i));
      const QpStatus s = sq.solve(start, false);
      lr.iterations += sq.iterations();
      if (s != QpStatus::Optimal || !sq.x().allFinite()) return false;
      hint = sq.x().head(n);
      const Eigen::Matrix<double, own, 1> d =
          dx_.template segment<own>(c0) + qp.C().middleRows(c0, own) * hint;
      double v = 0.0;
      for (int i = 0; i < own; ++i) {
        const double e = std::max(0.0, std::max(lower_(c0 + i) - d(i), d(i) - upper_(c0 + i)));
        v += e * e;
        lower_(c0 + i) = std::min(lower_(c0 + i), d(i));
        upper_(c0 + i) = std::max(upper_(c0 + i), d(i));
      }
      qp.lower().segment(c0, own) = lower_.segment(c0, own) - dx_.segment(c0, own);
      qp.upper().segment(c0, own) = upper_.segment(c0, own) - dx_.segment(c0, own);
      lr.violation = v;
      lr.slack_used = true;
      return true;
    }
  }

  HqpSettings settings_;
  std::tuple<Levels...> levels_;
  QpTuple qps_;
  SlackQp slack_qp_;
  DualQp dual_;
  // The dual start's working set.
  std::array<int, max_active> start_row_{};
  std::array<bool, max_active> start_upper_{};
  VectorC dlo_ = VectorC::Zero(), dup_ = VectorC::Zero();  // its bounds
  FarkasCertificate<Nx + 1> conflict_;  // the deferred attempt's (conflictShown)
  Eigen::Matrix<double, Nx, 1> conflict_z_;  // its scratch
  int ld_rows_ = 0;  // this level's failed least-distance step's active rows, first in prefer_
  // Rows a dual solve adds first: its warm start (at most Nx) or the level above's active rows.
  std::array<int, std::max(Nx, max_active)> prefer_{};
  // Rows at their bounds at x*_p of the level last solved (its QP's active set or the
  // least-distance step's): the next level's QP starts from them at u = 0.
  std::array<int, max_active> bound_row_{};
  std::array<bool, max_active> bound_upper_{};
  int bound_count_ = 0;
  LeastSquares ls_;
  std::array<NullSpace<capacity(max_task_rows), Nx>, sizeof...(Levels)> ns_{};  // per level: Q_p
  std::array<bool, sizeof...(Levels)> ns_deferred_{};  // ns_[p] from this solve's deferred attempt
  std::array<bool, sizeof...(Levels)> slack_{};
  static constexpr std::array<bool, sizeof...(Levels)> slack_capable_{
      (Levels::slack && Levels::constraint_rows > 0)...};

  // Stacked data of all levels, copied from the tasks/constraints at the start of solve().
  Eigen::Matrix<double, capacity(total_task_rows), Nx> A_ = decltype(A_)::Zero();
  Eigen::Matrix<double, capacity(total_task_rows), 1> b_ = decltype(b_)::Zero();
  Eigen::Matrix<double, capacity(total_task_rows), 1> w_ = decltype(w_)::Ones();
  Eigen::Matrix<double, capacity(total_constraint_rows), Nx> D_ = decltype(D_)::Zero();
  VectorC lower_ = VectorC::Constant(-kInf);
  VectorC upper_ = VectorC::Constant(kInf);
  VectorC dx_ = VectorC::Zero();  // D x*_{p−1} (all constraint rows)
  // All task rows, then all constraint rows, times Z_{p−1} (columns [Nx − n_p, Nx)).
  Eigen::Matrix<double, capacity(total_task_rows + total_constraint_rows), Nx> W_ =
      decltype(W_)::Zero();
  Eigen::Matrix<double, capacity(total_task_rows), 1> bt_ = decltype(bt_)::Zero();  // b − A x*
  Eigen::Matrix<double, capacity(total_task_rows + total_constraint_rows), 1> tmp_ =
      decltype(tmp_)::Zero();
  VectorC Dnorm_ = VectorC::Zero();  // row norms of D
  // A x − b (checkHealth) and the squared row norms of A (every level's rank scale too).
  Eigen::Matrix<double, capacity(total_task_rows), 1> he_ = decltype(he_)::Zero(), ha_ = he_;
  VectorC cnorm_ = VectorC::Zero();  // squared row norms of a level's reduced constraint rows

  // Cascade state and scratch.
  VectorX x_ = VectorX::Zero();  // x*_p
  int n_ = Nx;                   // columns of Z_p
  std::array<VectorU, sizeof...(Levels)> up_{};  // u'_p of every level
  std::array<int, sizeof...(Levels)> var_{}, rank_{};  // n and k of every level
  std::array<bool, sizeof...(Levels)> unrotated_{};    // u'_p = u_p (dual path: no Q_p)
  VectorU q_, v_;                // Q u' / reconstruction scratch
  Eigen::Matrix<double, Eigen::Dynamic, Nx, 0, Nx + 1, Nx> Zt_;  // Z_{p−1}ᵀ; x*_{p−1}ᵀ below
  VectorX xd_ = VectorX::Zero();  // x*_{p−1} there
  MatrixM M_;                    // Â_p
  MatrixM Aq_;                   // Â_p Q (truncated)
  VectorM bq_;                   // W^½ (b_p − A_p x*_{p−1})
  VectorU u_;                    // u' of the current level
  MatrixM Ls_;                   // Â_p Q₁ for the free step (overwritten by its QR)
  VectorM bs_;                   // its right-hand side (overwritten)
  Eigen::Matrix<double, Nx, 1> ys_ = Eigen::Matrix<double, Nx, 1>::Zero();  // its solution
  detail::QpMinNormWorkspace<capacity(max_task_rows), Nx> ls_ws_;
  Result result_{};
  bool deferred_ = false;  // solving on the deferred path (HqpSettings::defer_constraints)
  bool aborted_ = false;   // the deferred path failed; the cascade runs
  bool constraint_rows_pending_ = false;  // deferred: D Z_{p−1} not yet formed (deferredRows)
  bool higher_free_ = true;  // the cascade: no row held a level above the last so far
  VectorM kkt_e_;                // certificate scratch: A u − b
  VectorU kkt_s_;                // its stationarity vector
  VectorC kkt_d_ = VectorC::Zero();  // D x at the last level
  // Budget bookkeeping (HqpSettings::budget_us / budget_iterations).
  std::chrono::steady_clock::time_point solve_start_{};
  int iterations_used_ = 0;
  std::array<double, sizeof...(Levels)> last_time_us_{};
  std::array<int, sizeof...(Levels)> last_iterations_{};
};

}  // namespace hqp
