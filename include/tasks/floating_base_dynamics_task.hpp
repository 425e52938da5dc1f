#pragma once
// Level 1 task, eq. 1: the unactuated rows of the equations of motion,
//   S_f (M q̈ + h) = S_f J_cᵀ F   ⇔   [S_f M, −S_f J_cᵀ] x = −S_f h,
// S_f = [I₆ 0] (the floating base rows). J_c is each contact frame's Jacobian (its top
// CD rows), world-aligned at the contact origin, so F is a world-aligned wrench about it.

#include "hqp/task.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

template <class Layout>
class FloatingBaseDynamicsTask : public hqp::Task<6, Layout::nx> {
 public:
  using layout = Layout;
  static constexpr int nv = Layout::nv, NC = Layout::num_contacts, CD = Layout::contact_dim;

  FloatingBaseDynamicsTask() { this->name = "floating_base_dynamics"; }

  template <class Dyn>
  void update(const Dyn& dyn, const References<NC>&) noexcept {
    this->A.template leftCols<nv>() = dyn.M().template topRows<6>();
    for (int c = 0; c < NC; ++c)
      this->A.template middleCols<CD>(Layout::forceIndex(c)) =
          -dyn.J(c).template topLeftCorner<CD, 6>().transpose();
    this->b = -dyn.h().template head<6>();
  }

  template <class P>
  void configure(const P&) noexcept {}
};

}  // namespace hqp::tasks
