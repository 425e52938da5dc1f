#pragma once
// NOT REAL-TIME: files of recorded HqpWbc problem instances (hqp/problem_instance.hpp).
// Allocates, throws ProblemFileError, does file I/O: use it before or after a run, in tools,
// tests and benchmarks, never in a control tick. The format (little-endian, fixed-size
// records) is specified in docs/recording.md; keep the two in step (and bump kVersion).

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hqp/hqp_wbc.hpp"
#include "hqp/problem_instance.hpp"
#include "hqp/qp_status.hpp"

namespace hqp {

// Every read or write failure; what() names the file, what is wrong, and where.
class ProblemFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The header of a file: its problem shape, the solver settings of the run, where it came from.
struct ProblemFileInfo {
  std::uint32_t version = 0;
  int nx = 0;
  std::vector<int> task_rows, constraint_rows;  // per level
  HqpSettings settings{};                       // of the recorded run (replay uses them)
  std::string source;                           // free text: scenario, window, command
  std::uint64_t count = 0;                      // instances
  std::uint64_t header_bytes = 0, record_bytes = 0;
  // The run's settings with the path the solver takes today (HqpSettings::defer_constraints, which
  // does not change x*; files before version 3 read as the cascade that recorded them): what
  // benchmarks and the corpus check time and check. Exact replays use `settings`.
  HqpSettings shippedSettings() const {
    HqpSettings s = settings;
    s.defer_constraints = HqpSettings{}.defer_constraints;
    return s;
  }
};

namespace problem_file {

inline constexpr char kMagic[8] = {'H', 'Q', 'P', 'P', 'R', 'O', 'B', '\n'};
inline constexpr std::uint32_t kVersion = 3;  // 2: + dual_last_level, 3: + defer_constraints

// Bytes of one instance for a shape (docs/recording.md, "Record").
inline std::uint64_t recordBytes(int nx, int levels, int task_rows, int constraint_rows) {
  const std::uint64_t n = static_cast<std::uint64_t>(nx), L = static_cast<std::uint64_t>(levels);
  const std::uint64_t T = static_cast<std::uint64_t>(task_rows);
  const std::uint64_t C = static_cast<std::uint64_t>(constraint_rows);
  return 16 + 8 * (T * n + 2 * T + C * n + 2 * C)  // tick, time; A, b, w, D, lower, upper
         + L * (8 + 8 * C)                          // warm starts
         + 8 * n + 8                                // x, status, failed_level
         + L * (32 + 32 + 8 * C);                   // per level results
}

// Little-endian encoding independent of the host's byte order.
class Writer {
 public:
  void u32(std::uint32_t v) { bytes(v, 4); }
  void i32(int v) { bytes(static_cast<std::uint32_t>(v), 4); }
  void u64(std::uint64_t v) { bytes(v, 8); }
  void i64(std::int64_t v) { bytes(static_cast<std::uint64_t>(v), 8); }
  void f64(double v) {
    std::uint64_t u = 0;
    std::memcpy(&u, &v, 8);
    bytes(u, 8);
  }
  void raw(const char* p, std::size_t n) { out_.append(p, n); }
  std::string& str() { return out_; }

 private:
  void bytes(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
  }
  std::string out_;
};

class Reader {
 public:
  Reader(const std::string& data, std::string name) : data_(data), name_(std::move(name)) {}
  std::uint32_t u32(const char* what) { return static_cast<std::uint32_t>(bytes(4, what)); }
  int i32(const char* what) {
    return static_cast<int>(static_cast<std::int32_t>(static_cast<std::uint32_t>(bytes(4, what))));
  }
  std::uint64_t u64(const char* what) { return bytes(8, what); }
  std::int64_t i64(const char* what) { return static_cast<std::int64_t>(bytes(8, what)); }
  double f64(const char* what) {
    const std::uint64_t u = bytes(8, what);
    double v = 0.0;
    std::memcpy(&v, &u, 8);
    return v;
  }
  std::string raw(std::size_t n, const char* what) {
    need(n, what);
    std::string s = data_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  std::size_t pos() const { return pos_; }
  std::size_t size() const { return data_.size(); }
  [[noreturn]] void fail(const std::string& msg) const {
    throw ProblemFileError(name_ + ": " + msg);
  }
  void need(std::size_t n, const char* what) const {
    if (data_.size() - pos_ < n) {
      std::ostringstream m;
      m << "truncated file: " << data_.size() << " bytes, ended while reading " << what
        << " at byte " << pos_;
      fail(m.str());
    }
  }

 private:
  std::uint64_t bytes(int n, const char* what) {
    need(static_cast<std::size_t>(n), what);
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i)
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(data_[pos_ + i])) << (8 * i);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }
  const std::string& data_;
  std::string name_;
  std::size_t pos_ = 0;
};

inline std::string shapeText(int nx, const std::vector<int>& t, const std::vector<int>& c) {
  std::ostringstream s;
  s << "nx " << nx << ", " << t.size() << " levels, task rows (";
  for (std::size_t i = 0; i < t.size(); ++i) s << (i ? "," : "") << t[i];
  s << "), constraint rows (";
  for (std::size_t i = 0; i < c.size(); ++i) s << (i ? "," : "") << c[i];
  s << ")";
  return s.str();
}

template <class Wbc>
std::vector<int> taskRowsOf() {
  std::vector<int> v;
  for (int p = 0; p < Wbc::num_levels; ++p)
    v.push_back(Wbc::task_offset[static_cast<std::size_t>(p) + 1] -
                Wbc::task_offset[static_cast<std::size_t>(p)]);
  return v;
}
template <class Wbc>
std::vector<int> constraintRowsOf() {
  std::vector<int> v;
  for (int p = 0; p < Wbc::num_levels; ++p)
    v.push_back(Wbc::constraint_offset[static_cast<std::size_t>(p) + 1] -
                Wbc::constraint_offset[static_cast<std::size_t>(p)]);
  return v;
}

inline std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ProblemFileError(path + ": cannot open for reading");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw ProblemFileError(path + ": read error");
  return data;
}

inline ProblemFileInfo decodeHeader(Reader& r) {
  ProblemFileInfo info;
  const std::string magic = r.raw(8, "the magic number");
  if (std::memcmp(magic.data(), kMagic, 8) != 0)
    r.fail("wrong magic number: not an HQP problem recording (docs/recording.md)");
  info.version = r.u32("the version");
  if (info.version < 1 || info.version > kVersion)
    r.fail("unsupported version " + std::to_string(info.version) + " (this build reads versions 1 to " +
           std::to_string(kVersion) + ")");
  info.nx = r.i32("nx");
  const int levels = r.i32("the number of levels");
  if (info.nx <= 0 || info.nx > 100000 || levels <= 0 || levels > 1000)
    r.fail("bad dimensions in the header: nx " + std::to_string(info.nx) + ", levels " +
           std::to_string(levels));
  int T = 0, C = 0;
  for (int p = 0; p < levels; ++p) info.task_rows.push_back(r.i32("the task rows of a level"));
  for (int p = 0; p < levels; ++p)
    info.constraint_rows.push_back(r.i32("the constraint rows of a level"));
  for (int p = 0; p < levels; ++p) {
    if (info.task_rows[p] < 0 || info.constraint_rows[p] < 0 || info.task_rows[p] > 100000 ||
        info.constraint_rows[p] > 100000)
      r.fail("bad dimensions in the header: " +
             shapeText(info.nx, info.task_rows, info.constraint_rows));
    T += info.task_rows[p];
    C += info.constraint_rows[p];
  }
  info.settings.rank_tol = r.f64("settings.rank_tol");
  info.settings.warm_start = r.i32("settings.warm_start") != 0;
  // Version 1 files were recorded before the dual method existed.
  info.settings.dual_last_level = info.version >= 2 && r.i32("settings.dual_last_level") != 0;
  // Versions 1 and 2 were recorded before the deferred path existed (the cascade solved them).
  info.settings.defer_constraints = info.version >= 3 && r.i32("settings.defer_constraints") != 0;
  info.settings.qp.max_iterations = r.i32("settings.qp.max_iterations");
  info.settings.qp.feasibility_tol = r.f64("settings.qp.feasibility_tol");
  info.settings.qp.rank_tol = r.f64("settings.qp.rank_tol");
  info.settings.qp.dual_tol = r.f64("settings.qp.dual_tol");
  info.count = r.u64("the instance count");
  const std::uint32_t len = r.u32("the source text length");
  info.source = r.raw(len, "the source text");
  info.header_bytes = r.pos();
  info.record_bytes = recordBytes(info.nx, levels, T, C);
  if (info.count > (~std::uint64_t{0} - info.header_bytes) / info.record_bytes)
    r.fail("bad instance count " + std::to_string(info.count));
  const std::uint64_t expect = info.header_bytes + info.count * info.record_bytes;
  if (r.size() != expect) {
    std::ostringstream m;
    m << (r.size() < expect ? "truncated file: " : "unexpected trailing bytes: ") << r.size()
      << " bytes, expected " << expect << " for " << info.count << " instances of "
      << info.record_bytes << " bytes";
    if (r.size() < expect)
      m << " (instance " << (r.size() - info.header_bytes) / info.record_bytes << " is incomplete)";
    r.fail(m.str());
  }
  return info;
}

}  // namespace problem_file

// The header of a recording (any shape): for tools that print what a file holds.
inline ProblemFileInfo readProblemFileInfo(const std::string& path) {
  const std::string data = problem_file::readWholeFile(path);
  problem_file::Reader r(data, path);
  return problem_file::decodeHeader(r);
}

// The bytes of a recording of `count` instances of an HqpWbc of type Wbc.
template <class Wbc>
std::string encodeProblemFile(const ProblemInstance<Wbc>* instances, std::size_t count,
                              const HqpSettings& settings, const std::string& source) {
  using I = ProblemInstance<Wbc>;
  constexpr int n = I::nx, L = I::num_levels, T = I::task_rows, C = I::constraint_rows;
  problem_file::Writer w;
  w.raw(problem_file::kMagic, 8);
  w.u32(problem_file::kVersion);
  w.i32(n);
  w.i32(L);
  for (int t : problem_file::taskRowsOf<Wbc>()) w.i32(t);
  for (int c : problem_file::constraintRowsOf<Wbc>()) w.i32(c);
  w.f64(settings.rank_tol);
  w.i32(settings.warm_start ? 1 : 0);
  w.i32(settings.dual_last_level ? 1 : 0);
  w.i32(settings.defer_constraints ? 1 : 0);
  w.i32(settings.qp.max_iterations);
  w.f64(settings.qp.feasibility_tol);
  w.f64(settings.qp.rank_tol);
  w.f64(settings.qp.dual_tol);
  w.u64(count);
  if (source.size() > 0xffffffffu) throw ProblemFileError("source text too long");
  w.u32(static_cast<std::uint32_t>(source.size()));
  w.raw(source.data(), source.size());
  w.str().reserve(w.str().size() + count * problem_file::recordBytes(n, L, T, C));
  const auto ints = [&](const auto& a, int na, int fill) {
    for (int k = 0; k < C; ++k) w.i32(k < na ? static_cast<int>(a[static_cast<std::size_t>(k)]) : fill);
  };
  for (std::size_t s = 0; s < count; ++s) {
    const I& in = instances[s];
    w.i64(in.tick);
    w.f64(in.time);
    for (int i = 0; i < T; ++i)
      for (int j = 0; j < n; ++j) w.f64(in.A(i, j));
    for (int i = 0; i < T; ++i) w.f64(in.b(i));
    for (int i = 0; i < T; ++i) w.f64(in.w(i));
    for (int i = 0; i < C; ++i)
      for (int j = 0; j < n; ++j) w.f64(in.D(i, j));
    for (int i = 0; i < C; ++i) w.f64(in.lower(i));
    for (int i = 0; i < C; ++i) w.f64(in.upper(i));
    for (const auto& ws : in.warm) {
      w.i32(ws.variables);
      w.i32(ws.num_active);
      ints(ws.row, ws.num_active, -1);
      ints(ws.upper, ws.num_active, 0);
    }
    const auto& r = in.result;
    for (int j = 0; j < n; ++j) w.f64(r.x(j));
    w.i32(static_cast<int>(r.status));
    w.i32(r.failed_level);
    for (const auto& l : r.levels) {
      w.i32(static_cast<int>(l.status));
      w.i32(l.rank);
      w.i32(l.null_dim);
      w.i32(l.variables);
      w.i32(l.iterations);
      w.i32(l.num_active);
      w.i32(l.constraints_dropped ? 1 : 0);
      w.i32(l.slack_used ? 1 : 0);
      w.f64(l.residual);
      w.f64(l.objective);
      w.f64(l.violation);
      w.f64(l.time_us);
      ints(l.active_row, l.num_active, -1);
      ints(l.active_upper, l.num_active, 0);
    }
  }
  return std::move(w.str());
}

// Instances from the bytes of a recording; `name` labels the errors. Throws ProblemFileError
// if the data are not a recording, are truncated, or hold another shape than Wbc's.
template <class Wbc>
std::vector<ProblemInstance<Wbc>> decodeProblemFile(const std::string& data, const std::string& name,
                                                    ProblemFileInfo* info_out = nullptr) {
  using I = ProblemInstance<Wbc>;
  constexpr int n = I::nx, L = I::num_levels, T = I::task_rows, C = I::constraint_rows;
  problem_file::Reader r(data, name);
  const ProblemFileInfo info = problem_file::decodeHeader(r);
  const std::vector<int> tr = problem_file::taskRowsOf<Wbc>();
  const std::vector<int> cr = problem_file::constraintRowsOf<Wbc>();
  if (info.nx != n || info.task_rows != tr || info.constraint_rows != cr)
    r.fail("wrong dimensions: the file holds " +
           problem_file::shapeText(info.nx, info.task_rows, info.constraint_rows) +
           ", this reader expects " + problem_file::shapeText(n, tr, cr));
  std::vector<I> out(static_cast<std::size_t>(info.count));
  const auto count = [&](int v, int max, std::size_t s, const char* what) {
    if (v < 0 || v > max)
      r.fail("instance " + std::to_string(s) + ": bad " + what + " " + std::to_string(v));
    return v;
  };
  const auto status = [&](int v, std::size_t s) {
    if (v < 0 || v > static_cast<int>(QpStatus::BudgetCut))
      r.fail("instance " + std::to_string(s) + ": bad status " + std::to_string(v));
    return static_cast<QpStatus>(v);
  };
  for (std::size_t s = 0; s < out.size(); ++s) {
    I& in = out[s];
    in.tick = r.i64("tick");
    in.time = r.f64("time");
    for (int i = 0; i < T; ++i)
      for (int j = 0; j < n; ++j) in.A(i, j) = r.f64("A");
    for (int i = 0; i < T; ++i) in.b(i) = r.f64("b");
    for (int i = 0; i < T; ++i) in.w(i) = r.f64("w");
    for (int i = 0; i < C; ++i)
      for (int j = 0; j < n; ++j) in.D(i, j) = r.f64("D");
    for (int i = 0; i < C; ++i) in.lower(i) = r.f64("lower");
    for (int i = 0; i < C; ++i) in.upper(i) = r.f64("upper");
    for (auto& ws : in.warm) {
      ws.variables = count(r.i32("warm.variables"), n, s, "warm-start size");
      ws.num_active = count(r.i32("warm.num_active"), C, s, "warm-start row count");
      for (int k = 0; k < C; ++k) {
        const int v = r.i32("warm.row");
        if (k < ws.num_active) ws.row[static_cast<std::size_t>(k)] = count(v, C - 1, s, "warm-start row");
      }
      for (int k = 0; k < C; ++k) {
        const int v = r.i32("warm.upper");
        if (k < ws.num_active) ws.upper[static_cast<std::size_t>(k)] = v != 0;
      }
    }
    auto& res = in.result;
    for (int j = 0; j < n; ++j) res.x(j) = r.f64("x");
    res.status = status(r.i32("status"), s);
    res.failed_level = r.i32("failed_level");
    if (res.failed_level < -1 || res.failed_level >= L)
      r.fail("instance " + std::to_string(s) + ": bad failed_level " + std::to_string(res.failed_level));
    for (auto& l : res.levels) {
      l.status = status(r.i32("level status"), s);
      l.rank = count(r.i32("rank"), n, s, "rank");
      l.null_dim = count(r.i32("null_dim"), n, s, "null_dim");
      l.variables = count(r.i32("variables"), n, s, "variables");
      l.iterations = r.i32("iterations");
      l.num_active = count(r.i32("num_active"), C, s, "active row count");
      l.constraints_dropped = r.i32("constraints_dropped") != 0;
      l.slack_used = r.i32("slack_used") != 0;
      l.residual = r.f64("residual");
      l.objective = r.f64("objective");
      l.violation = r.f64("violation");
      l.time_us = r.f64("time_us");
      for (int k = 0; k < C; ++k) {
        const int v = r.i32("active_row");
        if (k < l.num_active) l.active_row[static_cast<std::size_t>(k)] = count(v, C - 1, s, "active row");
      }
      for (int k = 0; k < C; ++k) {
        const int v = r.i32("active_upper");
        if (k < l.num_active) l.active_upper[static_cast<std::size_t>(k)] = v != 0;
      }
    }
  }
  if (info_out) *info_out = info;
  return out;
}

template <class Wbc>
void writeProblemFile(const std::string& path, const ProblemInstance<Wbc>* instances,
                      std::size_t count, const HqpSettings& settings, const std::string& source) {
  const std::string data = encodeProblemFile<Wbc>(instances, count, settings, source);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw ProblemFileError(path + ": cannot open for writing");
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.close();
  if (!out) throw ProblemFileError(path + ": write error");
}

template <class Wbc>
std::vector<ProblemInstance<Wbc>> readProblemFile(const std::string& path,
                                                  ProblemFileInfo* info = nullptr) {
  return decodeProblemFile<Wbc>(problem_file::readWholeFile(path), path, info);
}

}  // namespace hqp
