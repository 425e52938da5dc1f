#pragma once
// Ways in which the simulated plant differs from the controller's model (docs/scenarios.md,
// "Plant perturbations"): a payload, mass errors, sensor and actuator latency, F/T offsets,
// torque-constant errors, joint friction, ground friction and contact softness. They change the
// MuJoCo plant only, never the controller's generated model or its YAML. All are off by default.
// Not real-time code.

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace hqp::sim {

struct PlantPerturbation {
  // A point mass rigidly attached to a body of the robot, at `payload_position` in that body's
  // frame (the URDF link frame; a link fused by a fixed joint is named by its parent body).
  std::string payload_link;                  // empty: no payload
  double payload_mass = 0.0;                 // kg
  Eigen::Vector3d payload_position = Eigen::Vector3d::Zero();  // m
  // Mass and rotational inertia of every robot body scaled by `mass_scale`, then each listed
  // body by its own factor (e.g. {"torso", 1.1}: a torso 10 % heavier than the model says).
  double mass_scale = 1.0;
  std::vector<std::pair<std::string, double>> link_mass_scale;
  // Latency in control ticks: the controller reads each sensor group as it was this many ticks
  // ago; the motors apply the current commanded this many ticks ago (zero before the first).
  int encoder_latency = 0, imu_latency = 0, ft_latency = 0, actuator_latency = 0;
  // Constant offsets added to each F/T reading (sensor frame: force N, moment N·m; left, right).
  std::array<Eigen::Matrix<double, 6, 1>, 2> ft_offset{Eigen::Matrix<double, 6, 1>::Zero(),
                                                        Eigen::Matrix<double, 6, 1>::Zero()};
  // The plant's torque constant is (1 + error) times plant.yaml's for every joint, then times
  // (1 + its own error) for each listed joint (full URDF joint name).
  double torque_constant_error = 0.0;
  std::vector<std::pair<std::string, double>> torque_constant_error_joint;
  double joint_friction_scale = 1.0;         // factor on the plant's Coulomb and viscous friction
  double ground_friction = -1.0;             // sliding friction of every contact; < 0: the scene's
  std::string contact = "default";           // default (the scene's), soft or hard: contact solref/solimp

  bool any() const {
    return !payload_link.empty() || mass_scale != 1.0 || !link_mass_scale.empty() || encoder_latency > 0 ||
           imu_latency > 0 || ft_latency > 0 || actuator_latency > 0 || !ft_offset[0].isZero() ||
           !ft_offset[1].isZero() || torque_constant_error != 0.0 || !torque_constant_error_joint.empty() ||
           joint_friction_scale != 1.0 || ground_friction >= 0.0 || contact != "default";
  }
  int maxSensorLatency() const { return std::max({encoder_latency, imu_latency, ft_latency}); }
};

// Contact softness presets: MuJoCo solref (time constant s, damping ratio) and solimp.
struct ContactPreset {
  std::array<double, 2> solref;
  std::array<double, 5> solimp;
};
// The scenes use MuJoCo's defaults (solref 0.02 s / 1, solimp 0.9 0.95 0.001). soft: twice the
// time constant and a lower, wider impedance ramp (rubber soles on a mat); hard: 5 ms (MuJoCo's
// floor is 2 physics steps) and a stiffer impedance.
// Throws std::invalid_argument for any other name ("default" keeps the scene's values).
inline ContactPreset contactPreset(const std::string& name) {
  if (name == "soft") return {{0.04, 1.0}, {0.7, 0.9, 0.005, 0.5, 2.0}};
  if (name == "hard") return {{0.005, 1.0}, {0.95, 0.99, 0.001, 0.5, 2.0}};
  throw std::invalid_argument("contact preset '" + name + "' (expected default, soft or hard)");
}

}  // namespace hqp::sim
