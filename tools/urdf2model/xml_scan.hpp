#pragma once
// A strict scan of the URDF XML (TinyXML, which urdfdom itself uses).
// urdfdom rejects several broken trees with messages that do not name the
// element, accepts others (two parents, mimic) and reads a malformed number as
// 0, so the structure and every number the model needs are read and checked
// here; urdfdom's parse only has to succeed as well (the file must stay a URDF
// that ROS tools and MuJoCo accept). Origins are read here so that rpy goes
// straight to a rotation matrix instead of through urdfdom's quaternion.

#include <tinyxml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <locale>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "urdf2model/error.hpp"

namespace hqp::tools {

using Vec3 = std::array<double, 3>;

// Accepted magnitudes (docs/generated-model.md). A robot's numbers lie far inside them; beyond
// them the parallel-axis sums of fused links lose the small inertias to rounding.
constexpr double kMaxMass = 1e6;      // kg, per link
constexpr double kMaxInertia = 1e6;   // kg m², per <inertia> entry
constexpr double kMaxLength = 1e3;    // m, per <origin xyz> entry

struct RawLink {
  std::string name;
  bool has_inertial = false;
  Vec3 inertial_xyz{0, 0, 0};
  Vec3 inertial_rpy{0, 0, 0};
  double mass = 0;
  double ixx = 0, iyy = 0, izz = 0, ixy = 0, ixz = 0, iyz = 0;
};

struct RawJoint {
  std::string name;
  std::string type;     // URDF type attribute
  std::string parent;   // link names
  std::string child;
  Vec3 xyz{0, 0, 0};    // <origin>
  Vec3 rpy{0, 0, 0};
  Vec3 axis{1, 0, 0};   // URDF default
  bool has_limit = false;
  double lower = 0, upper = 0;   // URDF defaults when the attributes are absent
  double effort = 0, velocity = 0;
  double damping = 0, friction = 0;
};

struct RawRobot {
  std::string name;
  std::vector<RawLink> links;     // file order
  std::vector<RawJoint> joints;   // file order
  std::map<std::string, int> link_index;
  std::map<std::string, int> joint_index;
  std::string root;                                    // the one link without a parent joint
  std::map<std::string, int> parent_joint;             // link -> joint index
  std::map<std::string, std::vector<int>> child_joints;  // link -> joint indices, sorted by name
};

namespace detail {

inline bool parseVec3(const char* text, Vec3& out) {
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  for (double& x : out) {
    if (!(in >> x)) return false;
  }
  in >> std::ws;
  return in.eof();
}

// Reads <origin xyz rpy> under `parent` (absent parts stay zero).
inline void readOrigin(const TiXmlElement* parent, Vec3& xyz, Vec3& rpy,
                       const std::string& owner_kind, const std::string& owner) {
  const TiXmlElement* o = parent->FirstChildElement("origin");
  if (o == nullptr) return;
  auto fail = [&](const char* attr, const char* value) {
    const std::string what = "<origin " + std::string(attr) + "=" + quote(value) + "> is not three numbers";
    return owner_kind == "joint" ? jointError(owner, what) : linkError(owner, what);
  };
  if (const char* s = o->Attribute("xyz")) {
    if (!parseVec3(s, xyz)) throw fail("xyz", s);
    for (double v : xyz)
      if (!(std::abs(v) <= kMaxLength)) {
        const std::string what = "<origin xyz=" + quote(s) + "> is outside ±" + show(kMaxLength) + " m";
        throw owner_kind == "joint" ? jointError(owner, what) : linkError(owner, what);
      }
  }
  if (const char* s = o->Attribute("rpy")) {
    if (!parseVec3(s, rpy)) throw fail("rpy", s);
  }
}

inline bool parseNumber(const char* text, double& out) {
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  if (!(in >> out)) return false;
  in >> std::ws;
  return in.eof();
}

// Reads attribute `attr` of `e` into `out` when present; `required` makes absence an error.
template <class Fail>
void readNumber(const TiXmlElement* e, const char* attr, double& out, bool required, Fail fail) {
  const char* s = e->Attribute(attr);
  if (s == nullptr) {
    if (required) throw fail("<" + std::string(e->Value()) + "> has no " + attr);
    return;
  }
  if (!parseNumber(s, out)) {
    throw fail("<" + std::string(e->Value()) + " " + attr + "=" + quote(s) + "> is not a number");
  }
}

inline std::string childLinkAttr(const TiXmlElement* joint, const char* tag) {
  const TiXmlElement* e = joint->FirstChildElement(tag);
  if (e == nullptr || e->Attribute("link") == nullptr) return {};
  return e->Attribute("link");
}

}  // namespace detail

// Parses `xml` and checks that it describes one tree of links. Throws UrdfError.
inline RawRobot scanUrdf(const std::string& xml) {
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  if (doc.Error()) {
    throw UrdfError("line " + std::to_string(doc.ErrorRow()) + ": XML error: " + doc.ErrorDesc());
  }
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) throw UrdfError("no <robot> element");
  RawRobot r;
  if (const char* n = robot->Attribute("name")) r.name = n;
  if (r.name.empty()) throw UrdfError("<robot> has no name");

  for (const TiXmlElement* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
    RawLink l;
    if (e->Attribute("name") == nullptr || std::string(e->Attribute("name")).empty()) {
      throw UrdfError("line " + std::to_string(e->Row()) + ": <link> without a name");
    }
    l.name = e->Attribute("name");
    if (r.link_index.count(l.name)) throw linkError(l.name, "defined twice");
    if (const TiXmlElement* in = e->FirstChildElement("inertial")) {
      auto fail = [&](const std::string& what) { return linkError(l.name, what); };
      l.has_inertial = true;
      detail::readOrigin(in, l.inertial_xyz, l.inertial_rpy, "link", l.name);
      const TiXmlElement* mass = in->FirstChildElement("mass");
      if (mass == nullptr) throw fail("<inertial> has no <mass>");
      detail::readNumber(mass, "value", l.mass, true, fail);
      // Checked here for every link, also those fused into a fixed base (whose inertia is dropped).
      if (!std::isfinite(l.mass) || l.mass < 0) throw fail("negative or invalid mass " + show(l.mass));
      if (l.mass > kMaxMass) throw fail("mass " + show(l.mass) + " kg is above " + show(kMaxMass) + " kg");
      const TiXmlElement* I = in->FirstChildElement("inertia");
      if (I == nullptr) throw fail("<inertial> has no <inertia>");
      detail::readNumber(I, "ixx", l.ixx, true, fail);
      detail::readNumber(I, "iyy", l.iyy, true, fail);
      detail::readNumber(I, "izz", l.izz, true, fail);
      detail::readNumber(I, "ixy", l.ixy, true, fail);
      detail::readNumber(I, "ixz", l.ixz, true, fail);
      detail::readNumber(I, "iyz", l.iyz, true, fail);
      const char* names[] = {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"};
      const double values[] = {l.ixx, l.iyy, l.izz, l.ixy, l.ixz, l.iyz};
      for (int k = 0; k < 6; ++k)
        if (!(std::abs(values[k]) <= kMaxInertia))
          throw fail("<inertia " + std::string(names[k]) + "=" + quote(I->Attribute(names[k])) + "> is outside ±" +
                     show(kMaxInertia) + " kg m²");
    }
    r.link_index[l.name] = static_cast<int>(r.links.size());
    r.links.push_back(l);
  }
  if (r.links.empty()) throw UrdfError("the robot has no links");

  for (const TiXmlElement* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    RawJoint j;
    if (e->Attribute("name") == nullptr || std::string(e->Attribute("name")).empty()) {
      throw UrdfError("line " + std::to_string(e->Row()) + ": <joint> without a name");
    }
    j.name = e->Attribute("name");
    if (r.joint_index.count(j.name)) throw jointError(j.name, "defined twice");
    j.type = e->Attribute("type") ? e->Attribute("type") : "";
    if (j.type == "planar") throw jointError(j.name, "planar joints are not supported");
    if (j.type != "revolute" && j.type != "continuous" && j.type != "prismatic" &&
        j.type != "fixed" && j.type != "floating") {
      throw jointError(j.name, "unknown joint type " + quote(j.type) + "");
    }
    if (e->FirstChildElement("mimic") != nullptr) {
      throw jointError(j.name, "mimic joints are not supported (model the coupling as a task)");
    }
    j.parent = detail::childLinkAttr(e, "parent");
    j.child = detail::childLinkAttr(e, "child");
    if (j.parent.empty()) throw jointError(j.name, "no <parent link=...>");
    if (j.child.empty()) throw jointError(j.name, "no <child link=...>");
    if (!r.link_index.count(j.parent)) {
      throw jointError(j.name, "parent link " + quote(j.parent) + " does not exist");
    }
    if (!r.link_index.count(j.child)) {
      throw jointError(j.name, "child link " + quote(j.child) + " does not exist");
    }
    if (j.parent == j.child) {
      throw jointError(j.name, "joins link " + quote(j.child) + " to itself (kinematic loop)");
    }
    detail::readOrigin(e, j.xyz, j.rpy, "joint", j.name);
    auto fail = [&](const std::string& what) { return jointError(j.name, what); };
    if (const TiXmlElement* a = e->FirstChildElement("axis")) {
      if (const char* s = a->Attribute("xyz")) {
        if (!detail::parseVec3(s, j.axis)) throw fail("<axis xyz=" + quote(s) + "> is not three numbers");
        // The axis gets normalized (here and by MuJoCo and ROS tools): its squared norm must be finite.
        const double n2 = j.axis[0] * j.axis[0] + j.axis[1] * j.axis[1] + j.axis[2] * j.axis[2];
        if (j.type != "fixed" && j.type != "floating" && !std::isfinite(n2)) {
          throw fail("<axis xyz=" + quote(s) + "> is too large to normalize; give a unit vector");
        }
      }
    }
    if (const TiXmlElement* lim = e->FirstChildElement("limit")) {
      j.has_limit = true;
      detail::readNumber(lim, "lower", j.lower, false, fail);
      detail::readNumber(lim, "upper", j.upper, false, fail);
      detail::readNumber(lim, "effort", j.effort, true, fail);
      detail::readNumber(lim, "velocity", j.velocity, true, fail);
      if (j.type == "revolute" || j.type == "prismatic" || j.type == "continuous") {
        // effort becomes the motor current limit and velocity a bound of the tasks: both must be
        // positive (a negative effort would make the clamp's low bound exceed its high bound).
        for (const char* attr : {"effort", "velocity"}) {
          const double x = attr[0] == 'e' ? j.effort : j.velocity;
          if (!std::isfinite(x) || x <= 0) {
            throw fail("<limit " + std::string(attr) + "=" + quote(lim->Attribute(attr)) + "> must be a finite number > 0");
          }
        }
      }
      if (j.type == "revolute" || j.type == "prismatic") {   // continuous joints ignore lower/upper
        for (const char* attr : {"lower", "upper"}) {
          const double x = attr[0] == 'l' ? j.lower : j.upper;
          if (!std::isfinite(x)) {
            throw fail("<limit " + std::string(attr) + "=" + quote(lim->Attribute(attr)) + "> is not finite");
          }
        }
        if (j.lower > j.upper) {
          const std::string lo = lim->Attribute("lower") ? lim->Attribute("lower") : "0";
          const std::string up = lim->Attribute("upper") ? lim->Attribute("upper") : "0";
          throw fail("<limit lower=" + quote(lo) + "> is above <limit upper=" + quote(up) + ">");
        }
      }
    }
    if (!j.has_limit && (j.type == "revolute" || j.type == "prismatic")) {
      throw fail(j.type + " joint without <limit> (use a continuous joint for an unbounded rotation)");
    }
    if (const TiXmlElement* dyn = e->FirstChildElement("dynamics")) {
      detail::readNumber(dyn, "damping", j.damping, false, fail);
      detail::readNumber(dyn, "friction", j.friction, false, fail);
    }
    r.joint_index[j.name] = static_cast<int>(r.joints.size());
    r.joints.push_back(j);
  }

  // One parent per link.
  for (int k = 0; k < static_cast<int>(r.joints.size()); ++k) {
    const RawJoint& j = r.joints[k];
    auto it = r.parent_joint.find(j.child);
    if (it != r.parent_joint.end()) {
      std::string a = r.joints[it->second].name, b = j.name;
      if (b < a) std::swap(a, b);
      throw linkError(j.child, "has two parents (joints " + quote(a) + " and " + quote(b) +
                                   "): kinematic loops are not supported");
    }
    r.parent_joint[j.child] = k;
    r.child_joints[j.parent].push_back(k);
  }
  for (auto& [link, kids] : r.child_joints) {
    std::sort(kids.begin(), kids.end(),
              [&](int a, int b) { return r.joints[a].name < r.joints[b].name; });
  }

  // With one parent per link, a loop is a cycle of parent pointers.
  for (const RawLink& l : r.links) {
    std::string at = l.name;
    // A link that only leads into a cycle stops after |links| steps; the
    // cycle's own links report it.
    for (std::size_t steps = 0; r.parent_joint.count(at) && steps <= r.links.size(); ++steps) {
      at = r.joints[r.parent_joint[at]].parent;
      if (at == l.name) {
        // Name the smallest joint on the cycle so the message does not depend on file order.
        std::string first = r.joints[r.parent_joint[l.name]].name;
        for (std::string c = r.joints[r.parent_joint[l.name]].parent; c != l.name;
             c = r.joints[r.parent_joint[c]].parent) {
          first = std::min(first, r.joints[r.parent_joint[c]].name);
        }
        throw jointError(first, "closes a kinematic loop (through link " + quote(l.name) + ")");
      }
    }
  }

  std::vector<std::string> roots;
  for (const RawLink& l : r.links) {
    if (!r.parent_joint.count(l.name)) roots.push_back(l.name);
  }
  if (roots.size() > 1) {
    std::sort(roots.begin(), roots.end());
    throw linkError(roots[1], "has no parent joint, and neither has link " + quote(roots[0]) +
                                  ": the links must form one tree");
  }
  r.root = roots.at(0);
  return r;
}

}  // namespace hqp::tools
