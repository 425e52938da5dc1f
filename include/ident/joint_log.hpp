#pragma once
// Measured joint data for identification, read from CSV:
//   time,q_<joint>,…,tau_<joint>,…   (one header line, then one line per sample)
// Columns are found by name (any order, extra columns ignored); lines starting
// with '#' are comments. τ is the joint torque (N·m), or the motor current
// already multiplied by the torque constant and gear ratio. Sampling must be
// uniform. Every defect is reported with the line and column it was found in.
// Offline code: allocates and throws std::runtime_error.

#include <cmath>
#include <cstdlib>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace hqp::ident {

struct JointLog {
  std::vector<std::string> joints;  // n joint names, in model order
  Eigen::VectorXd time;             // N (s)
  Eigen::MatrixXd q;                // N × n (rad or m)
  Eigen::MatrixXd tau;              // N × n (N·m or N)
  double dt() const { return (time[time.size() - 1] - time[0]) / static_cast<double>(time.size() - 1); }
};

namespace detail {

inline std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream ss(line);
  while (std::getline(ss, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r");
    const auto e = cell.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? std::string() : cell.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

}  // namespace detail

// Reads the columns `time` (or `t`), `q_<name>` and `tau_<name>` for every
// joint name given. `source` names the input in error messages.
inline JointLog readJointLog(std::istream& in, const std::vector<std::string>& joints,
                             const std::string& source = "log") {
  const auto fail = [&](const std::string& what) {
    throw std::runtime_error(source + ": " + what);
  };
  std::string line;
  int line_no = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#') continue;
    header = detail::splitCsv(line);
    break;
  }
  if (header.empty()) fail("empty file (expected a header line)");
  const auto column = [&](const std::string& name) {
    for (std::size_t c = 0; c < header.size(); ++c) {
      if (header[c] == name) return static_cast<int>(c);
    }
    return -1;
  };
  int c_time = column("time");
  if (c_time < 0) c_time = column("t");
  std::string missing;
  if (c_time < 0) missing += " time";
  std::vector<int> c_q, c_tau;
  for (const std::string& j : joints) {
    c_q.push_back(column("q_" + j));
    c_tau.push_back(column("tau_" + j));
    if (c_q.back() < 0) missing += " q_" + j;
    if (c_tau.back() < 0) missing += " tau_" + j;
  }
  if (!missing.empty()) fail("missing column(s):" + missing);

  std::vector<double> t;
  std::vector<std::vector<double>> qs, taus;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) {
      continue;
    }
    const std::vector<std::string> cells = detail::splitCsv(line);
    if (cells.size() != header.size()) {
      fail("line " + std::to_string(line_no) + ": " + std::to_string(cells.size()) +
           " fields, the header has " + std::to_string(header.size()));
    }
    const auto value = [&](int c) {
      const std::string& s = cells[static_cast<std::size_t>(c)];
      char* end = nullptr;
      const double x = std::strtod(s.c_str(), &end);
      if (s.empty() || end == s.c_str() || *end != '\0') {
        fail("line " + std::to_string(line_no) + ", column '" + header[static_cast<std::size_t>(c)] +
             "': not a number: '" + s + "'");
      }
      if (!std::isfinite(x)) {
        fail("line " + std::to_string(line_no) + ", column '" + header[static_cast<std::size_t>(c)] +
             "': non-finite value '" + s + "'");
      }
      return x;
    };
    t.push_back(value(c_time));
    qs.emplace_back();
    taus.emplace_back();
    for (std::size_t j = 0; j < joints.size(); ++j) {
      qs.back().push_back(value(c_q[j]));
      taus.back().push_back(value(c_tau[j]));
    }
  }
  const std::size_t N = t.size();
  if (N < 10) fail("only " + std::to_string(N) + " samples (need at least 10)");
  JointLog log;
  log.joints = joints;
  log.time.resize(static_cast<Eigen::Index>(N));
  log.q.resize(static_cast<Eigen::Index>(N), static_cast<Eigen::Index>(joints.size()));
  log.tau.resize(log.q.rows(), log.q.cols());
  for (std::size_t k = 0; k < N; ++k) {
    log.time[static_cast<Eigen::Index>(k)] = t[k];
    for (std::size_t j = 0; j < joints.size(); ++j) {
      log.q(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) = qs[k][j];
      log.tau(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) = taus[k][j];
    }
  }
  const double dt = log.dt();
  if (!(dt > 0.0)) fail("time does not increase");
  for (std::size_t k = 1; k < N; ++k) {
    const double step = t[k] - t[k - 1];
    if (!(step > 0.0) || std::abs(step - dt) > 0.01 * dt) {
      fail("non-uniform sampling at sample " + std::to_string(k) + " (step " +
           std::to_string(step) + " s, mean " + std::to_string(dt) + " s); resample first");
    }
  }
  return log;
}

// Torque prediction on a log, as CSV: time, tau_<joint>… (measured), tau_id_<joint>…
// (identified model), tau_cad_<joint>… (CAD model); the three matrices are N × n.
inline void writeTorquePrediction(std::ostream& out, const Eigen::VectorXd& time,
                                  const std::vector<std::string>& joints, const Eigen::MatrixXd& measured,
                                  const Eigen::MatrixXd& identified, const Eigen::MatrixXd& cad) {
  out << "time";
  for (const char* s : {"tau_", "tau_id_", "tau_cad_"}) {
    for (const std::string& j : joints) out << "," << s << j;
  }
  out << "\n";
  for (Eigen::Index k = 0; k < time.size(); ++k) {
    out << time[k];
    for (const Eigen::MatrixXd* m : {&measured, &identified, &cad}) {
      for (Eigen::Index j = 0; j < m->cols(); ++j) out << "," << (*m)(k, j);
    }
    out << "\n";
  }
}

}  // namespace hqp::ident
