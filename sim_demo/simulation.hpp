#pragma once
// The simulated Walker3: MuJoCo 2.2 scene (generated from the URDF, docs/simulation.md), the
// 1 kHz sensor -> current loop's plant side. The controller side sees SensorData filled from
// MuJoCo's sensors only (never the true state) and commands motor currents, which become joint
// torques through the plant's torque constants. The ground-truth accessors exist for logs,
// metrics and tests only.

#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <random>
#include <string>
#include <vector>

#include "plant_config.hpp"
#include "plant_perturbation.hpp"
#include "tasks/sensor_data.hpp"
#include "walker3_model.hpp"

namespace hqp::sim {

using Robot = walker3::Robot;
constexpr int kJoints = Robot::nj;
constexpr int kContacts = 2;  // left, right (the plant file's force_torque order)
using Sensors = hqp::tasks::SensorData<kJoints, kContacts>;
using Command = hqp::tasks::ActuatorCommand<kJoints>;
using VectorJ = Eigen::Matrix<double, kJoints, 1>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

struct SimulationOptions {
  std::string scene;               // scene MJCF (build tree: includes the generated robot)
  std::string plant;               // plant parameter file (robots/walker3/plant.yaml)
  double control_dt = 0.001;       // s, one tick of the loop
  int substeps = 1;                // physics steps per tick (physics dt = control_dt / substeps)
  bool noise = false;              // add the plant file's Gaussian sensor noise
  unsigned seed = 1;               // noise seed
  double hip_pitch = -0.3, knee = 0.6, ankle_pitch = -0.3;  // standing pose (rad), both legs
  PlantPerturbation perturbation;  // the plant's differences from the controller's model (off)
};

class Simulation {
 public:
  explicit Simulation(const SimulationOptions& options);  // throws std::runtime_error
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Standing pose, torso upright, at rest, t = 0, zero command; the soles rest on whatever is
  // below them (floor, seesaw, skateboards: found by a ray straight down from each sole).
  void reset();
  // SensorData from MuJoCo's sensors (encoders, IMU, F/T), plus noise if enabled, F/T offsets,
  // and each group as it was `latency` calls ago (PlantPerturbation; call once per tick). The
  // values belong to the current state with the previous command's torques (zero-order hold).
  void readSensors(Sensors& s);
  // Joint torque = k_t · current (the plant's k_t, with any torque-constant error), clamped to
  // the motor's ctrlrange (URDF effort); with actuator latency, the current of that many calls
  // ago. A non-finite current is applied as zero.
  void applyCommand(const Command& c);
  // One control period (substeps physics steps), then recompute the sensors.
  void step();
  // External force (world, N) at the torso's centre of mass until changed (pushes).
  void setTorsoForce(const Eigen::Vector3d& f);
  // The scene's 5 kg ball (body "ball"), if it has one: thrown horizontally with momentum
  // `momentum` (N·s, world; m v) at the torso's centre of mass, starting 1 cm before the robot's
  // surface on that line (so it hits at the push time; `distance` m from the torso's CoM if the
  // line misses the robot). It flies straight (gravity cancelled by an applied force) until it
  // first touches something; then it is an ordinary body. The impulse the robot receives is what the ball loses: ballMomentum()
  // before minus after.
  bool hasBall() const { return ball_ >= 0; }
  void launchBall(const Eigen::Vector3d& momentum, double distance = 0.6);
  Eigen::Vector3d ballMomentum() const;     // N·s, world (zero without a ball)
  bool ballTouchesRobot() const;

  // Moving supports (seesaw, skateboards; scene <position> actuators on one-DoF joints, found by
  // name; throws if there is none). The servo force is kp (ctrl - q) - damping q̇ (the joint's
  // damping, applied explicitly), so ctrl = q* + (damping / kp) q̇* makes it
  // kp (q* - q) + damping (q̇* - q̇): position servo with velocity feed-forward.
  int supportActuator(const std::string& name) const;
  void setSupportTarget(int actuator, double q, double dq);
  double supportPosition(int actuator) const;  // the servo joint's position (m or rad)

  double time() const { return d_->time; }
  double controlDt() const { return options_.control_dt; }
  const mjModel* model() const { return m_; }
  mjData* data() { return d_; }
  const mjData* data() const { return d_; }
  const PlantConfig& plant() const { return plant_; }
  const VectorJ& torqueConstant() const { return k_t_; }
  const VectorJ& standingPose() const { return q_stand_; }
  int jointQposAdr(int i) const { return qadr_[i]; }   // model joint i -> qpos index
  int jointDofAdr(int i) const { return dofadr_[i]; }  // model joint i -> qvel index
  // Viscous damping of model joint i (N·m·s/rad), applied explicitly (explicit_damping_ below).
  double jointDamping(int i) const { return explicit_damping_[static_cast<std::size_t>(dofadr_[i])]; }
  int actuator(int i) const { return act_[i]; }        // model joint i -> actuator id
  int baseQposAdr() const { return base_qadr_; }       // free joint: position, quaternion w x y z
  int baseDofAdr() const { return base_dofadr_; }      // free joint: linear (world), angular (body)

  // Ground truth (logs, metrics, tests; never for the controller).
  VectorJ appliedTorque() const;            // N·m, actuator output after the ctrlrange clamp
  VectorJ jointPositions() const;
  double torsoHeight() const;               // torso frame z (m)
  double torsoPitch() const;                // rad, about world y (+: leaning forward)
  double torsoRoll() const;                 // rad, about world x
  Eigen::Vector3d centerOfMass() const;     // m, world
  Eigen::Vector3d centerOfMassVelocity() const;  // m/s, world (valid after mj_subtreeVel)
  double footPitch(int c) const;            // rad, sole plate about world y
  double footRoll(int c) const;             // rad, sole plate about world x
  double footYaw(int c) const;              // rad, sole plate about world z
  // Sole plate velocity at the sole origin, world axes: angular (rad/s), then linear (m/s).
  Vector6 footVelocity(int c) const;
  // The sole plate's rectangle in the sole frame (x_min, y_min), (x_max, y_max), from the
  // scene's collision box: what the measured ZMP is checked against.
  const std::array<Eigen::Vector2d, 2>& soleRectangle(int c) const { return sole_rect_[c]; }
  bool nonFootContact() const;              // a robot geom other than a sole plate is in contact
  bool feetTouch() const;
  // The body the sole plate of foot c touches (its first contact; 0: the world, i.e. the floor),
  // -1 when it touches nothing.
  int soleSupport(int c) const;
  // Pose of foot c's sole frame in body b's frame (b = 0: world).
  Eigen::Isometry3d soleInBody(int c, int b) const;                   // the two sole plates touch each other (corrupts the F/T CoP)

  // The F/T wrench of foot c as SensorData::ft holds it, without sensor noise: what the run's
  // ZMP metrics judge (noise on a lightly loaded foot would move its CoP by centimetres).
  Vector6 trueForceTorque(int c) const;
  // Centre of pressure in the sole frame (x, y) from a SensorData F/T wrench (support on foot,
  // sensor frame, about the sensor origin). NaN when f_z < min_fz.
  Eigen::Vector2d copInSole(int c, const Vector6& ft, double min_fz = 10.0) const;
  // Sole-frame wrench (moment about the sole origin) from the same F/T wrench.
  Vector6 wrenchInSole(int c, const Vector6& ft) const;
  // Joint torque the plant delivered to the links during the last step() (N·m, mean over the
  // substeps; zero after reset()): the actuator torque minus the joint's friction, i.e. the viscous
  // damping at the step's start velocity (applied explicitly, see explicit_damping_) and the
  // frictionloss constraint force (efc_force of the dof's friction row). What the controller's
  // τ_opt asks for.
  const VectorJ& deliveredTorque() const { return delivered_; }

 private:
  int sensorAdr(const std::string& name, int dim) const;
  void addDeliveredTorque();  // one physics step's share of deliveredTorque()
  void applyModelPerturbation();
  void applyDamping();  // qfrc_applied = -D q̇ for every dof (explicit_damping_)
  void addNoise(Sensors& s);  // payload, masses, friction, contacts (constructor)

  SimulationOptions options_;
  PlantConfig plant_;
  mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  VectorJ k_t_, q_stand_;
  std::array<int, kJoints> qadr_{}, dofadr_{}, act_{}, jpos_{}, jvel_{};
  int imu_quat_ = 0, imu_gyro_ = 0, imu_accel_ = 0, torso_ = 0, base_qadr_ = 0, base_dofadr_ = 0;
  int ball_ = -1, ball_qadr_ = 0, ball_dofadr_ = 0;
  bool ball_flying_ = false;
  std::array<int, kContacts> ft_force_{}, ft_torque_{}, sole_body_{};
  std::array<Eigen::Matrix3d, kContacts> R_sole_ft_;  // F/T frame axes in the sole frame
  std::array<Eigen::Vector3d, kContacts> p_sole_ft_;  // F/T origin in the sole frame
  std::array<std::array<Eigen::Vector2d, 2>, kContacts> sole_rect_;
  std::mt19937 rng_;
  VectorJ delivered_ = VectorJ::Zero();  // deliveredTorque()
  // The scene's joint damping D per dof, moved out of the model (dof_damping = 0) and applied as
  // qfrc_applied = -D q̇ before each step. MuJoCo 2.2's Euler integrates dof_damping implicitly
  // after the constraint solve, which changes the damped dofs' accelerations but not the contact
  // forces: a sole on a damped board then slips in proportion to the board's velocity (6.8 mm on
  // skate_x at 0.96 m/s, whatever the noslip iterations). Applied explicitly, the damping is part
  // of the forces the contacts are solved with (stable: h D / m <= 0.62 for the boards).
  std::vector<double> explicit_damping_;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero(), accel_bias_ = Eigen::Vector3d::Zero();  // IMU frame
  VectorJ k_t_plant_;                    // k_t_ with the torque-constant errors (what the motors have)
  std::vector<Sensors> sensor_history_;  // ring of the last readings (latency), newest at sensor_head_
  int sensor_head_ = 0, sensor_count_ = 0;
  std::vector<VectorJ> current_history_;  // ring of commanded currents (actuator latency)
  int current_head_ = 0;
};

}  // namespace hqp::sim
