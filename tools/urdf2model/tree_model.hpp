#pragma once
// From the scanned URDF to the bodies and frames of docs/generated-model.md:
// fixed joints fused, bodies numbered depth-first with siblings sorted by
// joint name, every inertia checked and expressed in its body frame.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "urdf2model/error.hpp"
#include "urdf2model/xml_scan.hpp"

namespace hqp::tools {

struct Transform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Transform operator*(const Transform& o) const { return {R * o.R, p + R * o.p}; }
};

// URDF convention: fixed axes X (roll), then Y (pitch), then Z (yaw), R = Rz Ry Rx.
inline Eigen::Matrix3d rpyToMatrix(const Vec3& rpy) {
  const double cr = std::cos(rpy[0]), sr = std::sin(rpy[0]);
  const double cp = std::cos(rpy[1]), sp = std::sin(rpy[1]);
  const double cy = std::cos(rpy[2]), sy = std::sin(rpy[2]);
  Eigen::Matrix3d R;
  R << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,
       sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,
       -sp,     cp * sr,                cp * cr;
  return R;
}

inline Transform originTransform(const Vec3& xyz, const Vec3& rpy) {
  return {rpyToMatrix(rpy), Eigen::Vector3d(xyz[0], xyz[1], xyz[2])};
}

struct Body {
  std::string link, joint;
  std::string type;   // "Free", "Revolute", "Continuous", "Prismatic"
  int parent = -1;
  int idx_q = 0, idx_v = 0;
  Transform placement;                   // body frame in the parent body frame at q = 0
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();   // about the CoM, body axes
  double lower = 0, upper = 0, velocity = 0, effort = 0, damping = 0, friction = 0;
};

struct Frame {
  std::string name;
  int body = -1;
  Transform placement;   // in the body frame
};

struct Model {
  std::string name;
  bool floating_base = false;
  int nj = 0, nq = 0, nv = 0;
  double total_mass = 0;
  std::vector<Body> bodies;
  std::vector<Frame> frames;
};

struct Options {
  bool floating_base = false;
  bool frames_given = false;
  std::vector<std::string> frames;
};

namespace detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Links of one body (the body's own link first), each with its placement in the body frame.
struct Group {
  std::vector<std::pair<std::string, Transform>> links;
  std::vector<std::pair<int, Transform>> movable;   // (joint, joint frame in the body frame)
};

inline void collectGroup(const RawRobot& r, const std::string& link, const Transform& T, Group& g) {
  g.links.emplace_back(link, T);
  auto it = r.child_joints.find(link);
  if (it == r.child_joints.end()) return;
  for (int k : it->second) {   // sorted by joint name
    const RawJoint& j = r.joints[k];
    const Transform Tj = T * originTransform(j.xyz, j.rpy);
    if (j.type == "fixed") {
      collectGroup(r, j.child, Tj, g);
    } else {
      g.movable.emplace_back(k, Tj);
    }
  }
}

// Checks one link's <inertial> and adds it to the body's list of point masses: mass, CoM
// and rotated inertia about that CoM, in the body frame.
struct LinkMass {
  double mass;
  Eigen::Vector3d com;
  Eigen::Matrix3d inertia;
};
inline void addLinkInertia(const RawLink& raw, const Transform& T, std::vector<LinkMass>& parts) {
  if (!raw.has_inertial) return;   // massless (sensor frames and the like)
  struct {
    double mass, ixx, iyy, izz, ixy, ixz, iyz;
  } in{raw.mass, raw.ixx, raw.iyy, raw.izz, raw.ixy, raw.ixz, raw.iyz};
  if (!std::isfinite(in.mass) || in.mass < 0) {
    throw linkError(raw.name, "negative or invalid mass " + show(in.mass));
  }
  Eigen::Matrix3d I;
  I << in.ixx, in.ixy, in.ixz,
       in.ixy, in.iyy, in.iyz,
       in.ixz, in.iyz, in.izz;
  if (!I.allFinite()) throw linkError(raw.name, "the inertia is not finite");
  if (in.mass == 0) {
    if (I.cwiseAbs().maxCoeff() != 0) throw linkError(raw.name, "mass is 0 but the inertia is not");
    return;
  }
  // Principal moments, ascending. A link on its own may have a zero (or rounding-negative)
  // moment: exporters write frame links of 1e-9 kg with a zero inertia, and urdfdom and
  // MuJoCo accept them. What must be positive definite is the fused body that moves
  // (setInertia); here only a clearly negative moment is an error.
  const Eigen::Vector3d e = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I, Eigen::EigenvaluesOnly).eigenvalues();
  const double scale = std::max(I.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
  if (e(0) < -1e-12 * scale) {
    throw linkError(raw.name, "the inertia is not positive semi-definite (smallest principal moment " +
                                  show(e(0)) + ")");
  }
  // Triangle inequality on the principal moments; the tolerance admits flat
  // bodies (e.g. a disk, where Izz = Ixx + Iyy exactly up to rounding).
  if (e(0) + e(1) < e(2) * (1 - 1e-9)) {
    throw linkError(raw.name, "the inertia violates the triangle inequality (principal moments " +
                                  show(e(0)) + " + " + show(e(1)) + " < " +
                                  show(e(2)) + ")");
  }
  const Transform Ti = T * originTransform(raw.inertial_xyz, raw.inertial_rpy);
  const Eigen::Matrix3d Ib = Ti.R * I * Ti.R.transpose();   // I_body = R I R^T
  if (!Ti.p.allFinite() || !Ib.allFinite()) {
    throw linkError(raw.name, "<inertial> lies so far from the body origin that its inertia overflows");
  }
  parts.push_back({in.mass, Ti.p, Ib});
}

inline void setInertia(const RawRobot& r, const Group& g, Body& b) {
  std::vector<LinkMass> parts;
  for (const auto& [name, T] : g.links) {
    addLinkInertia(r.links[r.link_index.at(name)], T, parts);
  }
  double m = 0;
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  for (const LinkMass& l : parts) {
    m += l.mass;
    h += l.mass * l.com;
  }
  if (m <= 0) {
    const std::string why = b.joint.empty() ? "it is the floating base"
                                            : "joint " + quote(b.joint) + " moves it";
    throw linkError(b.link, why + ", but it has no mass (no <inertial> on it or on a link fixed to it)");
  }
  b.mass = m;
  b.com = h / m;
  // Each link shifted straight to the body's CoM (parallel-axis theorem): a sum of positive
  // semi-definite terms. Shifting to the body origin and back subtracts two large numbers,
  // which lost a light link's inertia next to a heavy one and left a negative eigenvalue.
  b.inertia.setZero();
  for (const LinkMass& l : parts) {
    const Eigen::Vector3d d = l.com - b.com;
    b.inertia += l.inertia + l.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  b.inertia = 0.5 * (b.inertia + b.inertia.transpose()).eval();
  if (!b.com.allFinite() || !b.inertia.allFinite()) {
    throw linkError(b.link, "the body's CoM or inertia overflows (links fixed to it lie too far apart)");
  }
  // A moving body needs a positive definite inertia, or M is singular. Checked on the fused
  // body, so zero-inertia frame links fixed to a body with inertia are fine. Relative to the
  // largest moment: a positive moment 1e-12 times smaller is rounding of the sums above.
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(b.inertia, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(ev(0) > 1e-12 * ev(2))) {
    const std::string why = b.joint.empty() ? "it is the floating base"
                                            : "joint " + quote(b.joint) + " moves it";
    throw linkError(b.link, why + ", but its inertia (with the links fixed to it) is not positive definite "
                                  "(smallest principal moment " + show(ev(0)) + ")");
  }
}

inline void setJoint(const RawJoint& raw, Body& b) {
  const Eigen::Vector3d axis(raw.axis[0], raw.axis[1], raw.axis[2]);
  // The scan rejects axes whose squared norm overflows; an inf norm would normalize to (0, 0, 0).
  const double norm = axis.norm();
  if (!axis.allFinite() || !std::isfinite(norm)) throw jointError(raw.name, "the axis is not a finite direction");
  if (norm < 1e-12) throw jointError(raw.name, "zero axis");
  b.axis = axis / norm;
  b.lower = -kInf;
  b.upper = kInf;
  b.velocity = kInf;
  b.effort = kInf;
  if (raw.type == "revolute") b.type = "Revolute";
  if (raw.type == "continuous") b.type = "Continuous";
  if (raw.type == "prismatic") b.type = "Prismatic";
  if (raw.has_limit) {
    if (raw.type != "continuous") {
      b.lower = raw.lower;
      b.upper = raw.upper;
      if (b.lower > b.upper) throw jointError(raw.name, "lower limit above upper limit");
    }
    b.velocity = raw.velocity;
    b.effort = raw.effort;
  }
  b.damping = raw.damping;
  b.friction = raw.friction;
}

}  // namespace detail

inline Model buildModel(const RawRobot& r, const Options& opt) {
  using detail::Group;
  Model m;
  m.name = r.name;

  // Floating base from the URDF: link 'world' whose only child joint is floating.
  std::string start = r.root;
  bool world_float = false;
  for (const RawJoint& j : r.joints) {
    if (j.type != "floating") continue;
    const auto& kids = r.child_joints.at(j.parent);
    if (j.parent != r.root || r.root != "world" || kids.size() != 1) {
      throw jointError(j.name, "floating joints are only supported as the one joint from link 'world' "
                               "to the root link");
    }
    world_float = true;
    start = j.child;
  }
  if (opt.floating_base && !world_float && r.root == "world") {
    throw linkError("world", "the robot floats (--floating-base) but link 'world' is its root; "
                             "join 'world' to the root link with a floating joint, or remove it");
  }
  m.floating_base = opt.floating_base || world_float;

  std::vector<Group> groups;   // one per body
  Group world;                 // fixed base: links fixed to the world (inertia dropped)
  auto addBody = [&](const std::string& link, const std::string& joint, int parent, const Transform& T,
                     const RawJoint* raw) {
    Body b;
    b.link = link;
    b.joint = joint;
    b.parent = parent;
    b.placement = T;
    if (raw) {
      detail::setJoint(*raw, b);
    } else {   // free root: no axis, no limits, nothing to actuate
      b.type = "Free";
      b.lower = -detail::kInf;
      b.upper = detail::kInf;
      b.velocity = detail::kInf;
      b.effort = 0;
    }
    Group g;
    detail::collectGroup(r, link, Transform{}, g);
    detail::setInertia(r, g, b);
    m.bodies.push_back(b);
    groups.push_back(g);
    return static_cast<int>(m.bodies.size()) - 1;
  };

  // Depth-first; the children of a body are its movable joints (reached through
  // fixed joints too), sorted by joint name.
  auto visit = [&](auto&& self, int body, std::vector<std::pair<int, Transform>> movable) -> void {
    std::sort(movable.begin(), movable.end(),
              [&](const auto& a, const auto& b) { return r.joints[a.first].name < r.joints[b.first].name; });
    for (const auto& [k, T] : movable) {
      const RawJoint& j = r.joints[k];
      const int child = addBody(j.child, j.name, body, T, &j);
      self(self, child, groups[child].movable);
    }
  };
  if (m.floating_base) {
    addBody(start, "", -1, Transform{}, nullptr);
    visit(visit, 0, groups[0].movable);
  } else {
    detail::collectGroup(r, start, Transform{}, world);
    visit(visit, -1, world.movable);
  }
  if (m.bodies.empty()) throw UrdfError("the robot has no movable joint");

  const int fb = m.floating_base ? 1 : 0;
  m.nj = static_cast<int>(m.bodies.size()) - fb;
  m.nq = m.nj + 7 * fb;
  m.nv = m.nj + 6 * fb;
  for (int i = 0; i < static_cast<int>(m.bodies.size()); ++i) {
    m.bodies[i].idx_q = i == 0 && fb ? 0 : 7 * fb + i - fb;
    m.bodies[i].idx_v = i == 0 && fb ? 0 : 6 * fb + i - fb;
    m.total_mass += m.bodies[i].mass;
  }

  // Frames: first each body's own link (frame i = body i), then the world's
  // links (fixed base), then the fused links of each body in body order.
  std::vector<Frame> all;
  for (int i = 0; i < static_cast<int>(m.bodies.size()); ++i) all.push_back({m.bodies[i].link, i, Transform{}});
  for (const auto& [name, T] : world.links) all.push_back({name, -1, T});
  for (int i = 0; i < static_cast<int>(groups.size()); ++i) {
    for (std::size_t k = 1; k < groups[i].links.size(); ++k) {
      all.push_back({groups[i].links[k].first, i, groups[i].links[k].second});
    }
  }
  if (!opt.frames_given) {
    m.frames = all;
  } else {
    std::set<std::string> wanted;
    for (const std::string& f : opt.frames) {
      const bool exists = std::any_of(all.begin(), all.end(), [&](const Frame& x) { return x.name == f; });
      if (!exists) throw UrdfError("--frames: link " + quote(f) + " does not exist");
      wanted.insert(f);
    }
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (i < m.bodies.size() || wanted.count(all[i].name)) m.frames.push_back(all[i]);
    }
  }
  return m;
}

}  // namespace hqp::tools
