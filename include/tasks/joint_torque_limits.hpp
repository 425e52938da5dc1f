#pragma once
// Level 1 constraint: joint torque saturation τ_min ≤ τ ≤ τ_max (Section III-B) with τ from
// the actuated rows of the equations of motion (eq. 6),
//   τ = S_a (M q̈ + h − J_cᵀ F) = [S_a M, −S_a J_cᵀ] x + S_a h,
// so D = [S_a M, −S_a J_cᵀ], τ_min − S_a h ≤ D x ≤ τ_max − S_a h. S_a = [0 I_nj].

#include <Eigen/Core>

#include "hqp/constraint.hpp"
#include "hqp/hqp_types.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

template <class Layout>
class JointTorqueLimits : public hqp::Constraint<Layout::nj, Layout::nx> {
 public:
  using layout = Layout;
  static constexpr int nv = Layout::nv, nj = Layout::nj, NC = Layout::num_contacts,
                       CD = Layout::contact_dim;
  using VectorJ = Eigen::Matrix<double, nj, 1>;

  VectorJ tau_min = VectorJ::Constant(-hqp::kInf);  // N·m
  VectorJ tau_max = VectorJ::Constant(hqp::kInf);   // N·m

  JointTorqueLimits() { this->name = "joint_torque_limits"; }

  template <class Dyn>
  void update(const Dyn& dyn, const References<NC>&) noexcept {
    this->D.template leftCols<nv>() = dyn.M().template bottomRows<nj>();
    for (int c = 0; c < NC; ++c)
      this->D.template middleCols<CD>(Layout::forceIndex(c)) =
          -dyn.J(c).template topRightCorner<CD, nj>().transpose();
    const auto ha = dyn.h().template tail<nj>();
    this->lower = tau_min - ha;  // −inf stays −inf
    this->upper = tau_max - ha;
  }

  // Symmetric limits |τ| ≤ tau_max.
  template <class P>
  void configure(const P& p) noexcept {
    tau_max = p.tau_max;
    tau_min = -p.tau_max;
  }
};

}  // namespace hqp::tasks
