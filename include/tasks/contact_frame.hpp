#pragma once
// Orientation of the surface frame in which a contact's wrench limits are written.
// Flat foot (CD = 6): the sole frame itself (its z axis is the sole normal), so a tilted
// foot on a tilted support (seesaw) keeps its CoP and friction limits.
// Point foot (CD = 3): the frame of a point foot rotates with the shank and says nothing
// about the ground, so the ground is taken horizontal: the world frame (docs/tasks.md).

#include <Eigen/Core>

namespace hqp::tasks {

template <int CD, class Dyn>
Eigen::Matrix3d contactSurfaceRotation(const Dyn& dyn, int c) noexcept {
  if constexpr (CD == 6) {
    return dyn.placement(c).linear();
  } else {
    static_cast<void>(dyn), static_cast<void>(c);
    return Eigen::Matrix3d::Identity();
  }
}

}  // namespace hqp::tasks
