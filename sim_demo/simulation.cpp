#include "simulation.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hqp::sim {

namespace {

int requireId(const mjModel* m, mjtObj type, const std::string& name, const char* what) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0) throw std::runtime_error(std::string("scene has no ") + what + " '" + name + "'");
  return id;
}

}  // namespace

Simulation::Simulation(const SimulationOptions& options) : options_(options), rng_(options.seed) {
  if (!(options_.control_dt > 0) || options_.substeps < 1) throw std::runtime_error("invalid control_dt / substeps");
  plant_ = loadPlantConfig(options_.plant);
  if (static_cast<int>(plant_.force_torque.size()) != kContacts) {
    throw std::runtime_error(options_.plant + ": expected 2 force_torque sensors (left, right)");
  }
  char error[1024] = {0};
  m_ = mj_loadXML(options_.scene.c_str(), nullptr, error, sizeof(error));
  if (!m_) throw std::runtime_error("cannot load scene " + options_.scene + ": " + error);
  m_->opt.timestep = options_.control_dt / options_.substeps;
  m_->opt.noslip_iterations = plant_.noslip_iterations;
  d_ = mj_makeData(m_);

  for (int i = 0; i < kJoints; ++i) {
    const std::string jn = Robot::bodies[i + 1].joint;  // joint i moves body i + 1 (floating base)
    const int j = requireId(m_, mjOBJ_JOINT, jn, "joint");
    qadr_[i] = m_->jnt_qposadr[j];
    dofadr_[i] = m_->jnt_dofadr[j];
    act_[i] = requireId(m_, mjOBJ_ACTUATOR, jn, "actuator");
    jpos_[i] = sensorAdr(jn + "_pos", 1);
    jvel_[i] = sensorAdr(jn + "_vel", 1);
    k_t_[i] = plant_.joint(jn).torque_constant;
    const std::string s = jn.substr(2);
    q_stand_[i] = s == "hip_pitch" ? options_.hip_pitch
                : s == "knee" ? options_.knee
                : s == "ankle_pitch" ? options_.ankle_pitch
                : 0.0;
  }
  imu_quat_ = sensorAdr("imu_quat", 4);
  imu_gyro_ = sensorAdr("imu_gyro", 3);
  imu_accel_ = sensorAdr("imu_accel", 3);
  torso_ = requireId(m_, mjOBJ_BODY, Robot::bodies[0].name, "body");
  if (m_->body_jntnum[torso_] != 1 || m_->jnt_type[m_->body_jntadr[torso_]] != mjJNT_FREE) {
    throw std::runtime_error("the robot's root body has no free joint");
  }
  base_qadr_ = m_->jnt_qposadr[m_->body_jntadr[torso_]];
  base_dofadr_ = m_->jnt_dofadr[m_->body_jntadr[torso_]];
  ball_ = mj_name2id(m_, mjOBJ_BODY, "ball");
  if (ball_ >= 0) {
    if (m_->body_jntnum[ball_] != 1 || m_->jnt_type[m_->body_jntadr[ball_]] != mjJNT_FREE || !(m_->body_mass[ball_] > 0)) {
      throw std::runtime_error("scene body 'ball' needs a free joint and a mass");
    }
    ball_qadr_ = m_->jnt_qposadr[m_->body_jntadr[ball_]];
    ball_dofadr_ = m_->jnt_dofadr[m_->body_jntadr[ball_]];
  }
  for (int c = 0; c < kContacts; ++c) {
    const ForceTorqueSite& ft = plant_.force_torque[c];
    ft_force_[c] = sensorAdr(ft.name + "_force", 3);
    ft_torque_[c] = sensorAdr(ft.name + "_torque", 3);
    sole_body_[c] = requireId(m_, mjOBJ_BODY, ft.sole, "body");
    const int site = requireId(m_, mjOBJ_SITE, ft.name, "site");
    if (m_->site_bodyid[site] != sole_body_[c]) throw std::runtime_error("F/T site " + ft.name + " is not on its sole body");
    // The site is placed relative to the sole body, whose frame is the sole frame.
    const double* sq = m_->site_quat + 4 * site;
    R_sole_ft_[c] = Eigen::Quaterniond(sq[0], sq[1], sq[2], sq[3]).normalized().toRotationMatrix();
    p_sole_ft_[c] = Eigen::Vector3d(m_->site_pos[3 * site], m_->site_pos[3 * site + 1], m_->site_pos[3 * site + 2]);
    // The sole plate: the one box geom of the sole body, axis-aligned with the sole frame.
    int plate = -1;
    for (int g = 0; g < m_->ngeom; ++g) {
      if (m_->geom_bodyid[g] != sole_body_[c] || m_->geom_type[g] != mjGEOM_BOX) continue;
      if (plate >= 0) throw std::runtime_error("sole body " + ft.sole + " has more than one box geom");
      plate = g;
    }
    if (plate < 0) throw std::runtime_error("sole body " + ft.sole + " has no box geom (sole plate)");
    const double* gq = m_->geom_quat + 4 * plate;
    if (std::abs(std::abs(gq[0]) - 1.0) > 1e-9) throw std::runtime_error("sole plate of " + ft.sole + " is rotated");
    const Eigen::Vector2d centre(m_->geom_pos[3 * plate], m_->geom_pos[3 * plate + 1]);
    const Eigen::Vector2d half(m_->geom_size[3 * plate], m_->geom_size[3 * plate + 1]);
    sole_rect_[c] = {centre - half, centre + half};
  }
  applyModelPerturbation();
  explicit_damping_.assign(m_->dof_damping, m_->dof_damping + m_->nv);
  for (int i = 0; i < m_->nv; ++i) m_->dof_damping[i] = 0.0;
  reset();
}

void Simulation::applyDamping() {
  for (int i = 0; i < m_->nv; ++i) d_->qfrc_applied[i] = -explicit_damping_[i] * d_->qvel[i];
}

void Simulation::applyModelPerturbation() {
  const PlantPerturbation& pp = options_.perturbation;
  auto bodyOf = [&](const std::string& name) {
    const int b = mj_name2id(m_, mjOBJ_BODY, name.c_str());
    if (b < 0 || m_->body_rootid[b] != torso_) {
      throw std::runtime_error("plant perturbation: the robot has no body '" + name + "'");
    }
    return b;
  };
  auto scaleMass = [&](int b, double f) {
    if (!(f > 0.0)) throw std::runtime_error("plant perturbation: mass scale must be > 0");
    m_->body_mass[b] *= f;
    for (int k = 0; k < 3; ++k) m_->body_inertia[3 * b + k] *= f;
  };
  if (pp.mass_scale != 1.0) {
    for (int b = 1; b < m_->nbody; ++b) {
      if (m_->body_rootid[b] == torso_) scaleMass(b, pp.mass_scale);
    }
  }
  for (const auto& [name, f] : pp.link_mass_scale) scaleMass(bodyOf(name), f);
  if (!pp.payload_link.empty() && pp.payload_mass != 0.0) {
    // A point mass at p (body frame): new CoM and the inertia about it by the parallel-axis
    // theorem, then back to MuJoCo's principal form (body_inertia, body_iquat).
    const int b = bodyOf(pp.payload_link);
    const double m = m_->body_mass[b], mp = pp.payload_mass, mt = m + mp;
    if (!(mp > 0.0)) throw std::runtime_error("plant perturbation: payload mass must be > 0");
    const Eigen::Vector3d c(m_->body_ipos + 3 * b), p = pp.payload_position;
    const Eigen::Vector3d ct = (m * c + mp * p) / mt;
    const double* iq = m_->body_iquat + 4 * b;
    const Eigen::Matrix3d R = Eigen::Quaterniond(iq[0], iq[1], iq[2], iq[3]).normalized().toRotationMatrix();
    const Eigen::Vector3d I0(m_->body_inertia + 3 * b);
    auto shift = [](double mass, const Eigen::Vector3d& r) {
      return (mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose())).eval();
    };
    const Eigen::Matrix3d I = R * I0.asDiagonal() * R.transpose() + shift(m, c - ct) + shift(mp, p - ct);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
    Eigen::Matrix3d V = eig.eigenvectors();
    if (V.determinant() < 0) V.col(0) = -V.col(0);
    const Eigen::Quaterniond q(V);
    m_->body_mass[b] = mt;
    for (int k = 0; k < 3; ++k) {
      m_->body_ipos[3 * b + k] = ct[k];
      m_->body_inertia[3 * b + k] = eig.eigenvalues()[k];
    }
    m_->body_iquat[4 * b] = q.w();
    m_->body_iquat[4 * b + 1] = q.x();
    m_->body_iquat[4 * b + 2] = q.y();
    m_->body_iquat[4 * b + 3] = q.z();
  }
  if (pp.joint_friction_scale != 1.0) {
    if (!(pp.joint_friction_scale >= 0.0)) throw std::runtime_error("plant perturbation: friction scale must be >= 0");
    for (int i = 0; i < kJoints; ++i) {
      m_->dof_frictionloss[dofadr_[i]] *= pp.joint_friction_scale;
      m_->dof_damping[dofadr_[i]] *= pp.joint_friction_scale;
    }
  }
  // Every geom alike: MuJoCo combines two geoms' friction by the maximum and their solref and
  // solimp by a mixture, so equal values give exactly these.
  if (pp.ground_friction >= 0.0) {
    for (int g = 0; g < m_->ngeom; ++g) m_->geom_friction[3 * g] = pp.ground_friction;
  }
  if (pp.contact != "default") {
    const ContactPreset c = contactPreset(pp.contact);
    for (int g = 0; g < m_->ngeom; ++g) {
      for (int k = 0; k < 2; ++k) m_->geom_solref[mjNREF * g + k] = c.solref[k];
      for (int k = 0; k < 5; ++k) m_->geom_solimp[mjNIMP * g + k] = c.solimp[k];
    }
  }
  k_t_plant_ = k_t_ * (1.0 + pp.torque_constant_error);
  for (const auto& [name, e] : pp.torque_constant_error_joint) {
    int found = -1;
    for (int i = 0; i < kJoints; ++i) {
      if (name == Robot::bodies[i + 1].joint) found = i;
    }
    if (found < 0) throw std::runtime_error("plant perturbation: the robot has no joint '" + name + "'");
    k_t_plant_[found] *= 1.0 + e;
  }
  if (!(k_t_plant_.minCoeff() > 0.0)) throw std::runtime_error("plant perturbation: a torque constant became <= 0");
  if (pp.encoder_latency < 0 || pp.imu_latency < 0 || pp.ft_latency < 0 || pp.actuator_latency < 0) {
    throw std::runtime_error("plant perturbation: latency must be >= 0 ticks");
  }
  sensor_history_.assign(static_cast<std::size_t>(pp.maxSensorLatency() + 1), Sensors{});
  current_history_.assign(static_cast<std::size_t>(pp.actuator_latency + 1), VectorJ::Zero());
  // Derived constants (subtree masses, the constraint solver's inverse weights) of the new model.
  if (pp.any()) mj_setConst(m_, d_);
}

Simulation::~Simulation() {
  mj_deleteData(d_);
  mj_deleteModel(m_);
}

int Simulation::sensorAdr(const std::string& name, int dim) const {
  const int id = requireId(m_, mjOBJ_SENSOR, name, "sensor");
  if (m_->sensor_dim[id] != dim) throw std::runtime_error("sensor " + name + " has the wrong dimension");
  return m_->sensor_adr[id];
}

void Simulation::reset() {
  mj_resetData(m_, d_);
  // Free joint: position, quaternion (w x y z, upright).
  double* base = d_->qpos + base_qadr_;
  base[0] = base[1] = 0.0;
  base[2] = 2.0;  // above every support, so the rays below start outside them
  base[3] = 1.0;
  base[4] = base[5] = base[6] = 0.0;
  for (int i = 0; i < kJoints; ++i) d_->qpos[qadr_[i]] = q_stand_[i];
  mj_kinematics(m_, d_);
  // Lower the base until the first sole touches what is below it: a ray straight down from each
  // sole origin (the plate's underside) to the first geom that is not that sole (the floor plane
  // at z = 0 in scene.xml, a board top on moving supports).
  double drop = std::numeric_limits<double>::infinity();
  const mjtNum down[3] = {0.0, 0.0, -1.0};
  for (int c = 0; c < kContacts; ++c) {
    const double* p = d_->xpos + 3 * sole_body_[c];
    int geom = -1;
    const double dist = mj_ray(m_, d_, p, down, nullptr, 1, sole_body_[c], &geom);
    drop = std::min(drop, dist >= 0.0 ? dist : p[2]);  // nothing below: land on z = 0
  }
  base[2] -= drop;
  for (int u = 0; u < m_->nu; ++u) d_->ctrl[u] = 0.0;
  ball_flying_ = false;  // mj_resetData parked the ball at its qpos0
  sensor_head_ = sensor_count_ = 0;
  for (VectorJ& c : current_history_) c.setZero();
  current_head_ = 0;
  delivered_.setZero();
  gyro_bias_.setZero();
  accel_bias_.setZero();
  if (options_.noise) {
    std::normal_distribution<double> g(0.0, 1.0);
    for (int k = 0; k < 3; ++k) {
      gyro_bias_[k] = plant_.noise.gyro_bias * g(rng_);
      accel_bias_[k] = plant_.noise.accelerometer_bias * g(rng_);
    }
  }
  mj_forward(m_, d_);
}

void Simulation::launchBall(const Eigen::Vector3d& momentum, double distance) {
  if (ball_ < 0 || !(momentum.norm() > 0)) return;
  const Eigen::Vector3d v = momentum / m_->body_mass[ball_];
  const Eigen::Vector3d target(d_->xipos + 3 * torso_);
  const Eigen::Vector3d dir = v.normalized();
  Eigen::Vector3d start = target - distance * dir;
  // Start the ball `gap` from the robot's surface along its path, so that it hits at the push
  // time (within gap / speed) instead of after a flight across the 0.6 m.
  const Eigen::Vector3d far = target - 1.0 * dir;
  int geom = -1;
  const double hit = mj_ray(m_, d_, far.data(), dir.data(), nullptr, 0, ball_, &geom);
  constexpr double gap = 0.01;
  if (hit >= 0.0 && hit < 1.0) {
    start = far + (hit - m_->geom_size[3 * m_->body_geomadr[ball_]] - gap) * dir;
  }
  double* q = d_->qpos + ball_qadr_;
  q[0] = start.x();
  q[1] = start.y();
  q[2] = start.z();
  q[3] = 1.0;
  q[4] = q[5] = q[6] = 0.0;
  double* w = d_->qvel + ball_dofadr_;
  for (int k = 0; k < 3; ++k) {
    w[k] = v[k];
    w[3 + k] = 0.0;
  }
  ball_flying_ = true;
  for (int k = 0; k < 6; ++k) d_->xfrc_applied[6 * ball_ + k] = 0.0;
  d_->xfrc_applied[6 * ball_ + 2] = -m_->body_mass[ball_] * m_->opt.gravity[2];  // straight flight
  mj_forward(m_, d_);
}

Eigen::Vector3d Simulation::ballMomentum() const {
  if (ball_ < 0) return Eigen::Vector3d::Zero();
  return m_->body_mass[ball_] * Eigen::Vector3d(d_->qvel + ball_dofadr_);  // free joint: world linear velocity
}

void Simulation::readSensors(Sensors& s) {
  const double* sd = d_->sensordata;
  s.time = d_->time;
  for (int i = 0; i < kJoints; ++i) {
    s.q[i] = sd[jpos_[i]];
    s.dq[i] = sd[jvel_[i]];
  }
  s.imu_orientation = Eigen::Quaterniond(sd[imu_quat_], sd[imu_quat_ + 1], sd[imu_quat_ + 2], sd[imu_quat_ + 3]);
  s.imu_orientation.normalize();
  s.imu_gyro = Eigen::Vector3d(sd + imu_gyro_);
  s.imu_accel = Eigen::Vector3d(sd + imu_accel_);
  for (int c = 0; c < kContacts; ++c) {
    // MuJoCo reads the wrench of the parent (foot) on the massless sole-plate body, which the
    // contact balances exactly: the support's wrench on the foot is its negative.
    s.ft[c] = trueForceTorque(c);
  }
  if (options_.noise) addNoise(s);
  const PlantPerturbation& pp = options_.perturbation;
  for (int c = 0; c < kContacts; ++c) s.ft[c] += pp.ft_offset[c];
  if (sensor_history_.size() > 1) {
    // Newest reading into the ring, then each group from its own age (the oldest available at the start).
    const int n = static_cast<int>(sensor_history_.size());
    sensor_head_ = (sensor_head_ + 1) % n;
    sensor_history_[sensor_head_] = s;
    sensor_count_ = std::min(sensor_count_ + 1, n);
    auto aged = [&](int latency) -> const Sensors& {
      return sensor_history_[(sensor_head_ - std::min(latency, sensor_count_ - 1) + n) % n];
    };
    const Sensors &enc = aged(pp.encoder_latency), &imu = aged(pp.imu_latency), &ft = aged(pp.ft_latency);
    s.q = enc.q;
    s.dq = enc.dq;
    s.imu_orientation = imu.imu_orientation;
    s.imu_gyro = imu.imu_gyro;
    s.imu_accel = imu.imu_accel;
    s.ft = ft.ft;
  }
}

void Simulation::addNoise(Sensors& s) {
  const SensorNoise& n = plant_.noise;
  std::normal_distribution<double> g(0.0, 1.0);
  for (int i = 0; i < kJoints; ++i) {
    s.q[i] += n.joint_position * g(rng_);
    s.dq[i] += n.joint_velocity * g(rng_);
  }
  const Eigen::Vector3d rot(g(rng_), g(rng_), g(rng_));
  const Eigen::Vector3d drot = n.imu_orientation * rot;
  if (drot.norm() > 0) {
    s.imu_orientation = (s.imu_orientation * Eigen::Quaterniond(Eigen::AngleAxisd(drot.norm(), drot.normalized()))).normalized();
  }
  if (n.imu_yaw_drift > 0) {  // the IMU's heading turns away from the world's
    s.imu_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(n.imu_yaw_drift * d_->time, Eigen::Vector3d::UnitZ())) *
                        s.imu_orientation;
  }
  for (int k = 0; k < 3; ++k) {
    s.imu_gyro[k] += n.gyro * g(rng_) + gyro_bias_[k];
    s.imu_accel[k] += n.accelerometer * g(rng_) + accel_bias_[k];
  }
  for (int c = 0; c < kContacts; ++c) {
    for (int k = 0; k < 3; ++k) {
      s.ft[c][k] += n.force * g(rng_);
      s.ft[c][3 + k] += n.torque * g(rng_);
    }
  }
}

void Simulation::applyCommand(const Command& c) {
  const int n = static_cast<int>(current_history_.size());
  current_head_ = (current_head_ + 1) % n;
  current_history_[current_head_] = c.current;
  const VectorJ& current = current_history_[(current_head_ + 1) % n];  // n - 1 calls ago (zero at first)
  for (int i = 0; i < kJoints; ++i) {
    const double a = std::isfinite(current[i]) ? current[i] : 0.0;
    d_->ctrl[act_[i]] = k_t_plant_[i] * a;  // MuJoCo clamps to ctrlrange
  }
}

void Simulation::step() {
  delivered_.setZero();
  if (options_.noise && (plant_.noise.gyro_bias_drift > 0 || plant_.noise.accelerometer_bias_drift > 0)) {
    std::normal_distribution<double> g(0.0, 1.0);
    const double sq = std::sqrt(options_.control_dt);
    for (int k = 0; k < 3; ++k) {
      gyro_bias_[k] += plant_.noise.gyro_bias_drift * sq * g(rng_);
      accel_bias_[k] += plant_.noise.accelerometer_bias_drift * sq * g(rng_);
    }
  }
  for (int k = 0; k < options_.substeps; ++k) {
    applyDamping();
    mj_step(m_, d_);
    addDeliveredTorque();
    if (ball_flying_) {
      for (int i = 0; i < d_->ncon; ++i) {
        if (m_->geom_bodyid[d_->contact[i].geom1] == ball_ || m_->geom_bodyid[d_->contact[i].geom2] == ball_) {
          ball_flying_ = false;  // first touch: gravity acts again
          d_->xfrc_applied[6 * ball_ + 2] = 0.0;
          break;
        }
      }
    }
  }
  delivered_ /= options_.substeps;
  // mj_step leaves sensordata of the state before its integration: refresh it for the new state.
  applyDamping();
  mj_forward(m_, d_);
}

void Simulation::setTorsoForce(const Eigen::Vector3d& f) {
  for (int k = 0; k < 6; ++k) d_->xfrc_applied[6 * torso_ + k] = k < 3 ? f[k] : 0.0;
}

VectorJ Simulation::appliedTorque() const {
  VectorJ tau;
  for (int i = 0; i < kJoints; ++i) tau[i] = d_->actuator_force[act_[i]];
  return tau;
}

VectorJ Simulation::jointPositions() const {
  VectorJ q;
  for (int i = 0; i < kJoints; ++i) q[i] = d_->qpos[qadr_[i]];
  return q;
}

double Simulation::torsoHeight() const { return d_->xpos[3 * torso_ + 2]; }

namespace {

// Pitch about world y and roll about world x of a body (ZYX Euler angles of R_world_body).
double bodyPitch(const mjData* d, int body) {
  const double* R = d->xmat + 9 * body;  // row-major
  return std::asin(std::clamp(-R[6], -1.0, 1.0));
}

double bodyRoll(const mjData* d, int body) {
  const double* R = d->xmat + 9 * body;
  return std::atan2(R[7], R[8]);
}

}  // namespace

double Simulation::torsoPitch() const { return bodyPitch(d_, torso_); }
double Simulation::torsoRoll() const { return bodyRoll(d_, torso_); }
double Simulation::footPitch(int c) const { return bodyPitch(d_, sole_body_[c]); }
double Simulation::footRoll(int c) const { return bodyRoll(d_, sole_body_[c]); }

double Simulation::footYaw(int c) const {
  const double* R = d_->xmat + 9 * sole_body_[c];
  return std::atan2(R[3], R[0]);
}

Vector6 Simulation::footVelocity(int c) const {
  mjtNum v[6];
  mj_objectVelocity(m_, d_, mjOBJ_BODY, sole_body_[c], v, 0);  // [angular; linear], world axes
  Vector6 out;
  for (int k = 0; k < 6; ++k) out[k] = v[k];
  return out;
}

int Simulation::supportActuator(const std::string& name) const {
  const int a = requireId(m_, mjOBJ_ACTUATOR, name, "support actuator");
  const int j = m_->actuator_trnid[2 * a];
  if (m_->actuator_trntype[a] != mjTRN_JOINT || (m_->jnt_type[j] != mjJNT_HINGE && m_->jnt_type[j] != mjJNT_SLIDE) ||
      !(m_->actuator_gainprm[mjNGAIN * a] > 0.0) || m_->actuator_biastype[a] != mjBIAS_AFFINE) {
    throw std::runtime_error("actuator '" + name + "' is not a position servo on a hinge or slide joint");
  }
  for (int i = 0; i < kJoints; ++i) {
    if (a == act_[i]) throw std::runtime_error("actuator '" + name + "' belongs to the robot");
  }
  return a;
}

void Simulation::setSupportTarget(int a, double q, double dq) {
  const int j = m_->actuator_trnid[2 * a];
  const double kp = m_->actuator_gainprm[mjNGAIN * a];
  d_->ctrl[a] = q + explicit_damping_[m_->jnt_dofadr[j]] / kp * dq;  // kp (q - q_a) + D (dq - q̇_a)
}

double Simulation::supportPosition(int a) const { return d_->qpos[m_->jnt_qposadr[m_->actuator_trnid[2 * a]]]; }

Eigen::Vector3d Simulation::centerOfMass() const {
  return Eigen::Vector3d(d_->subtree_com + 3 * torso_);  // the robot is the torso's subtree
}

Eigen::Vector3d Simulation::centerOfMassVelocity() const {
  return Eigen::Vector3d(d_->subtree_linvel + 3 * torso_);
}

bool Simulation::nonFootContact() const {
  for (int i = 0; i < d_->ncon; ++i) {
    const int b1 = m_->geom_bodyid[d_->contact[i].geom1], b2 = m_->geom_bodyid[d_->contact[i].geom2];
    if (ball_ >= 0 && (b1 == ball_ || b2 == ball_)) continue;  // the push itself
    for (int g : {d_->contact[i].geom1, d_->contact[i].geom2}) {
      const int b = m_->geom_bodyid[g];
      if (m_->body_rootid[b] != torso_) continue;  // not the robot (floor, other objects)
      if (b != sole_body_[0] && b != sole_body_[1]) return true;
    }
  }
  return false;
}

bool Simulation::ballTouchesRobot() const {
  if (ball_ < 0) return false;
  for (int i = 0; i < d_->ncon; ++i) {
    const int b1 = m_->geom_bodyid[d_->contact[i].geom1], b2 = m_->geom_bodyid[d_->contact[i].geom2];
    if ((b1 == ball_ && m_->body_rootid[b2] == torso_) || (b2 == ball_ && m_->body_rootid[b1] == torso_)) return true;
  }
  return false;
}

bool Simulation::feetTouch() const {
  for (int i = 0; i < d_->ncon; ++i) {
    const int b1 = m_->geom_bodyid[d_->contact[i].geom1], b2 = m_->geom_bodyid[d_->contact[i].geom2];
    if ((b1 == sole_body_[0] && b2 == sole_body_[1]) || (b1 == sole_body_[1] && b2 == sole_body_[0])) return true;
  }
  return false;
}

int Simulation::soleSupport(int c) const {
  for (int i = 0; i < d_->ncon; ++i) {
    const int b1 = m_->geom_bodyid[d_->contact[i].geom1], b2 = m_->geom_bodyid[d_->contact[i].geom2];
    if (b1 == sole_body_[c] && b2 != sole_body_[1 - c]) return b2;
    if (b2 == sole_body_[c] && b1 != sole_body_[1 - c]) return b1;
  }
  return -1;
}

namespace {

Eigen::Isometry3d bodyPose(const mjData* d, int b) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double* R = d->xmat + 9 * b;  // row-major
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) T.linear()(r, k) = R[3 * r + k];
  }
  T.translation() = Eigen::Vector3d(d->xpos + 3 * b);
  return T;
}

}  // namespace

Eigen::Isometry3d Simulation::soleInBody(int c, int b) const {
  return bodyPose(d_, b).inverse() * bodyPose(d_, sole_body_[c]);
}

Vector6 Simulation::trueForceTorque(int c) const {
  const double* sd = d_->sensordata;
  Vector6 ft;
  ft.head<3>() = -Eigen::Vector3d(sd + ft_force_[c]);  // MuJoCo: the foot's wrench on the plate
  ft.tail<3>() = -Eigen::Vector3d(sd + ft_torque_[c]);
  return ft;
}

Vector6 Simulation::wrenchInSole(int c, const Vector6& ft) const {
  Vector6 w;
  const Eigen::Vector3d f = R_sole_ft_[c] * ft.head<3>();
  w.head<3>() = f;
  w.tail<3>() = R_sole_ft_[c] * ft.tail<3>() + p_sole_ft_[c].cross(f);
  return w;
}

Eigen::Vector2d Simulation::copInSole(int c, const Vector6& ft, double min_fz) const {
  const Vector6 w = wrenchInSole(c, ft);
  if (!(w[2] >= min_fz)) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Moment about the sole origin of a force f at (x, y, 0): m_x = y f_z, m_y = -x f_z (z-parts of f
  // acting in the sole plane only), so the CoP is (-m_y, m_x) / f_z.
  return Eigen::Vector2d(-w[4] / w[2], w[3] / w[2]);
}

// After mj_step, d_ still holds the forces of the step just taken (only qpos, qvel moved on). The
// plant's joints have no springs; their damping is the explicit qfrc_applied of the step. A
// frictionloss row's Jacobian is the unit vector of its dof, so its efc_force is the joint torque
// directly.
void Simulation::addDeliveredTorque() {
  for (int i = 0; i < kJoints; ++i) {
    const int dof = dofadr_[i];
    delivered_[i] += d_->qfrc_actuator[dof] + d_->qfrc_applied[dof];
  }
  for (int r = 0; r < d_->nefc; ++r) {
    if (d_->efc_type[r] != mjCNSTR_FRICTION_DOF) continue;
    for (int i = 0; i < kJoints; ++i) {
      if (dofadr_[i] == d_->efc_id[r]) delivered_[i] += d_->efc_force[r];
    }
  }
}

}  // namespace hqp::sim
