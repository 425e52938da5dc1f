#pragma once
// Independent readings of a URDF through urdfdom (not through the generator's
// own XML scan): joint order, where each link sits in its body, link masses.
// The generated headers are checked against these.

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <string>
#include <vector>

namespace hqp::test {

struct Pose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Pose operator*(const Pose& o) const { return {R * o.R, p + R * o.p}; }
};

inline Pose toPose(const urdf::Pose& u) {
  Pose out;
  out.R = Eigen::Quaterniond(u.rotation.w, u.rotation.x, u.rotation.y, u.rotation.z).toRotationMatrix();
  out.p = Eigen::Vector3d(u.position.x, u.position.y, u.position.z);
  return out;
}

inline bool isMovable(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS ||
         j.type == urdf::Joint::PRISMATIC;
}

class UrdfReference {
 public:
  explicit UrdfReference(const std::string& path) : model_(urdf::parseURDFFile(path)) {}
  bool ok() const { return model_ != nullptr; }
  const urdf::ModelInterface& model() const { return *model_; }

  // The link that is body 0 (floating) or the world (fixed base).
  std::string startLink() const {
    const urdf::LinkConstSharedPtr root = model_->getRoot();
    if (root->name == "world" && root->child_joints.size() == 1 &&
        root->child_joints[0]->type == urdf::Joint::FLOATING) {
      return root->child_joints[0]->child_link_name;
    }
    return root->name;
  }

  // Movable joints depth-first; the children of a body (movable joints reached
  // through fixed joints) visited in joint-name order.
  std::vector<std::string> jointOrder() const {
    std::vector<std::string> out;
    visitBody(startLink(), out);
    return out;
  }

  // The link whose body `link` belongs to (walking up through fixed joints), and
  // the pose of `link` in it. For a fixed base the start link stands for the world.
  std::pair<std::string, Pose> bodyOf(const std::string& link) const {
    Pose T;
    std::string at = link;
    while (true) {
      const urdf::LinkConstSharedPtr l = model_->getLink(at);
      const urdf::JointConstSharedPtr j = l->parent_joint;
      if (at == startLink() || !j || j->type != urdf::Joint::FIXED) return {at, T};
      T = toPose(j->parent_to_joint_origin_transform) * T;
      at = j->parent_link_name;
    }
  }

  // Sum of <mass> over the links that move: every link with a floating base,
  // all but those fixed to the world with a fixed base.
  double mass(bool floating) const {
    double m = 0;
    std::vector<urdf::LinkSharedPtr> links;
    model_->getLinks(links);
    for (const auto& l : links) {
      if (!l->inertial) continue;
      if (!floating && bodyOf(l->name).first == startLink()) continue;
      m += l->inertial->mass;
    }
    return m;
  }

 private:
  void movableBelow(const std::string& link, std::vector<urdf::JointSharedPtr>& out) const {
    for (const auto& j : model_->getLink(link)->child_joints) {
      if (j->type == urdf::Joint::FIXED) {
        movableBelow(j->child_link_name, out);
      } else {
        out.push_back(j);
      }
    }
  }
  void visitBody(const std::string& link, std::vector<std::string>& out) const {
    std::vector<urdf::JointSharedPtr> kids;
    movableBelow(link, kids);
    std::sort(kids.begin(), kids.end(), [](const auto& a, const auto& b) { return a->name < b->name; });
    for (const auto& j : kids) {
      out.push_back(j->name);
      visitBody(j->child_link_name, out);
    }
  }

  urdf::ModelInterfaceSharedPtr model_;
};

}  // namespace hqp::test
