#pragma once
// BalanceParameters: the numbers of the balance hierarchy (gains, friction, sole, torque
// limits, level-4 weights). Plain data; robots/walker3/controller.yaml overrides them.
// Defaults are chosen for Walker3 (43 kg, 1 kHz); the reasons are in docs/tasks.md.

#include <limits>

#include <Eigen/Core>

#include "hqp/hqp_types.hpp"
#include "tasks/pd_gains.hpp"

namespace hqp::tasks {

template <int NJ>
struct BalanceParameters {
  using VectorJ = Eigen::Matrix<double, NJ, 1>;
  // Critically damped (kd = 2√kp): feet at 20 rad/s, torso at 14 rad/s, far below the 1 kHz
  // loop. CoM horizontally at 3 rad/s (≈ the LIP's √(g/z)): a 12 N·s push then asks for a ZMP
  // near the sole edge instead of 4× beyond it; CoM height at 1 rad/s (soft, so that a leaning
  // torso lowers the CoM a little instead of straightening the knees). docs/tasks.md.
  PdGains foot_linear{400.0, 40.0};
  PdGains foot_angular{400.0, 40.0};
  PdGains com{9.0, 6.0};
  PdGains com_vertical{1.0, 2.0};
  // Integral of the horizontal CoM error, beyond the paper (0 = the paper's PD): a = ... + ki ∫e dt
  // with |∫e dt| ≤ com_integral_limit per axis. Uncompensated joint stiction holds a soft CoM
  // loop millimetres off its reference; the integral takes it back (docs/tasks.md).
  double com_ki = 0.0;               // 1/s³
  double com_integral_limit = 0.02;  // m·s
  // Reset an axis's integral to 0 when its error has the opposite sign (Clegg 1958): the
  // integral stored during a push then does not carry the CoM past its reference on the way back.
  bool com_integral_reset = false;
  double dt = 0.001;                 // s, the control period (the controller sets it from its own)
  // Capture-point gain schedule of the horizontal CoM rows, beyond the paper: the gains blend from
  // `com` to `com_high` as |e + ė/ω| grows from com_dcm_low to com_dcm_high (m); off while
  // com_dcm_high <= com_dcm_low.
  PdGains com_high{9.0, 6.0};
  double com_dcm_low = 0.0, com_dcm_high = 0.0;
  // Hip-strategy budget of the horizontal CoM rows, beyond the paper (linear_momentum_task.hpp):
  // L̇ within [−K (θ + θ_max) − D L, K (θ_max − θ) − D L], θ the torso's tilt; θ_max ∞ = off.
  double hip_max_tilt = std::numeric_limits<double>::infinity();  // rad, θ_max
  double hip_stiffness = 0.0;                                      // N·m/rad, K
  double hip_damping = 0.0;                                        // 1/s, D
  PdGains torso{200.0, 28.28};
  // Largest torso error the proportional term acts on (rad), beyond the paper: a saturated PD
  // brings a torso the hip strategy pitched far back at a bounded rate (∞ = the paper's PD).
  double torso_error_limit = std::numeric_limits<double>::infinity();
  double mu = 0.6;        // friction coefficient (rubber sole on floor ~0.8–1; kept conservative)
  double fz_min = 10.0;   // N, unilateral margin: ~2 % of the weight keeps a lightly loaded foot down
  // CoP rectangle in the sole frame (m): the 0.22 × 0.10 sole box is centred on the sole frame
  // (robots/walker3/README.md); 1 cm is kept from every edge for model error.
  double sole_x_min = -0.10, sole_x_max = 0.10, sole_y_min = -0.04, sole_y_max = 0.04;
  // N·m, beyond the paper (cop_constraint.hpp): a moment kept from every edge of the CoP region, so
  // that a torque error of this size cannot tip a lightly loaded foot; 0 = the paper's CoP region.
  double cop_moment_margin = 0.0;
  VectorJ tau_max = VectorJ::Constant(hqp::kInf);  // symmetric limits |τ| ≤ tau_max (N·m)
  // Level-4 row weights: 1 rad/s² of torso error weighs as much as ~32 N of force error.
  double torso_weight = 1.0;
  double force_weight = 1e-3;
  // m (> 0): the torsion rows m_z weigh force_weight / torsion_radius² (1 N·m of torsion costs
  // as much as 1 / torsion_radius N of force); ≤ 0: like the other rows.
  double torsion_radius = 0.05;
};

// Defaults with tau_max from the URDF effort limits of Robot.
template <class Robot>
BalanceParameters<Robot::nj> defaultBalanceParameters() {
  BalanceParameters<Robot::nj> p;
  constexpr int first = Robot::floating_base ? 1 : 0;
  for (int j = 0; j < Robot::nj; ++j) p.tau_max(j) = Robot::bodies[static_cast<std::size_t>(j + first)].effort;
  return p;
}

}  // namespace hqp::tasks
