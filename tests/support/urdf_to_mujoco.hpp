#pragma once
// Load a URDF into MuJoCo 2.2.2 as a pure rigid-body model for cross-checks.
//
// MuJoCo's URDF defaults do not match a rigid-body-dynamics reading of the file
// (docs: docs/simulation.md, MuJoCo 2.2 facts), so before compiling we rewrite the text:
//  - one <mujoco><compiler .../></mujoco> element: fusestatic="false" keeps every link as a
//    body with its own name (and mass), inertiafromgeom="false" keeps massless links
//    massless, balanceinertia="false" keeps the URDF inertias as written;
//  - for a floating base, <link name="world"/> plus a `floating` joint world -> root link
//    (MuJoCo makes it a free joint), unless the file already has a world link.
// The text goes through MuJoCo's virtual file system, so nothing is written to disk.
// After loading, gravity is set to (0, 0, -9.81), armature to 0 and every constraint and
// passive force is disabled so that only M, C and G remain.
//
// Inertia accuracy: MuJoCo stores a body inertia as principal moments plus a principal frame
// (body_inertia, body_iquat) from its own iterative 3x3 eigen-solver, which is only accurate
// to ~1e-7 relative for tensors with products of inertia (measured on
// tests/mujoco/full_inertia_tree.urdf: slider Izz 0.008 came back as 0.0079999992). By default
// the loader therefore re-derives every body's principal axes from the URDF tensor with
// Eigen's self-adjoint eigen-solver (exact to round-off) and writes them into the model; all
// dynamics stays MuJoCo's. Pass exact_inertia = false to keep MuJoCo's own values.

#include <mujoco/mujoco.h>

#include <Eigen/Dense>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hqp::test {

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDataDeleter>;

namespace urdf_detail {

// Copy of `text` with every XML comment blanked out (same length, so positions stay valid).
inline std::string blankComments(const std::string& text) {
  std::string out = text;
  std::size_t pos = 0;
  while ((pos = out.find("<!--", pos)) != std::string::npos) {
    const std::size_t end = out.find("-->", pos + 4);
    const std::size_t stop = (end == std::string::npos) ? out.size() : end + 3;
    for (std::size_t i = pos; i < stop; ++i) {
      if (out[i] != '\n') out[i] = ' ';
    }
    pos = stop;
  }
  return out;
}

// Value of attribute `attr` inside the tag that starts at `tag_begin`; empty when absent.
inline std::string attribute(const std::string& text, std::size_t tag_begin, const std::string& attr) {
  const std::size_t tag_end = text.find('>', tag_begin);
  std::size_t pos = tag_begin;
  while (true) {
    pos = text.find(attr, pos);
    if (pos == std::string::npos || pos >= tag_end) return {};
    const bool word_start = pos > 0 && (text[pos - 1] == ' ' || text[pos - 1] == '\t' ||
                                        text[pos - 1] == '\n' || text[pos - 1] == '\r');
    std::size_t eq = pos + attr.size();
    while (eq < tag_end && (text[eq] == ' ' || text[eq] == '\t' || text[eq] == '\n')) ++eq;
    if (word_start && eq < tag_end && text[eq] == '=') {
      std::size_t q = eq + 1;
      while (q < tag_end && text[q] != '"' && text[q] != '\'') ++q;
      if (q >= tag_end) return {};
      const std::size_t close = text.find(text[q], q + 1);
      return text.substr(q + 1, close - q - 1);
    }
    pos += attr.size();
  }
}

// Start positions of every element `<name` (followed by whitespace, '/' or '>').
inline std::vector<std::size_t> elements(const std::string& text, const std::string& name) {
  std::vector<std::size_t> out;
  const std::string open = "<" + name;
  std::size_t pos = 0;
  while ((pos = text.find(open, pos)) != std::string::npos) {
    const char c = pos + open.size() < text.size() ? text[pos + open.size()] : '>';
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '/' || c == '>') out.push_back(pos);
    pos += open.size();
  }
  return out;
}

}  // namespace urdf_detail

// The root link of a URDF: the one link that is no joint's child.
inline std::string urdfRootLink(const std::string& urdf_text) {
  const std::string text = urdf_detail::blankComments(urdf_text);
  std::vector<std::string> links, children;
  for (std::size_t p : urdf_detail::elements(text, "link")) links.push_back(urdf_detail::attribute(text, p, "name"));
  for (std::size_t p : urdf_detail::elements(text, "child")) children.push_back(urdf_detail::attribute(text, p, "link"));
  std::string root;
  for (const auto& l : links) {
    bool is_child = false;
    for (const auto& c : children) is_child = is_child || c == l;
    if (!is_child) {
      if (!root.empty()) throw std::runtime_error("URDF has several root links: " + root + ", " + l);
      root = l;
    }
  }
  if (root.empty()) throw std::runtime_error("URDF has no root link");
  return root;
}

// The URDF text rewritten for MuJoCo (see the file comment). `mesh_dir` is where relative
// mesh paths resolve (the URDF's own directory); empty leaves MuJoCo's default.
inline std::string prepareUrdfForMujoco(const std::string& urdf_text, bool floating,
                                        const std::string& mesh_dir = {}) {
  std::string text = urdf_text;
  // Drop any <mujoco> element of the file: MuJoCo allows only one and we need ours.
  {
    const std::string blank = urdf_detail::blankComments(text);
    const auto found = urdf_detail::elements(blank, "mujoco");
    for (auto it = found.rbegin(); it != found.rend(); ++it) {
      const std::size_t tag_end = blank.find('>', *it);
      std::size_t stop = tag_end + 1;
      if (blank[tag_end - 1] != '/') {
        const std::size_t close = blank.find("</mujoco>", tag_end);
        if (close == std::string::npos) throw std::runtime_error("unterminated <mujoco> in URDF");
        stop = close + std::strlen("</mujoco>");
      }
      text.erase(*it, stop - *it);
    }
  }
  const std::string blank = urdf_detail::blankComments(text);
  const auto robots = urdf_detail::elements(blank, "robot");
  if (robots.empty()) throw std::runtime_error("not a URDF: no <robot> element");
  const std::size_t insert_at = blank.find('>', robots.front()) + 1;

  std::ostringstream extra;
  extra << "\n  <mujoco><compiler fusestatic=\"false\" inertiafromgeom=\"false\""
        << " balanceinertia=\"false\" discardvisual=\"true\" strippath=\"false\"";
  if (!mesh_dir.empty()) extra << " meshdir=\"" << mesh_dir << "\"";
  extra << "/></mujoco>\n";

  const std::string root = urdfRootLink(text);
  if (floating && root != "world") {
    extra << "  <link name=\"world\"/>\n"
          << "  <joint name=\"hqp_test_floating_base\" type=\"floating\">\n"
          << "    <parent link=\"world\"/><child link=\"" << root << "\"/>\n"
          << "    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
          << "  </joint>\n";
  }
  text.insert(insert_at, extra.str());
  return text;
}

// The <inertial> of one URDF link, in the link frame.
struct UrdfInertial {
  std::string link;
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the CoM, link axes
};

namespace urdf_detail {

inline Eigen::Vector3d vec3(const std::string& text) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  std::istringstream in(text);
  in >> v.x() >> v.y() >> v.z();
  return v;
}

inline double number(const std::string& text) { return text.empty() ? 0.0 : std::stod(text); }

// URDF rpy: fixed-axis roll about x, then pitch about y, then yaw about z.
inline Eigen::Matrix3d rpyToRotation(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace urdf_detail

// Every <inertial> of a URDF, with its tensor rotated into the link frame.
inline std::vector<UrdfInertial> urdfInertials(const std::string& urdf_text) {
  const std::string text = urdf_detail::blankComments(urdf_text);
  std::vector<UrdfInertial> out;
  for (std::size_t p : urdf_detail::elements(text, "link")) {
    const std::size_t tag_end = text.find('>', p);
    if (text[tag_end - 1] == '/') continue;  // <link .../>: no inertial
    const std::size_t link_end = text.find("</link>", tag_end);
    const std::string body = text.substr(tag_end, link_end - tag_end);
    const auto inertials = urdf_detail::elements(body, "inertial");
    if (inertials.empty()) continue;
    const std::size_t ibeg = inertials.front();
    const std::string in = body.substr(ibeg, body.find("</inertial>", ibeg) - ibeg);
    UrdfInertial u;
    u.link = urdf_detail::attribute(text, p, "name");
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    const auto origins = urdf_detail::elements(in, "origin");
    if (!origins.empty()) {
      u.com = urdf_detail::vec3(urdf_detail::attribute(in, origins.front(), "xyz"));
      R = urdf_detail::rpyToRotation(urdf_detail::vec3(urdf_detail::attribute(in, origins.front(), "rpy")));
    }
    const auto masses = urdf_detail::elements(in, "mass");
    if (!masses.empty()) u.mass = urdf_detail::number(urdf_detail::attribute(in, masses.front(), "value"));
    const auto tensors = urdf_detail::elements(in, "inertia");
    if (!tensors.empty()) {
      auto get = [&](const char* a) {
        return urdf_detail::number(urdf_detail::attribute(in, tensors.front(), a));
      };
      Eigen::Matrix3d I;
      I << get("ixx"), get("ixy"), get("ixz"), get("ixy"), get("iyy"), get("iyz"), get("ixz"),
          get("iyz"), get("izz");
      u.inertia = R * I * R.transpose();
    }
    out.push_back(u);
  }
  return out;
}

// Replace MuJoCo's principal inertias and axes by an exact eigen-decomposition of the URDF
// tensors (see the file comment). Every URDF link with mass is a MuJoCo body of the same name.
inline void setExactInertias(mjModel* m, const std::string& urdf_text) {
  for (const UrdfInertial& u : urdfInertials(urdf_text)) {
    const int b = mj_name2id(m, mjOBJ_BODY, u.link.c_str());
    if (b < 0) continue;  // e.g. a "world" link
    if (std::abs(m->body_mass[b] - u.mass) > 1e-12 * (1.0 + u.mass)) {
      throw std::runtime_error("mass of " + u.link + " differs between URDF and MuJoCo");
    }
    if (m->body_sameframe[b]) {
      // MuJoCo then uses the body frame as the inertial frame (and may treat the body as
      // "simple"), so its principal axes are the link axes: the tensor must be diagonal there
      // and MuJoCo keeps it exactly. Leave it alone, but make sure.
      const Eigen::Vector3d diag(m->body_inertia + 3 * b);
      const Eigen::Matrix3d I_mj = diag.asDiagonal();
      if ((I_mj - u.inertia).cwiseAbs().maxCoeff() > 1e-15 * u.inertia.cwiseAbs().maxCoeff()) {
        throw std::runtime_error("inertia of " + u.link + " is not diagonal in its MuJoCo frame");
      }
      continue;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(u.inertia);
    Eigen::Matrix3d V = eig.eigenvectors();
    if (V.determinant() < 0) V.col(2) = -V.col(2);  // a proper rotation
    const Eigen::Quaterniond q(V);
    for (int k = 0; k < 3; ++k) {
      m->body_inertia[3 * b + k] = eig.eigenvalues()[k];
      m->body_ipos[3 * b + k] = u.com[k];
    }
    m->body_iquat[4 * b + 0] = q.w();
    m->body_iquat[4 * b + 1] = q.x();
    m->body_iquat[4 * b + 2] = q.y();
    m->body_iquat[4 * b + 3] = q.z();
  }
}

// Settings that leave MuJoCo with nothing but rigid-body dynamics.
inline void configureForRigidBodyDynamics(mjModel* m) {
  m->opt.gravity[0] = 0.0;
  m->opt.gravity[1] = 0.0;
  m->opt.gravity[2] = -9.81;
  m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_EQUALITY | mjDSBL_FRICTIONLOSS | mjDSBL_LIMIT |
                         mjDSBL_CONTACT | mjDSBL_PASSIVE | mjDSBL_ACTUATION;
  for (int i = 0; i < m->nv; ++i) m->dof_armature[i] = 0.0;
}

// Compile URDF text into a MuJoCo model; throws std::runtime_error with MuJoCo's message.
inline MjModelPtr loadUrdfStringIntoMujoco(const std::string& urdf_text, bool floating,
                                           const std::string& mesh_dir = {},
                                           bool exact_inertia = true) {
  const std::string text = prepareUrdfForMujoco(urdf_text, floating, mesh_dir);
  // mjVFS is ~2 MB: keep it off the stack.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "hqp_mujoco_crosscheck.urdf";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(text.size())) != 0) {
    throw std::runtime_error("mj_makeEmptyFileVFS failed");
  }
  const int id = mj_findFileVFS(vfs.get(), name);
  std::memcpy(vfs->filedata[id], text.data(), text.size());
  char error[1024] = {0};
  mjModel* m = mj_loadXML(name, vfs.get(), error, sizeof(error));
  mj_deleteVFS(vfs.get());
  if (m == nullptr) throw std::runtime_error(std::string("MuJoCo failed to load the URDF: ") + error);
  MjModelPtr model(m);
  configureForRigidBodyDynamics(m);
  if (exact_inertia) setExactInertias(m, urdf_text);
  return model;
}

inline MjModelPtr loadUrdfFileIntoMujoco(const std::string& path, bool floating,
                                         bool exact_inertia = true) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read URDF " + path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? std::string(".") : path.substr(0, slash);
  return loadUrdfStringIntoMujoco(buffer.str(), floating, dir, exact_inertia);
}

}  // namespace hqp::test
