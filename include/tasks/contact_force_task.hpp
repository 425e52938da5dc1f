#pragma once
// Level 4 task: the contact forces towards the planner's reference, [0 I] x = F_ref
// (NC·CD rows; the first CD entries of each References::contact_force).

#include <Eigen/Core>

#include "hqp/task.hpp"
#include "tasks/contact_layout.hpp"
#include "tasks/references.hpp"

namespace hqp::tasks {

template <class Layout>
class ContactForceTask : public hqp::Task<Layout::nf, Layout::nx> {
 public:
  using layout = Layout;
  static constexpr int nv = Layout::nv, nf = Layout::nf, NC = Layout::num_contacts,
                       CD = Layout::contact_dim;

  ContactForceTask() {
    this->name = "contact_force";
    this->A.template rightCols<nf>().setIdentity();
  }

  template <class Dyn>
  void update(const Dyn&, const References<NC>& refs) noexcept {
    for (int c = 0; c < NC; ++c)
      this->b.template segment<CD>(CD * c) = refs.contact_force[c].template head<CD>();
  }

  template <class P>
  void configure(const P& p) noexcept {
    this->setWeight(p.force_weight);
  }

  // F − F_ref for a solution x.
  template <class VecX>
  Eigen::Matrix<double, nf, 1> error(const VecX& x) const {
    return x.template tail<nf>() - this->b;
  }
};

}  // namespace hqp::tasks
