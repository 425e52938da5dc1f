#pragma once
// Level 2 constraint: friction pyramid and unilateral normal force (Section III-B), 5 rows
// per contact on the contact force rotated into the surface frame (contact_frame.hpp):
//   ±f_tx − μ' f_n ≤ 0,  ±f_ty − μ' f_n ≤ 0  (4 rows, upper bound 0),   f_n ≥ fz_min (1 row),
// in the order +x, −x, +y, −y, normal. μ' = μ/√2: the pyramid inscribed in the Coulomb cone
// (|f_t| ≤ μ f_n holds for every force it admits; the circumscribed μ' = μ would admit
// forces up to √2 over the cone at the pyramid's corners).

#include <cmath>

#include <Eigen/Core>

#include "hqp/constraint.hpp"
#include "tasks/contact_frame.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

template <class Layout>
class FrictionConstraint : public hqp::Constraint<5 * Layout::num_contacts, Layout::nx> {
 public:
  using layout = Layout;
  static constexpr int NC = Layout::num_contacts, CD = Layout::contact_dim;

  double mu = 0.6;       // Coulomb friction coefficient
  double fz_min = 10.0;  // N, least normal force

  FrictionConstraint() {
    this->name = "friction_pyramid";
    for (int c = 0; c < NC; ++c) {
      this->lower.template segment<4>(5 * c).setConstant(-hqp::kInf);
      this->upper.template segment<4>(5 * c).setZero();
    }
  }

  template <class Dyn>
  void update(const Dyn& dyn, const References<NC>&) noexcept {
    const double k = mu / std::sqrt(2.0);
    for (int c = 0; c < NC; ++c) {
      const Eigen::Matrix3d R = contactSurfaceRotation<CD>(dyn, c);
      const Eigen::RowVector3d tx = R.col(0).transpose(), ty = R.col(1).transpose(),
                               n = R.col(2).transpose();
      auto Dc = this->D.template block<5, 3>(5 * c, Layout::forceIndex(c));
      Dc.row(0) = tx - k * n;
      Dc.row(1) = -tx - k * n;
      Dc.row(2) = ty - k * n;
      Dc.row(3) = -ty - k * n;
      Dc.row(4) = n;
      this->lower(5 * c + 4) = fz_min;
      this->upper(5 * c + 4) = hqp::kInf;
    }
  }

  template <class P>
  void configure(const P& p) noexcept {
    mu = p.mu;
    fz_min = p.fz_min;
  }
};

}  // namespace hqp::tasks
