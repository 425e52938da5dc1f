#pragma once
// Writes the Model as the constexpr header of docs/generated-model.md.
// Output depends only on the model (no paths, no dates), so the same robot
// always gives the same bytes.

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "urdf2model/error.hpp"
#include "urdf2model/tree_model.hpp"

namespace hqp::tools {

// Name -> C++ identifier: characters outside [A-Za-z0-9_] become '_', a
// leading digit gets a '_' in front, a keyword gets a '_' appended.
inline std::string sanitize(const std::string& name) {
  static const std::set<std::string> kKeywords = {
      "alignas", "alignof", "and", "and_eq", "asm", "auto", "bitand", "bitor", "bool", "break",
      "case", "catch", "char", "char16_t", "char32_t", "class", "compl", "const", "constexpr",
      "const_cast", "continue", "decltype", "default", "delete", "do", "double", "dynamic_cast",
      "else", "enum", "explicit", "export", "extern", "false", "float", "for", "friend", "goto",
      "if", "inline", "int", "long", "mutable", "namespace", "new", "noexcept", "not", "not_eq",
      "nullptr", "operator", "or", "or_eq", "private", "protected", "public", "register",
      "reinterpret_cast", "return", "short", "signed", "sizeof", "static", "static_assert",
      "static_cast", "struct", "switch", "template", "this", "thread_local", "throw", "true", "try",
      "typedef", "typeid", "typename", "union", "unsigned", "using", "virtual", "void", "volatile",
      "wchar_t", "while", "xor", "xor_eq"};
  std::string id;
  for (unsigned char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    id += ok ? static_cast<char>(c) : '_';
  }
  if (id.empty() || (id[0] >= '0' && id[0] <= '9')) id = "_" + id;
  if (kKeywords.count(id)) id += "_";
  return id;
}

// Checks that a namespace option is `ident` or `ident::ident...`.
inline bool isNamespace(const std::string& ns) {
  std::size_t start = 0;
  while (true) {
    const std::size_t end = ns.find("::", start);
    const std::string part = ns.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (part.empty() || sanitize(part) != part) return false;
    if (end == std::string::npos) return true;
    start = end + 2;
  }
}

namespace detail {

// A C string literal; octal escapes end after three digits, so they cannot
// swallow a following character.
inline std::string literal(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c >= 0x7f || c == '?') {   // '?' avoids trigraphs
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

inline std::string num(double x) {
  if (std::isinf(x)) {
    return x > 0 ? "std::numeric_limits<double>::infinity()" : "-std::numeric_limits<double>::infinity()";
  }
  if (x == 0) return "0.0";   // also folds -0 into 0
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  std::string s = buf;
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

template <class V>
std::string list(const V& v, int n) {
  std::string s = "{";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "}";
}

inline std::string rot(const Eigen::Matrix3d& R) {
  std::array<double, 9> a{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a[3 * i + j] = R(i, j);   // row-major
  }
  return list(a, 9);
}

// One identifier per name; two names with the same identifier are an error.
// `scope` is the enclosing struct, whose name a member may not take.
inline std::vector<std::pair<std::string, int>> identifiers(const std::vector<std::string>& names,
                                                            const std::string& kind, const std::string& scope) {
  std::map<std::string, std::string> seen;   // identifier -> name
  std::vector<std::pair<std::string, int>> out;
  for (int i = 0; i < static_cast<int>(names.size()); ++i) {
    std::string id = sanitize(names[i]);
    if (id == scope) id += "_";
    auto it = seen.find(id);
    if (it != seen.end()) {
      std::string a = it->second, b = names[i];
      if (b < a) std::swap(a, b);
      throw UrdfError(kind + " " + quote(b) + ": name collides with " + kind + " " + quote(a) +
                      " after sanitization (both become " + quote(id) + ")");
    }
    seen[id] = names[i];
    out.emplace_back(id, i);
  }
  return out;
}

}  // namespace detail

inline std::string writeHeader(const Model& m, const std::string& ns) {
  using detail::list;
  using detail::literal;
  using detail::num;
  const int fb = m.floating_base ? 1 : 0;
  std::vector<std::string> frame_names, joint_names;
  for (const Frame& f : m.frames) frame_names.push_back(f.name);
  for (std::size_t i = fb; i < m.bodies.size(); ++i) joint_names.push_back(m.bodies[i].joint);
  const auto frame_ids = detail::identifiers(frame_names, "link", "Frames");
  const auto joint_ids = detail::identifiers(joint_names, "joint", "Joints");

  std::ostringstream o;
  o << "// Generated by hqp_urdf2model from the URDF of robot " << quote(m.name) << ". Do not edit.\n"
    << "// Format: docs/generated-model.md. Types: include/model/robot_description.hpp.\n"
    << "#pragma once\n\n"
    << "#include <array>\n#include <limits>\n#include <string_view>\n\n"
    << "#include \"model/robot_description.hpp\"\n\n"
    << "namespace " << ns << " {\n\n"
    << "struct Robot {\n"
    << "  static constexpr const char* name = " << literal(m.name) << ";\n"
    << "  static constexpr bool floating_base = " << (m.floating_base ? "true" : "false") << ";\n"
    << "  static constexpr int nb = " << m.bodies.size() << ";\n"
    << "  static constexpr int nj = " << m.nj << ";\n"
    << "  static constexpr int nq = " << m.nq << ";\n"
    << "  static constexpr int nv = " << m.nv << ";\n"
    << "  static constexpr int nframes = " << m.frames.size() << ";\n"
    << "  static constexpr double total_mass = " << num(m.total_mass) << ";\n\n";

  o << "  // name, joint, type, parent, idx_q, idx_v, xyz, rot, axis, mass, com, inertia\n"
    << "  // (xx yy zz xy xz yz), lower, upper, velocity, effort, damping, friction\n"
    << "  static constexpr std::array<hqp::model::BodyDesc, nb> bodies = {{\n";
  for (std::size_t i = 0; i < m.bodies.size(); ++i) {
    const Body& b = m.bodies[i];
    const Eigen::Matrix3d& I = b.inertia;
    const std::array<double, 6> in6 = {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)};
    o << "      // " << i << "\n"
      << "      {" << literal(b.link) << ", " << literal(b.joint) << ", hqp::model::JointType::" << b.type
      << ", " << b.parent << ", " << b.idx_q << ", " << b.idx_v << ",\n"
      << "       " << list(b.placement.p, 3) << ",\n"
      << "       " << detail::rot(b.placement.R) << ",\n"
      << "       " << list(b.axis, 3) << ",\n"
      << "       " << num(b.mass) << ", " << list(b.com, 3) << ",\n"
      << "       " << list(in6, 6) << ",\n"
      << "       " << num(b.lower) << ", " << num(b.upper) << ", " << num(b.velocity) << ", "
      << num(b.effort) << ", " << num(b.damping) << ", " << num(b.friction) << "},\n";
  }
  o << "  }};\n\n";

  o << "  // name, body, xyz, rot (frame i < nb is body i's own link)\n"
    << "  static constexpr std::array<hqp::model::FrameDesc, nframes> frames = {{\n";
  for (std::size_t i = 0; i < m.frames.size(); ++i) {
    const Frame& f = m.frames[i];
    o << "      {" << literal(f.name) << ", " << f.body << ", " << list(f.placement.p, 3) << ",\n"
      << "       " << detail::rot(f.placement.R) << "},\n";
  }
  o << "  }};\n\n";

  o << "  static constexpr int frameIndex(std::string_view n) { return hqp::model::indexOf(frames, n); }\n"
    << "  static constexpr int bodyIndex(std::string_view n) { return hqp::model::indexOf(bodies, n); }\n"
    << "  static constexpr int jointIndex(std::string_view n) {\n"
    << "    for (int i = 0; i < nj; ++i) {\n"
    << "      if (std::string_view(bodies[i + (floating_base ? 1 : 0)].joint) == n) return i;\n"
    << "    }\n"
    << "    return -1;\n"
    << "  }\n\n";

  o << "  struct Frames {\n";
  for (const auto& [id, i] : frame_ids) o << "    static constexpr int " << id << " = " << i << ";\n";
  o << "  };\n"
    << "  struct Joints {\n";
  for (const auto& [id, i] : joint_ids) o << "    static constexpr int " << id << " = " << i << ";\n";
  o << "  };\n"
    << "};\n\n"
    << "}  // namespace " << ns << "\n";
  return o.str();
}

}  // namespace hqp::tools
