#pragma once
// The compile-time description of a robot, as written by the generator
// (tools/urdf2model) into a header per robot. Everything here is a literal
// type so that a generated `Robot` struct can hold its tree in constexpr arrays.
// Conventions: docs/conventions.md. Format of the generated header:
// docs/generated-model.md.

#include <array>
#include <string_view>

namespace hqp::model {

enum class JointType : int {
  Free = 0,     // 6-DoF floating base (root body only): nq 7, nv 6
  Revolute,     // 1 DoF, bounded
  Continuous,   // 1 DoF, unbounded revolute
  Prismatic,    // 1 DoF, translation along the axis
};

// One movable body: the joint that connects it to its parent and the
// inertia of the body with every link fused into it by fixed joints.
struct BodyDesc {
  const char* name;        // URDF link name of the body
  const char* joint;       // URDF joint name ("" for a floating root)
  JointType type;
  int parent;              // parent body index; -1 = world
  int idx_q;               // first index in q
  int idx_v;               // first index in v
  // Placement of the body (joint) frame in the parent body frame at q = 0.
  double xyz[3];           // translation (m)
  double rot[9];           // rotation R_parent_body, row-major
  double axis[3];          // unit joint axis in the body frame (1-DoF joints)
  // Inertia of the fused body, in the body frame.
  double mass;             // kg
  double com[3];           // centre of mass (m)
  double inertia[6];       // about the CoM: Ixx, Iyy, Izz, Ixy, Ixz, Iyz (kg m^2)
  // Limits and friction from the URDF (1-DoF joints). Absent limits are
  // +/- infinity; absent friction is 0.
  double lower, upper;     // position limits (rad or m)
  double velocity;         // velocity limit
  double effort;           // effort limit (N m or N)
  double damping;          // viscous friction (N m s/rad)
  double friction;         // Coulomb friction (N m)
};

// A named frame rigidly attached to a body: every URDF link, including the
// links fused by fixed joints.
struct FrameDesc {
  const char* name;        // URDF link name
  int body;                // body index; -1 = world (the root link of a fixed-base robot)
  double xyz[3];           // placement in the body frame: translation
  double rot[9];           // and rotation R_body_frame, row-major
};

// Index of a name in a constexpr array of descriptions; -1 when absent.
template <class Desc, std::size_t N>
constexpr int indexOf(const std::array<Desc, N>& items, std::string_view name) {
  for (std::size_t i = 0; i < N; ++i) {
    if (std::string_view(items[i].name) == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace hqp::model
