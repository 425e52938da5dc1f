// hqp_corpus: the HqpWbc instance corpus (docs/benchmarks.md, "Instance corpus").
//   hqp_corpus generate --seeds bench/data/corpus.txt --scenarios DIR --out DIR
//       DIR/walker3_scenarios.hqprec: the sim_demo recordings of DIR/<scenario>.hqprec, in
//       seed-list order; DIR/stress.hqprec and DIR/degenerate.hqprec: instances derived from
//       them by the seeded transformations of the list. --base FILE instead of --scenarios
//       derives from one recording (the checked-in one, for the ctest).
//   hqp_corpus check DIR [--max K] [--verbose]
//       exactness: every instance warm and cold, every level Optimal, warm x* = cold x* = the
//       stored x* (or the same level objectives), the level objectives against the peer cascade
//       (peer_cascade.hpp). Exit 1 on a mismatch.
//   hqp_corpus show FILE K
//       one instance per level: warm, cold and the peer (objective, status, iterations).
//   hqp_corpus dump FILE OUT.json
//       every instance's rows and bounds (±inf as null) with the warm solve's x and statuses,
//       for an independent check of each level (tools/hqp_oracle.py).
//   hqp_corpus reformulate DIR OUT [--seed S]
//       the families in DIR written as another formulation of the same hierarchies: variables
//       in a random order, constraint rows and task rows rescaled (weights compensating). The
//       optima are the same up to the permutation, only the rounding differs; `check OUT`
//       then tests that the answers do not depend on the bits the solver was tuned on.
// Deterministic: the random numbers come from std::mt19937_64 through our own uniform and
// normal transforms (the standard distributions differ between standard libraries).
// The shape is Walker3's balance hierarchy (Table I), as for hqp_replay.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "hqp/problem_file.hpp"
#include "hqp/problem_instance.hpp"
#include "peer_cascade.hpp"
#include "tasks/balance_hierarchy.hpp"
#include "walker3_model.hpp"

namespace {

using Wbc = hqp::tasks::StackedHqpOf<hqp::tasks::BalanceHierarchy, hqp::tasks::ContactLayout<walker3::Robot, 2, 6>>;
using Instance = hqp::ProblemInstance<Wbc>;
constexpr int NX = Wbc::nx, L = Wbc::num_levels, T = Wbc::total_task_rows, C = Wbc::total_constraint_rows;
static_assert(NX == 30 && L == 4 && T == 36 && C == 30, "the corpus is Walker3's Table I shape");
// Walker3's x = [q̈ (18); F (12)], two flat contacts of 6 rows each (balance_hierarchy.hpp).
constexpr int kForce0 = 18, kContactDim = 6;
constexpr int kForceTaskRow = 3;  // level 4: torso posture (3), then the contact forces
using Peer = hqp::bench::PeerCascade<NX, L, Wbc::max_task_rows, C>;

const char* const kFamilies[] = {"walker3_scenarios", "stress", "degenerate"};

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}
  double uniform() { return static_cast<double>(g_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double normal() {  // Box-Muller
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * v);
  }
  int below(int k) { return std::min(k - 1, static_cast<int>(uniform() * k)); }

 private:
  std::mt19937_64 g_;
};

struct SeedLine {
  std::string family;
  std::string name;  // scenario name
  std::map<std::string, std::string> kv;
  double num(const std::string& k, double def) const {
    const auto it = kv.find(k);
    return it == kv.end() ? def : std::stod(it->second);
  }
  std::string str(const std::string& k) const {
    const auto it = kv.find(k);
    return it == kv.end() ? "" : it->second;
  }
};

std::vector<SeedLine> readSeeds(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<SeedLine> out;
  std::string line;
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream s(line);
    SeedLine l;
    if (!(s >> l.family)) continue;
    std::string tok;
    while (s >> tok) {
      const auto eq = tok.find('=');
      if (eq == std::string::npos) l.name = tok;
      else l.kv[tok.substr(0, eq)] = tok.substr(eq + 1);
    }
    out.push_back(l);
  }
  return out;
}

// ---- Derived instances ------------------------------------------------------------------

// Bounds shrunk toward D x_base on a fraction of the rows, references of levels 2-4 moved.
// x_base meets every shrunk row, and level 1's dynamics rows keep their references, so
// x_base stays a point of level 1's optimal set and every level stays feasible.
Instance stress(const Instance& base, Rng& rng, double fraction, double slack, double noise) {
  Instance in = base;
  const Eigen::Matrix<double, NX, 1> x = base.result.x;
  for (int i = 0; i < C; ++i) {
    const double d = in.D.row(i).dot(x);
    const bool pick = rng.uniform() < fraction;
    const double s = slack * rng.uniform();
    if (!pick) continue;
    if (std::isfinite(in.upper(i)) && d <= in.upper(i)) in.upper(i) = d + s * (in.upper(i) - d);
    if (std::isfinite(in.lower(i)) && d >= in.lower(i)) in.lower(i) = d - s * (d - in.lower(i));
  }
  for (int p = 1; p < L; ++p) {
    const int t0 = Wbc::task_offset[p], r = Wbc::task_offset[p + 1] - t0;
    const double rms = std::sqrt(in.b.segment(t0, r).squaredNorm() / r) + 1e-3;
    for (int i = t0; i < t0 + r; ++i) in.b(i) += noise * rms * rng.normal();
  }
  return in;
}

// A task row of levels 2-4 (0-based p ≥ 1): level p, row index in the stack.
std::pair<int, int> lowerTaskRow(Rng& rng) {
  const int p = 1 + rng.below(L - 1);
  const int t0 = Wbc::task_offset[p], r = Wbc::task_offset[p + 1] - t0;
  return {p, t0 + rng.below(r)};
}

void dropContact(Instance& in, int f) {
  const int c0 = kForce0 + kContactDim * f;
  // Its forces act nowhere (dynamics, torques, CoP, friction) ...
  in.A.block(0, c0, Wbc::task_offset[1], kContactDim).setZero();
  in.D.block(0, c0, C, kContactDim).setZero();
  for (int i = 0; i < C; ++i)
    if (in.D.row(i).squaredNorm() == 0.0) {  // a foot's CoP and friction rows: 0 must be allowed
      in.lower(i) = std::min(in.lower(i), 0.0);
      in.upper(i) = std::max(in.upper(i), 0.0);
    }
  // ... its pose task is released (a swing foot), and its reference force is 0.
  const int t1 = Wbc::task_offset[1] + kContactDim * f;
  in.A.middleRows(t1, kContactDim).setZero();
  in.b.segment(t1, kContactDim).setZero();
  in.b.segment(Wbc::task_offset[3] + kForceTaskRow + kContactDim * f, kContactDim).setZero();
}

Instance degenerate(const Instance& base, Rng& rng, const std::string& kind) {
  Instance in = base;
  if (kind == "duplicate_task" || kind == "near_dependent") {
    // Row j of a level becomes a multiple of (or a rounding away from) row i of the same level.
    int p = 0, i = 0, j = 0;
    do {
      std::tie(p, i) = lowerTaskRow(rng);
      const int t0 = Wbc::task_offset[p], r = Wbc::task_offset[p + 1] - t0;
      j = t0 + rng.below(r);
    } while (i == j);
    if (kind == "duplicate_task") {
      const double alphas[] = {1.0, -1.0, 2.5, 1e-3};
      const double a = alphas[rng.below(4)];
      in.A.row(j) = a * in.A.row(i);
      in.b(j) = a * in.b(i);
    } else {
      const double eps = std::pow(10.0, -13.0 + 3.0 * rng.uniform()) * in.A.row(i).norm();
      for (int k = 0; k < NX; ++k) in.A(j, k) = in.A(i, k) + eps * rng.normal();
      in.b(j) = in.b(i);
    }
    in.w(j) = in.w(i);
  } else if (kind == "zero_task" || kind == "zero_weight") {
    const int k = 1 + rng.below(3);
    for (int m = 0; m < k; ++m) {
      const int i = lowerTaskRow(rng).second;
      if (kind == "zero_task") {
        in.A.row(i).setZero();
        in.b(i) = 0.0;
      } else {
        in.w(i) = 0.0;
      }
    }
  } else if (kind == "duplicate_constraint") {
    // Two identical rows (bounds too): a degenerate vertex when the row is active.
    const int p = rng.below(2);
    const int c0 = Wbc::constraint_offset[p], r = Wbc::constraint_offset[p + 1] - c0;
    const int i = c0 + rng.below(r);
    int j = i;
    while (j == i) j = c0 + rng.below(r);
    in.D.row(j) = in.D.row(i);
    in.lower(j) = in.lower(i);
    in.upper(j) = in.upper(i);
  } else if (kind == "contact_drop") {
    dropContact(in, rng.below(2));
  } else {
    throw std::runtime_error("unknown degenerate kind '" + kind + "'");
  }
  return in;
}

// The stored result of a derived instance: HqpWbc's cold solve (its statuses are the
// instance's expected ones; the warm replay must reach the same x*).
void solveCold(Wbc& wbc, Instance& in) {
  hqp::loadInstance(in, wbc, false);
  wbc.solve();
  in.result = wbc.result();
  for (auto& l : in.result.levels) l.time_us = 0.0;  // not a run's time
}

struct Family {
  std::vector<Instance> instances;
  std::string source;
};

int generate(const std::string& seeds_path, const std::string& scenario_dir, const std::string& base_path,
             const std::string& out_dir, int max_per_line) {
  const std::vector<SeedLine> seeds = readSeeds(seeds_path);
  hqp::ProblemFileInfo info;
  std::map<std::string, Family> fam;
  Family& sc = fam["walker3_scenarios"];
  std::vector<Instance> pool;
  if (!base_path.empty()) {
    pool = hqp::readProblemFile<Wbc>(base_path, &info);
  } else {
    sc.source = "hqp_corpus generate: sim_demo recordings of";
    for (const SeedLine& l : seeds) {
      if (l.family != "scenario") continue;
      const std::string path = scenario_dir + "/" + l.name + ".hqprec";
      hqp::ProblemFileInfo fi;
      std::vector<Instance> v = hqp::readProblemFile<Wbc>(path, &fi);
      if (sc.instances.empty()) info = fi;
      std::printf("%-14s %4zu instances  (%s)\n", l.name.c_str(), v.size(), fi.source.c_str());
      sc.instances.insert(sc.instances.end(), v.begin(), v.end());
      sc.source += " " + l.name;
    }
    pool = sc.instances;
  }
  if (pool.empty()) throw std::runtime_error("no base instances");
  auto wbc = std::make_unique<Wbc>(info.settings);
  for (const SeedLine& l : seeds) {
    if (l.family != "stress" && l.family != "degenerate") continue;
    Family& f = fam[l.family];
    const auto seed = static_cast<std::uint64_t>(l.num("seed", 0));
    Rng rng(seed);
    const int count = std::min(static_cast<int>(l.num("count", 0)), max_per_line);
    for (int k = 0; k < count; ++k) {
      const Instance& base = pool[static_cast<std::size_t>(rng.below(static_cast<int>(pool.size())))];
      Instance in = l.family == "stress"
                        ? stress(base, rng, l.num("fraction", 0.5), l.num("slack", 0.05), l.num("noise", 0.2))
                        : degenerate(base, rng, l.str("kind"));
      solveCold(*wbc, in);
      f.instances.push_back(in);
    }
    std::ostringstream s;
    s << (f.source.empty() ? "hqp_corpus generate from " + (base_path.empty() ? std::string("walker3_scenarios") : base_path) + ":"
                           : std::string(";"));
    s << " " << l.family << " seed=" << seed << " count=" << count;
    for (const auto& [k, v] : l.kv)
      if (k != "seed" && k != "count") s << " " << k << "=" << v;
    f.source += s.str();
  }
  for (const char* name : kFamilies) {
    const Family& f = fam[name];
    if (f.instances.empty()) continue;
    const std::string path = out_dir + "/" + name + ".hqprec";
    hqp::writeProblemFile<Wbc>(path, f.instances.data(), f.instances.size(), info.settings, f.source);
    std::printf("%s: %zu instances\n", path.c_str(), f.instances.size());
  }
  return 0;
}

// ---- Exactness check ----------------------------------------------------------------------

// Weighted residual of every level at x.
std::array<double, L> levelObjectives(const Instance& in, const Eigen::Matrix<double, NX, 1>& x) {
  std::array<double, L> f{};
  for (int p = 0; p < L; ++p)
    for (int i = Wbc::task_offset[p]; i < Wbc::task_offset[p + 1]; ++i) {
      const double e = in.A.row(i).dot(x) - in.b(i);
      f[static_cast<std::size_t>(p)] += in.w(i) * e * e;
    }
  return f;
}

// Largest bound violation at x over all rows, each row scaled by its norm.
double violation(const Instance& in, const Eigen::Matrix<double, NX, 1>& x) {
  double v = 0.0;
  for (int i = 0; i < C; ++i) {
    const double nr = std::max(in.D.row(i).norm(), 1e-300), d = in.D.row(i).dot(x);
    v = std::max(v, std::max(in.lower(i) - d, d - in.upper(i)) / nr);
  }
  return v;
}

// −1: a better than b (lexicographically, to tolerance), 0 equal, 1 worse.
int compareLex(const std::array<double, L>& a, const std::array<double, L>& b, double rel) {
  for (int p = 0; p < L; ++p) {
    const double tol = rel * (1.0 + std::max(a[p], b[p]));
    if (a[p] < b[p] - tol) return -1;
    if (a[p] > b[p] + tol) return 1;
  }
  return 0;
}

struct Tally {
  int instances = 0, status_warm = 0, status_cold = 0, stored_not_optimal = 0;
  int x_warm_cold = 0, x_stored = 0, peer_equal = 0, hqp_better = 0, peer_better = 0, peer_failed = 0;
  int unique = 0;  // no null space left after the last level (x* unique)
  double worst_dx = 0.0, worst_viol = 0.0, active = 0.0;
  std::vector<std::string> notes;
};

Tally check(const std::vector<Instance>& v, const hqp::HqpSettings& settings, const std::string& name, double tol,
            double obj_tol, bool verbose) {
  Tally t;
  auto wbc = std::make_unique<Wbc>(settings);
  auto peer = std::make_unique<Peer>();
  for (std::size_t k = 0; k < v.size(); ++k) {
    const Instance& in = v[k];
    ++t.instances;
    std::array<Eigen::Matrix<double, NX, 1>, 2> x;
    std::array<bool, 2> status_ok{};
    for (int warm = 0; warm < 2; ++warm) {
      hqp::loadInstance(in, *wbc, warm != 0);
      wbc->solve();
      const auto& r = wbc->result();
      x[warm] = r.x;
      // Every family is feasible by construction (docs/benchmarks.md): every level Optimal.
      bool ok = true;
      for (int p = 0; p < L; ++p) ok = ok && r.levels[p].status == hqp::QpStatus::Optimal;
      // ... and every bound held (a status is a claim; the point is checked against it).
      const double viol = violation(in, r.x);
      if (viol > 1e-6) {
        ok = false;
        t.notes.push_back(name + " instance " + std::to_string(k) + (warm ? ", warm" : ", cold") +
                          ": a bound broken by " + std::to_string(viol));
      }
      status_ok[warm] = ok;
      if (warm) {
        double a = 0.0;
        for (const auto& l : r.levels) a = std::max(a, static_cast<double>(l.num_active));
        t.active += a;
        if (r.levels[L - 1].null_dim == 0) ++t.unique;
      }
    }
    bool stored_optimal = true;
    for (const auto& l : in.result.levels) stored_optimal = stored_optimal && l.status == hqp::QpStatus::Optimal;
    if (!stored_optimal) ++t.stored_not_optimal;
    t.status_warm += status_ok[1];
    t.status_cold += status_ok[0];
    const auto scaled = [](const auto& a, const auto& b) {
      return (a - b).template lpNorm<Eigen::Infinity>() / std::max(1.0, b.template lpNorm<Eigen::Infinity>());
    };
    // Where x* is not unique (null space left), warm and cold may pick other points of the
    // optimal set: then equal level objectives are what must agree.
    const auto fw = levelObjectives(in, x[1]), fc = levelObjectives(in, x[0]);
    const double dx = scaled(x[1], x[0]);
    const bool same = dx <= tol || compareLex(fw, fc, obj_tol) == 0;
    t.x_warm_cold += same;
    const bool as_stored =
        scaled(x[1], in.result.x) <= tol || compareLex(fw, levelObjectives(in, in.result.x), obj_tol) == 0;
    t.x_stored += as_stored;
    if (!as_stored && status_ok[1])
      t.notes.push_back(name + " instance " + std::to_string(k) + ": x* not the stored one (|dx| " +
                        std::to_string(scaled(x[1], in.result.x)) + ", level objectives differ)");
    t.worst_dx = std::max(t.worst_dx, dx);
    t.worst_viol = std::max(t.worst_viol, violation(in, x[1]));
    if (!status_ok[0] || !status_ok[1] || !same)
      t.notes.push_back(name + " instance " + std::to_string(k) + ": |dx warm-cold| " + std::to_string(dx) +
                        (status_ok[1] ? "" : ", warm: a level not Optimal") +
                        (status_ok[0] ? "" : ", cold: a level not Optimal"));
    // The peer, cold (an independent solve of the same hierarchy).
    const int fails = peer->solve(in.A, in.b, in.w, in.D, in.lower, in.upper, Wbc::task_offset,
                                  Wbc::constraint_offset, false);
    const Eigen::Matrix<double, NX, 1> xp = peer->x();
    // A peer point that breaks a bound is not comparable (its QPs in 30 variables drift).
    if (fails > 0 || violation(in, xp) > 1e-6) {
      ++t.peer_failed;
      continue;
    }
    const int c = compareLex(fw, levelObjectives(in, xp), obj_tol);
    if (c == 0) ++t.peer_equal;
    else if (c < 0) {
      ++t.hqp_better;
      if (verbose) t.notes.push_back(name + " instance " + std::to_string(k) + ": the peer ends lexicographically higher");
    }
    else {
      ++t.peer_better;
      t.notes.push_back(name + " instance " + std::to_string(k) + ": the peer reaches a lexicographically lower objective");
    }
  }
  return t;
}

int checkCommand(const std::string& dir, int max, double tol, double obj_tol, bool verbose) {
  std::printf("%-18s %5s %12s %12s %9s %9s %11s %11s %10s %10s %8s %8s %10s\n", "family", "inst", "optimal_warm",
              "optimal_cold", "warm=cold", "=stored", "stored_nopt", "peer_equal", "hqp_better", "peer_better",
              "peer_fail", "unique", "active");
  bool ok = true;
  std::vector<std::string> notes;
  for (const char* name : kFamilies) {
    const std::string path = dir + "/" + name + ".hqprec";
    hqp::ProblemFileInfo info;
    std::vector<Instance> v;
    try {
      v = hqp::readProblemFile<Wbc>(path, &info);
    } catch (const hqp::ProblemFileError& e) {
      std::printf("%-18s (none: %s)\n", name, e.what());
      continue;
    }
    if (max > 0 && static_cast<int>(v.size()) > max) v.resize(static_cast<std::size_t>(max));
    const Tally t = check(v, info.shippedSettings(), name, tol, obj_tol, verbose);
    std::printf("%-18s %5d %12d %12d %9d %9d %11d %11d %10d %10d %8d %8d %10.1f\n", name, t.instances, t.status_warm,
                t.status_cold, t.x_warm_cold, t.x_stored, t.stored_not_optimal, t.peer_equal, t.hqp_better,
                t.peer_better, t.peer_failed, t.unique, t.active / std::max(1, t.instances));
    ok = ok && t.status_warm == t.instances && t.status_cold == t.instances && t.x_warm_cold == t.instances &&
         t.x_stored == t.instances && t.peer_better == 0;
    notes.insert(notes.end(), t.notes.begin(), t.notes.end());
  }
  for (std::size_t k = 0; k < notes.size() && (verbose || k < 30); ++k) std::printf("  %s\n", notes[k].c_str());
  std::printf("%s\n", ok ? "corpus check: all instances as expected" : "corpus check: MISMATCHES (above)");
  return ok ? 0 : 1;
}

// One instance in detail: per level, warm / cold / peer objective, status, iterations, active rows.
int showCommand(const std::string& file, int k) {
  hqp::ProblemFileInfo info;
  const std::vector<Instance> v = hqp::readProblemFile<Wbc>(file, &info);
  if (k < 0 || k >= static_cast<int>(v.size())) throw std::runtime_error("no instance " + std::to_string(k));
  const Instance& in = v[static_cast<std::size_t>(k)];
  auto wbc = std::make_unique<Wbc>(info.shippedSettings());
  wbc->setKktResiduals(true);  // the certificate says which of two disagreeing solves is optimal
  std::printf("%s instance %d (tick %lld, t = %.3f s)\n", file.c_str(), k, static_cast<long long>(in.tick), in.time);
  std::array<Eigen::Matrix<double, NX, 1>, 2> x;
  for (int warm = 1; warm >= 0; --warm) {
    hqp::loadInstance(in, *wbc, warm != 0);
    wbc->solve();
    const auto& r = wbc->result();
    x[warm] = r.x;
    const auto f = levelObjectives(in, r.x);
    std::printf("%s: violation %.3g\n", warm ? "warm" : "cold", violation(in, r.x));
    for (int p = 0; p < L; ++p) {
      const auto& l = r.levels[p];
      std::printf("  level %d: %-16s objective %.12g  stored %-16s iterations %d  active %d  rank %d  null %d  dual %d\n",
                  p + 1, hqp::toString(l.status), f[p], hqp::toString(in.result.levels[p].status), l.iterations,
                  l.num_active, l.rank, l.null_dim, l.dual ? 1 : 0);
      if (l.kkt.computed)
        std::printf("           KKT: stationarity %.3g (scale %.3g, gradient %.3g), primal %.3g, dual %.3g, complementarity %.3g\n",
                    l.kkt.stationarity, l.kkt.stationarity_scale, l.kkt.gradient_scale, l.kkt.primal, l.kkt.dual,
                    l.kkt.complementarity);
    }
  }
  std::printf("|x_warm - x_cold|_inf = %.3g\n", (x[1] - x[0]).lpNorm<Eigen::Infinity>());
  auto peer = std::make_unique<Peer>();
  const int fails = peer->solve(in.A, in.b, in.w, in.D, in.lower, in.upper, Wbc::task_offset,
                                Wbc::constraint_offset, false);
  const Eigen::Matrix<double, NX, 1> xp = peer->x();
  const auto f = levelObjectives(in, xp);
  std::printf("peer (cold): %d levels not Optimal, violation %.3g\n", fails, violation(in, xp));
  for (int p = 0; p < L; ++p) std::printf("  level %d: objective %.12g\n", p + 1, f[p]);
  return 0;
}

nlohmann::json vectorJson(const Eigen::Ref<const Eigen::VectorXd>& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (std::isfinite(v(i))) out.push_back(v(i));
    else out.push_back(nullptr);  // ±inf: no bound (the side tells which)
  }
  return out;
}

nlohmann::json rowsJson(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(vectorJson(m.row(i).transpose()));
  return rows;
}

int dumpCommand(const std::string& file, const std::string& out_path) {
  hqp::ProblemFileInfo info;
  const std::vector<Instance> v = hqp::readProblemFile<Wbc>(file, &info);
  auto wbc = std::make_unique<Wbc>(info.shippedSettings());
  nlohmann::json doc;
  doc["source"] = file;
  doc["task_offset"] = std::vector<int>(Wbc::task_offset.begin(), Wbc::task_offset.end());
  doc["constraint_offset"] = std::vector<int>(Wbc::constraint_offset.begin(), Wbc::constraint_offset.end());
  nlohmann::json list = nlohmann::json::array();
  for (const Instance& in : v) {
    hqp::loadInstance(in, *wbc, true);
    wbc->solve();
    nlohmann::json j;
    j["A"] = rowsJson(in.A);
    j["b"] = vectorJson(in.b);
    j["w"] = vectorJson(in.w);
    j["D"] = rowsJson(in.D);
    j["lower"] = vectorJson(in.lower);
    j["upper"] = vectorJson(in.upper);
    j["x"] = vectorJson(wbc->result().x);
    nlohmann::json status = nlohmann::json::array();
    for (const auto& l : wbc->result().levels) status.push_back(hqp::toString(l.status));
    j["status"] = status;
    list.push_back(j);
  }
  doc["instances"] = list;
  std::ofstream out(out_path);
  if (!out) throw std::runtime_error(out_path + ": cannot open for writing");
  out << doc.dump() << "\n";  // shortest round-trip representation of every double
  if (!out) throw std::runtime_error(out_path + ": write error");
  std::printf("%s: %zu instances\n", out_path.c_str(), v.size());
  return 0;
}

// ---- Rewritten families (steady, reformulate) -----------------------------------------------

// Every family file in dir passed through rewrite(info, family index, instances) and written to
// out_dir, note appended to its source; families absent from dir are skipped (generate --base
// writes no scenarios).
template <class Rewrite>
int rewriteFamilies(const std::string& dir, const std::string& out_dir, const std::string& note,
                    Rewrite&& rewrite) {
  std::filesystem::create_directories(out_dir);
  int families = 0;
  for (std::size_t fam = 0; fam < std::size(kFamilies); ++fam) {
    const std::string path = dir + "/" + kFamilies[fam] + ".hqprec";
    if (!std::filesystem::exists(path)) continue;
    ++families;
    hqp::ProblemFileInfo info;
    std::vector<Instance> v = hqp::readProblemFile<Wbc>(path, &info);
    rewrite(info, fam, v);
    const std::string out = out_dir + "/" + kFamilies[fam] + ".hqprec";
    hqp::writeProblemFile<Wbc>(out, v.data(), v.size(), info.settings, info.source + "; " + note);
    std::printf("%s: %zu instances\n", out.c_str(), v.size());
  }
  if (families == 0) throw std::runtime_error(dir + ": no family file");
  return 0;
}

// Every instance's warm start replaced by the working sets this build's solve of it ends with
// (from its recorded warm start): a controller's next tick on a problem that did not change
// (docs/hqp-tuning.md, "The steady state"). Instances, stored results and header as read.
int steadyCommand(const std::string& dir, const std::string& out_dir) {
  return rewriteFamilies(dir, out_dir, "warm starts: the working sets each solve ends with",
                         [](const hqp::ProblemFileInfo& info, std::size_t, std::vector<Instance>& v) {
                           auto wbc = std::make_unique<Wbc>(info.shippedSettings());
                           for (Instance& in : v) {
                             hqp::loadInstance(in, *wbc, true);
                             wbc->solve();
                             hqp::captureWarmStart(*wbc, in);
                           }
                         });
}

// ---- Reformulations -------------------------------------------------------------------------

// The same hierarchy written another way (docs/hqp-tuning.md, "Reformulated corpus"):
//  - the variables in a random order: A and D by columns, the stored x* by rows;
//  - every constraint row times f ∈ [1/2, 2] (D_i and both bounds; ±inf stays), its stored
//    multiplier divided by f;
//  - every task row times g ∈ [1/2, 2] (A_i, b_i) with its weight divided by g², so that
//    W^½ A and W^½ b, every level objective, are unchanged.
// The feasible set and the lexicographic optimum are the same up to the permutation; the
// factors are not powers of 2, so every product rounds differently. Warm starts name rows and
// their sides: unchanged.
Instance reformulated(const Instance& in, Rng& rng) {
  Instance out = in;
  std::array<int, NX> perm{};  // new variable j is old variable perm[j]
  std::iota(perm.begin(), perm.end(), 0);
  for (int j = NX - 1; j > 0; --j) std::swap(perm[std::size_t(j)], perm[std::size_t(rng.below(j + 1))]);
  for (int j = 0; j < NX; ++j) {
    const int o = perm[std::size_t(j)];
    out.A.col(j) = in.A.col(o);
    out.D.col(j) = in.D.col(o);
    out.result.x(j) = in.result.x(o);
  }
  const auto factor = [&] { return std::exp2(2.0 * rng.uniform() - 1.0); };
  std::array<double, C> f{};
  for (int i = 0; i < C; ++i) {
    const double fi = f[std::size_t(i)] = factor();
    out.D.row(i) *= fi;
    out.lower(i) *= fi;
    out.upper(i) *= fi;
  }
  for (int i = 0; i < T; ++i) {
    const double g = factor();
    out.A.row(i) *= g;
    out.b(i) *= g;
    out.w(i) /= g * g;
  }
  for (auto& l : out.result.levels)
    for (int a = 0; a < l.num_active; ++a)
      l.multiplier[std::size_t(a)] /= f[std::size_t(l.active_row[std::size_t(a)])];
  return out;
}

int reformulateCommand(const std::string& dir, const std::string& out_dir, std::uint64_t seed) {
  return rewriteFamilies(dir, out_dir, "reformulated (seed " + std::to_string(seed) + ")",
                         [seed](const hqp::ProblemFileInfo&, std::size_t fam, std::vector<Instance>& v) {
                           for (std::size_t k = 0; k < v.size(); ++k) {
                             Rng rng(seed * 1000003u + fam * 100003u + k);
                             v[k] = reformulated(v[k], rng);
                           }
                         });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"HqpWbc instance corpus: generate the families, check them (docs/benchmarks.md)"};
  app.require_subcommand(1);
  std::string seeds, scenarios, base, out = ".", dir = ".";
  int max_per_line = 1 << 30, max = 0;
  double tol = 1e-6, obj_tol = 1e-6;
  auto* gen = app.add_subcommand("generate", "write walker3_scenarios / stress / degenerate .hqprec files");
  gen->add_option("--seeds", seeds, "seed list (bench/data/corpus.txt)")->required();
  gen->add_option("--scenarios", scenarios, "folder of the sim_demo recordings <scenario>.hqprec");
  gen->add_option("--base", base, "derive stress and degenerate from this recording instead");
  gen->add_option("--out", out, "output folder")->capture_default_str();
  gen->add_option("--max-per-line", max_per_line, "at most this many instances per seed line");
  auto* chk = app.add_subcommand("check", "exactness over the corpus files in DIR");
  chk->add_option("dir", dir, "folder of the family files")->required();
  chk->add_option("--max", max, "check at most this many instances per family (0: all)");
  chk->add_option("--tol", tol, "|x_warm - x_cold|_inf / max(1, |x_cold|_inf)")->capture_default_str();
  chk->add_option("--objective-tol", obj_tol, "relative tolerance of level objectives")->capture_default_str();
  bool verbose = false;
  chk->add_flag("--verbose", verbose, "also list the instances where the peer ends worse");
  std::string show_file;
  int show_k = 0;
  auto* shw = app.add_subcommand("show", "one instance in detail: warm, cold and the peer per level");
  shw->add_option("file", show_file, "a family file")->required();
  shw->add_option("instance", show_k, "0-based index")->required();
  std::string dump_file, dump_out;
  auto* dmp = app.add_subcommand("dump", "instances and warm solutions as JSON (tools/hqp_oracle.py)");
  dmp->add_option("file", dump_file, "a family file")->required();
  dmp->add_option("out", dump_out, "the JSON file to write")->required();
  std::string steady_out;
  auto* std_ = app.add_subcommand("steady", "the families with each instance warm-started from its own solve's working sets");
  std_->add_option("dir", dir, "folder of the family files")->required();
  std_->add_option("out", steady_out, "folder to write them to")->required();
  std::string reform_out;
  std::uint64_t reform_seed = 1;
  auto* ref = app.add_subcommand("reformulate", "the families as another formulation of the same hierarchies");
  ref->add_option("dir", dir, "folder of the family files")->required();
  ref->add_option("out", reform_out, "folder to write them to")->required();
  ref->add_option("--seed", reform_seed, "seed of the permutation and the factors")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    if (*gen) {
      if (scenarios.empty() == base.empty()) {
        std::fprintf(stderr, "hqp_corpus generate: give --scenarios DIR or --base FILE\n");
        return 2;
      }
      return generate(seeds, scenarios, base, out, max_per_line);
    }
    if (*shw) return showCommand(show_file, show_k);
    if (*dmp) return dumpCommand(dump_file, dump_out);
    if (*std_) return steadyCommand(dir, steady_out);
    if (*ref) return reformulateCommand(dir, reform_out, reform_seed);
    return checkCommand(dir, max, tol, obj_tol, verbose);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hqp_corpus: %s\n", e.what());
    return 2;
  }
}
