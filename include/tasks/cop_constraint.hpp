#pragma once
// Level 2 constraint: the centre of pressure of each flat foot inside its sole rectangle
// (Section III-B). With the world-aligned wrench [f; m] about the sole origin rotated into the
// sole frame (f_s = Rᵀ f, m_s = Rᵀ m), the CoP is p = (−m_sy / f_sz, m_sx / f_sz), and
//   x_min f_sz ≤ −m_sy ≤ x_max f_sz,   y_min f_sz ≤ m_sx ≤ y_max f_sz
// is linear in F: 4 one-sided rows per foot, D x ≤ 0, in the order
//   −m_y − x_max f_z ≤ 0,   m_y + x_min f_z ≤ 0,   m_x − y_max f_z ≤ 0,   −m_x + y_min f_z ≤ 0.
// Only for flat feet (CD = 6).
// Beyond the paper, each row's bound may be −δ (`moment_margin`, N·m) instead of 0: the CoP then
// stays δ / f_sz inside the rectangle, a margin that grows as the foot unloads. A joint-torque error
// moves the true CoP by about δτ / f_sz, so a fixed distance from the edge protects a loaded foot
// and not a light one; a fixed moment protects both. It implies f_sz ≥ 2δ / (y_max − y_min).
// Each contact's δ is capped at (y_max − y_min) f_load / 4 (f_load: its measured normal force,
// References::contact_load), so the rows never ask a foot for more than half the load it carries:
// a foot the plant is lifting is let go instead of being held down.

#include <algorithm>

#include <Eigen/Core>

#include "hqp/constraint.hpp"
#include "tasks/contact_frame.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

// δ_c = min(δ, (y_max − y_min) f_load / 4): the moment margin of a foot that carries f_load
// (0 for a load ≤ 0 or NaN).
inline double copMomentMargin(double delta, double load, double y_min, double y_max) noexcept {
  return std::min(delta, 0.25 * (y_max - y_min) * std::max(0.0, load));
}

template <class Layout>
class CopConstraint : public hqp::Constraint<4 * Layout::num_contacts, Layout::nx> {
  static_assert(Layout::contact_dim == 6, "the CoP needs a 6-D contact wrench");

 public:
  using layout = Layout;
  static constexpr int NC = Layout::num_contacts;

  // CoP rectangle in the sole frame (m).
  double x_min = -0.10, x_max = 0.10, y_min = -0.04, y_max = 0.04;
  double moment_margin = 0.0;  // N·m, δ

  CopConstraint() {
    this->name = "center_of_pressure";
    this->lower.setConstant(-hqp::kInf);
    this->upper.setZero();
  }

  template <class Dyn>
  void update(const Dyn& dyn, const References<NC>& refs) noexcept {
    for (int c = 0; c < NC; ++c) {
      const double margin = copMomentMargin(moment_margin, refs.contact_load[c], y_min, y_max);
      this->upper.template segment<4>(4 * c).setConstant(-margin);
      const Eigen::Matrix3d R = contactSurfaceRotation<6>(dyn, c);
      // Sole axes in world coordinates: f_sz = n·f, m_sx = t_x·m, m_sy = t_y·m.
      const Eigen::RowVector3d tx = R.col(0).transpose(), ty = R.col(1).transpose(),
                               n = R.col(2).transpose();
      auto Dc = this->D.template block<4, 6>(4 * c, Layout::forceIndex(c));
      Dc.template block<1, 3>(0, 0) = -x_max * n;
      Dc.template block<1, 3>(0, 3) = -ty;
      Dc.template block<1, 3>(1, 0) = x_min * n;
      Dc.template block<1, 3>(1, 3) = ty;
      Dc.template block<1, 3>(2, 0) = -y_max * n;
      Dc.template block<1, 3>(2, 3) = tx;
      Dc.template block<1, 3>(3, 0) = y_min * n;
      Dc.template block<1, 3>(3, 3) = -tx;
    }
  }

  template <class P>
  void configure(const P& p) noexcept {
    x_min = p.sole_x_min;
    x_max = p.sole_x_max;
    y_min = p.sole_y_min;
    y_max = p.sole_y_max;
    moment_margin = p.cop_moment_margin;
  }
};

}  // namespace hqp::tasks
