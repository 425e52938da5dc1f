#pragma once
// Level 4 task: the contact forces towards the planner's reference, [0 I] x = F_ref
// (NC·CD rows; the first CD entries of each References::contact_force).
// Row weights: force_weight on every row, except the torsion m_z of a flat foot, which weighs
// force_weight / r_t² (r_t = torsion_radius): Table I has no torsion limit, and a level that
// lacks freedom would otherwise buy tiny gains with torsions the sole cannot transmit
// (|m_z| ≲ μ f_z r_t), spinning the feet (docs/tasks.md).

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
    if constexpr (CD == 6) {
      const double r = p.torsion_radius;
      const double w = r > 0.0 ? p.force_weight / (r * r) : p.force_weight;
      for (int c = 0; c < NC; ++c) this->weight(CD * c + 5) = w;
    }
  }

  // F − F_ref for a solution x.
  template <class VecX>
  Eigen::Matrix<double, nf, 1> error(const VecX& x) const {
    return x.template tail<nf>() - this->b;
  }
};

}  // namespace hqp::tasks
