#pragma once
// Joint-space inertia matrix M(q) of eq. 1 by the composite-rigid-body
// algorithm (Featherstone 2008, §6.2), in world-origin coordinates:
// one forward sweep for placements and body inertias, one backward sweep for
// composite inertias Ic_i and M_ij = S_jᵀ Ic_i S_i (j an ancestor of i).

#include "model/backward_pass.hpp"
#include "model/data.hpp"
#include "model/kinematics.hpp"

namespace hqp::model {

// d.M (full symmetric nv x nv); also d.Ic, d.F, d.Itot.
template <class Robot>
const typename Data<Robot>::MatrixV& crba(Data<Robot>& d,
                                          const typename Data<Robot>::VectorQ& q) noexcept {
  detail::forwardPass<Robot, detail::kInertia>(d, q, d.tau, d.tau);
  detail::backwardPass<Robot, detail::kComposite | detail::kMassMatrix>(d, d.tau);
  return d.M;
}

}  // namespace hqp::model
