#pragma once
// Writes identified parameters as YAML for the controller's friction
// compensation (eq. 7, include/tasks/friction_model.hpp):
//
//   friction:                 # one entry per joint, by URDF joint name
//     l_knee: {coulomb: 4.98, viscous: 2.01, dq_star: 0.01}
//   base_parameters:          # for the record: value, standard deviation, definition
//     - {value: 1.23, std: 0.01, definition: "l_knee_link.Izz + ..."}
//
// `friction` is a map keyed by joint name with the fields of
// tasks::JointFriction. Numbers are written with 17 significant digits (exact
// round trip).
//
// The controller's own configuration (robots/walker3/controller.yaml, read by
// tasks::loadControllerConfig, which requires every key and rejects unknown
// ones) keeps F_c, F_v and q̇* per joint under `joint_control: joints:` as
// one-line flow maps. controllerYamlWithFriction() rewrites only the `coulomb`
// and `viscous` values of those lines, so comments and every other setting stay
// as they are and the result loads directly; controllerYamlDqStar() reads the
// q̇* the controller uses, so that the fit uses the same eq. 7.
// Offline code: allocates and throws std::runtime_error.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hqp::ident {

struct IdentifiedFriction {
  std::string joint;
  double coulomb = 0.0;
  double viscous = 0.0;
  double dq_star = 0.0;
};

struct IdentifiedBaseParameter {
  double value = 0.0;
  double std = 0.0;
  std::string definition;
};

namespace detail {
inline std::string yamlNumber(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}
// Double-quoted YAML scalar.
inline std::string yamlQuoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}
}  // namespace detail

inline void writeParametersYaml(std::ostream& out, const std::string& comment,
                                const std::vector<IdentifiedFriction>& friction,
                                const std::vector<IdentifiedBaseParameter>& base = {}) {
  if (!comment.empty()) out << "# " << comment << "\n";
  out << "friction:\n";
  for (const IdentifiedFriction& f : friction) {
    out << "  " << f.joint << ": {coulomb: " << detail::yamlNumber(f.coulomb)
        << ", viscous: " << detail::yamlNumber(f.viscous)
        << ", dq_star: " << detail::yamlNumber(f.dq_star) << "}\n";
  }
  if (!base.empty()) {
    out << "base_parameters:\n";
    for (const IdentifiedBaseParameter& b : base) {
      out << "  - {value: " << detail::yamlNumber(b.value) << ", std: " << detail::yamlNumber(b.std)
          << ", definition: " << detail::yamlQuoted(b.definition) << "}\n";
    }
  }
}

namespace detail {

inline std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}
inline int indentation(const std::string& s) {
  const auto b = s.find_first_not_of(' ');
  return b == std::string::npos ? -1 : static_cast<int>(b);
}
// Position of the value of `field:` inside a flow map line, or npos.
inline std::size_t fieldValue(const std::string& line, const std::string& field) {
  std::size_t pos = 0;
  while ((pos = line.find(field + ":", pos)) != std::string::npos) {
    if (pos > 0 && (line[pos - 1] == '{' || line[pos - 1] == ' ' || line[pos - 1] == ',')) {
      return pos + field.size() + 1;
    }
    pos += field.size();
  }
  return std::string::npos;
}

// Lines of the `joint_control: joints:` block, keyed by joint name: calls f(line, name).
template <class F>
void forEachControllerJoint(std::vector<std::string>& lines, F&& f) {
  std::size_t k = 0;
  while (k < lines.size() && trimmed(lines[k]).rfind("joint_control:", 0) != 0) ++k;
  if (k == lines.size() || indentation(lines[k]) != 0) {
    throw std::runtime_error("controller YAML: no top-level 'joint_control:'");
  }
  for (++k; k < lines.size(); ++k) {
    const std::string t = trimmed(lines[k]);
    if (t.empty() || t[0] == '#') continue;
    if (indentation(lines[k]) == 0) break;
    if (t.rfind("joints:", 0) == 0) {
      const int indent = indentation(lines[k]);
      for (++k; k < lines.size(); ++k) {
        const std::string u = trimmed(lines[k]);
        if (u.empty() || u[0] == '#') continue;
        if (indentation(lines[k]) <= indent) return;
        f(lines[k], u.substr(0, u.find(':')));
      }
      return;
    }
  }
  throw std::runtime_error("controller YAML: no 'joints:' under 'joint_control:'");
}

inline std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

}  // namespace detail

// q̇* of each joint (in the order of `joints`) from a controller YAML.
inline std::vector<double> controllerYamlDqStar(const std::string& text,
                                                const std::vector<std::string>& joints) {
  std::vector<std::string> lines = detail::splitLines(text);
  std::vector<double> dq_star(joints.size(), -1.0);
  detail::forEachControllerJoint(lines, [&](std::string& line, const std::string& name) {
    const auto it = std::find(joints.begin(), joints.end(), name);
    if (it == joints.end()) return;
    const std::size_t v = detail::fieldValue(line, "dq_star");
    if (v == std::string::npos) throw std::runtime_error("controller YAML: joint " + name + " has no dq_star");
    dq_star[static_cast<std::size_t>(it - joints.begin())] = std::strtod(line.c_str() + v, nullptr);
  });
  for (std::size_t j = 0; j < joints.size(); ++j) {
    if (!(dq_star[j] >= 0.0)) throw std::runtime_error("controller YAML: no entry for joint " + joints[j]);
  }
  return dq_star;
}

// The controller YAML with `coulomb` and `viscous` (and `dq_star` too with
// `with_dq_star`, when q̇* was estimated) replaced by the identified values
// (negative estimates, which the controller rejects, become 0 and are reported
// in `warnings`). Every identified joint must be present.
inline std::string controllerYamlWithFriction(const std::string& text,
                                              const std::vector<IdentifiedFriction>& friction,
                                              std::vector<std::string>* warnings = nullptr,
                                              bool with_dq_star = false) {
  std::vector<std::string> lines = detail::splitLines(text);
  std::vector<bool> done(friction.size(), false);
  detail::forEachControllerJoint(lines, [&](std::string& line, const std::string& name) {
    for (std::size_t j = 0; j < friction.size(); ++j) {
      if (friction[j].joint != name) continue;
      for (const char* field : {"coulomb", "viscous", "dq_star"}) {
        const std::string f(field);
        if (f == "dq_star" && !with_dq_star) continue;
        double x = f == "coulomb" ? friction[j].coulomb : (f == "viscous" ? friction[j].viscous : friction[j].dq_star);
        if (x < 0.0) {
          if (warnings) warnings->push_back(name + "." + field + " identified as " + detail::yamlNumber(x) + ", written as 0");
          x = 0.0;
        }
        const std::size_t v = detail::fieldValue(line, field);
        if (v == std::string::npos) throw std::runtime_error("controller YAML: joint " + name + " has no " + field);
        std::size_t end = line.find_first_of(",}", v);
        if (end == std::string::npos) end = line.size();
        char buf[32];
        std::snprintf(buf, sizeof buf, " %.6g", x);
        line.replace(v, end - v, buf);
      }
      done[j] = true;
    }
  });
  for (std::size_t j = 0; j < friction.size(); ++j) {
    if (!done[j]) throw std::runtime_error("controller YAML: no entry for joint " + friction[j].joint);
  }
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

}  // namespace hqp::ident
