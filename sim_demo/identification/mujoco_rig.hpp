#pragma once
// A MuJoCo 2.2 identification rig: a robot hung by its root link (fixed to the
// world), legs free, with "true" parameters that differ from the URDF:
//   - every movable link's mass scaled by up to ±15 % (inertia scaled with it),
//     its CoM moved by up to ±2 cm per axis;
//   - Coulomb friction as MuJoCo frictionloss (1–5 N·m) with solimp near 1 so
//     that a stuck joint does not creep (docs: mujoco-2.2-notes.md);
//   - viscous friction 0.2–2 N·m·s/rad, applied explicitly as −b q̇ through
//     qfrc_applied (MuJoCo's Euler integrator treats dof_damping implicitly,
//     which would change the plant's effective law at 1 ms steps).
// Joints are mapped by name to the generated model's order.
// Used by sim_demo/identification/identification_rig.cpp and tests/ident.

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include <Eigen/Core>

#include "support/urdf_to_mujoco.hpp"

namespace hqp::ident_demo {

struct RigTruth {
  std::vector<double> coulomb;  // per model joint (N·m)
  std::vector<double> viscous;  // per model joint (N·m·s/rad)
};

class MujocoRig {
 public:
  // `links` / `joints`: the generated model's movable link and joint names.
  MujocoRig(const std::string& urdf, const std::vector<std::string>& links,
            const std::vector<std::string>& joints)
      : model_(hqp::test::loadUrdfFileIntoMujoco(urdf, /*floating=*/false)), links_(links) {
    for (const std::string& j : joints) {
      const int id = mj_name2id(model_.get(), mjOBJ_JOINT, j.c_str());
      if (id < 0) throw std::runtime_error("MuJoCo model has no joint " + j);
      qadr_.push_back(model_->jnt_qposadr[id]);
      vadr_.push_back(model_->jnt_dofadr[id]);
    }
    data_.reset(mj_makeData(model_.get()));
    truth_.coulomb.assign(joints.size(), 0.0);
    truth_.viscous.assign(joints.size(), 0.0);
  }

  int joints() const { return static_cast<int>(qadr_.size()); }
  // Time constant of the frictionloss constraint (s, ≥ 2 time steps); set before perturb().
  double friction_timeconst = 0.004;
  const RigTruth& truth() const { return truth_; }
  mjModel* model() { return model_.get(); }

  // Perturbs masses, CoMs and sets friction (Coulomb in [c_lo, c_hi], viscous in [v_lo, v_hi]).
  void perturb(unsigned seed, double mass_range = 0.15, double com_offset = 0.02,
               double c_lo = 1.0, double c_hi = 5.0, double v_lo = 0.2, double v_hi = 2.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
    mjModel* m = model_.get();
    for (const std::string& l : links_) {
      const int b = mj_name2id(m, mjOBJ_BODY, l.c_str());
      if (b < 0) throw std::runtime_error("MuJoCo model has no body " + l);
      const double k = 1.0 + mass_range * u(rng);
      m->body_mass[b] *= k;
      for (int i = 0; i < 3; ++i) {
        m->body_inertia[3 * b + i] *= k;
        m->body_ipos[3 * b + i] += com_offset * u(rng);
      }
      m->body_sameframe[b] = 0;  // the CoM moved off the body origin
      m->body_simple[b] = 0;
    }
    for (int j = 0; j < joints(); ++j) {
      truth_.coulomb[j] = c_lo + (c_hi - c_lo) * u01(rng);
      truth_.viscous[j] = v_lo + (v_hi - v_lo) * u01(rng);
    }
    setFriction(true);
    mj_setConst(m, data_.get());
  }

  // Coulomb friction as frictionloss (on) or none (off: pure rigid body + the
  // explicit viscous term).
  void setFriction(bool coulomb_on) {
    mjModel* m = model_.get();
    for (int j = 0; j < joints(); ++j) {
      m->dof_frictionloss[vadr_[j]] = coulomb_on ? truth_.coulomb[j] : 0.0;
      m->dof_damping[vadr_[j]] = 0.0;
      // solimp (d0, dwidth, width, mid, power) near 1: almost hard friction, little creep.
      const double solimp[5] = {0.99, 0.999, 0.001, 0.5, 2.0};
      for (int k = 0; k < 5; ++k) m->dof_solimp[mjNIMP * vadr_[j] + k] = solimp[k];
      // solref: a short time constant, so that a sliding joint feels the full
      // frictionloss even where it is light (MuJoCo's default 0.02 s makes the
      // friction of a light ankle act like a damper up to ~10 rad/s).
      m->dof_solref[mjNREF * vadr_[j]] = friction_timeconst;
      m->dof_solref[mjNREF * vadr_[j] + 1] = 1.0;
    }
    m->opt.disableflags = mjDSBL_EQUALITY | mjDSBL_LIMIT | mjDSBL_CONTACT | mjDSBL_PASSIVE |
                          mjDSBL_ACTUATION;
    if (!coulomb_on) m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_FRICTIONLOSS;
    m->opt.timestep = 0.001;
    m->opt.integrator = mjINT_EULER;
  }

  // Rigid-body inverse dynamics of the (perturbed) plant, no friction: M q̈ + h.
  Eigen::VectorXd inverseDynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& dq,
                                  const Eigen::VectorXd& ddq) {
    mjModel* m = model_.get();
    mjData* d = data_.get();
    const int saved = m->opt.disableflags;
    m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_FRICTIONLOSS;
    mj_resetData(m, d);
    for (int j = 0; j < joints(); ++j) {
      d->qpos[qadr_[j]] = q[j];
      d->qvel[vadr_[j]] = dq[j];
      d->qacc[vadr_[j]] = ddq[j];
    }
    mj_inverse(m, d);
    m->opt.disableflags = saved;
    Eigen::VectorXd tau(joints());
    for (int j = 0; j < joints(); ++j) tau[j] = d->qfrc_inverse[vadr_[j]];
    return tau;
  }

  // Starts the simulation at rest at q.
  void reset(const Eigen::VectorXd& q) {
    mj_resetData(model_.get(), data_.get());
    for (int j = 0; j < joints(); ++j) data_->qpos[qadr_[j]] = q[j];
    mj_forward(model_.get(), data_.get());
  }
  Eigen::VectorXd q() const {
    Eigen::VectorXd x(joints());
    for (int j = 0; j < joints(); ++j) x[j] = data_->qpos[qadr_[j]];
    return x;
  }
  Eigen::VectorXd dq() const {
    Eigen::VectorXd x(joints());
    for (int j = 0; j < joints(); ++j) x[j] = data_->qvel[vadr_[j]];
    return x;
  }
  // One 1 ms step with motor torque tau (the plant adds −b q̇ and its Coulomb friction).
  void step(const Eigen::VectorXd& tau) {
    for (int j = 0; j < joints(); ++j) {
      data_->qfrc_applied[vadr_[j]] = tau[j] - truth_.viscous[j] * data_->qvel[vadr_[j]];
    }
    mj_step(model_.get(), data_.get());
  }
  double time() const { return data_->time; }

 private:
  hqp::test::MjModelPtr model_;
  hqp::test::MjDataPtr data_;
  std::vector<std::string> links_;
  std::vector<int> qadr_, vadr_;
  RigTruth truth_;
};

}  // namespace hqp::ident_demo
