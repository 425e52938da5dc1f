#pragma once
// MuJoCo 2.2.2 as the independent reference for the dynamics layer, with every quantity
// converted to OUR conventions (docs/conventions.md). Test code only: dynamic sizes, heap,
// exceptions are all fine here.
//
// Velocity conventions. Ours: v = [v_b; w_b; qdot] with v_b, w_b the base twist in the base
// frame. MuJoCo's free joint: [pdot (world); w_b (body)]. Joints map by name (MuJoCo orders
// DoFs depth-first in its own way). So v_mj = S v with
//   S = P * blockdiag(R, I3, I_nj),  P the DoF permutation, R = R_world_base.
// Differentiating along a motion with our vdot = 0 (the "q̈ = 0" of every bias term):
//   vdot_mj = Sdot v = P [R (w_b x v_b); 0; 0]                       (a_mj below)
// Generalized forces transform with S^T (power v_mj^T f_mj = v^T S^T f_mj), hence
//   M = S^T M_mj S
//   h = S^T (M_mj Sdot v + h_mj)     = S^T rne_mj(q, v_mj, qacc = Sdot v)
//   G = S^T G_mj                      (bias at v = 0: Sdot v = 0 there)
// Task-space maps act on velocities: J = J_mj S, and the classical bias acceleration at
// vdot = 0 is  J_mj vdot_mj + Jdot_mj v_mj = J_mj Sdot v + Jdot_mj v_mj, i.e. exactly what
// MuJoCo's recursive acceleration pass gives with qacc = Sdot v (and gravity off, because
// mj_rnePostConstraint starts the world at -g). mj_objectAcceleration then turns MuJoCo's
// spatial acceleration into the classical one at the object origin (adds w x v).
//
// Centroidal quantities (Wensing & Orin): h_G = [P; L_G] world-aligned at the CoM.
//   P = sum m_i pdot_i,  L_G = sum (I_i w_i + m_i (p_i - c) x pdot_i)   (p_i body CoM)
// For dAg_v = d/dt h_G at vdot = 0 (A_G qddot vanishes there):
//   d/dt P   = sum m_i pddot_i
//   d/dt L_G = sum (I_i wdot_i + w_i x I_i w_i + m_i (p_i - c) x pddot_i)
// (d/dt I_i = [w_i]x I_i - I_i [w_i]x, and sum m_i (pdot_i - cdot) x pdot_i = -cdot x P = 0),
// with pddot_i, wdot_i the classical accelerations from the same MuJoCo pass as Jdot v.
// With a floating base, h_G and the CoM come from MuJoCo's subtree quantities of the base
// body (subtree_com, mj_jacSubtreeCom, mj_subtreeVel); with a fixed base (root link welded to
// the world, its mass not part of our model) from sums over the bodies that can move.
// A_G itself (MuJoCo has no centroidal matrix) is summed per body from mj_jacBodyCom:
//   A_G = sum [m_i Jp_i; I_i Jr_i + m_i (p_i - c) x Jp_i] S.

#include <mujoco/mujoco.h>

#include <Eigen/Dense>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "support/urdf_to_mujoco.hpp"

namespace hqp::test {

// Where one of our 1-DoF joints sits in our q and v.
struct JointSlot {
  std::string name;
  int idx_q;
  int idx_v;
};

class MujocoReference {
 public:
  using Vector6d = Eigen::Matrix<double, 6, 1>;

  // `floating`: q[0..6], v[0..5] belong to a free joint on body `base_link`.
  MujocoReference(MjModelPtr model, bool floating, const std::string& base_link,
                  std::vector<JointSlot> joints, int nq, int nv)
      : m_(std::move(model)), d_(mj_makeData(m_.get())), d0_(mj_makeData(m_.get())),
        floating_(floating), joints_(std::move(joints)), nq_(nq), nv_(nv) {
    if (m_->nq != nq || m_->nv != nv) {
      throw std::runtime_error("MuJoCo model has nq/nv " + std::to_string(m_->nq) + "/" +
                               std::to_string(m_->nv) + ", ours " + std::to_string(nq) + "/" +
                               std::to_string(nv));
    }
    base_body_ = floating ? bodyId(base_link) : 0;
    if (floating) {
      const int jnt = m_->body_jntadr[base_body_];
      if (jnt < 0 || m_->jnt_type[jnt] != mjJNT_FREE) {
        throw std::runtime_error("base body " + base_link + " has no free joint in MuJoCo");
      }
      base_qpos_ = m_->jnt_qposadr[jnt];
      base_dof_ = m_->jnt_dofadr[jnt];
    }
    for (const auto& j : joints_) {
      const int id = mj_name2id(m_.get(), mjOBJ_JOINT, j.name.c_str());
      if (id < 0) throw std::runtime_error("joint " + j.name + " not in the MuJoCo model");
      if (m_->jnt_type[id] != mjJNT_HINGE && m_->jnt_type[id] != mjJNT_SLIDE) {
        throw std::runtime_error("joint " + j.name + " is not 1-DoF in MuJoCo");
      }
      qpos_of_.push_back(m_->jnt_qposadr[id]);
      dof_of_.push_back(m_->jnt_dofadr[id]);
    }
    for (int i = 1; i < m_->nbody; ++i) {
      if (m_->body_weldid[i] != 0) moving_bodies_.push_back(i);
    }
  }

  int bodyId(const std::string& link) const {
    const int id = mj_name2id(m_.get(), mjOBJ_BODY, link.c_str());
    if (id < 0) throw std::runtime_error("link " + link + " is not a MuJoCo body");
    return id;
  }

  // Our q (positions, quaternion w x y z) -> MuJoCo qpos.
  Eigen::VectorXd toQpos(const Eigen::VectorXd& q) const {
    Eigen::VectorXd qpos(nq_);
    if (floating_) qpos.segment<7>(base_qpos_) = q.head<7>();
    for (std::size_t k = 0; k < joints_.size(); ++k) qpos[qpos_of_[k]] = q[joints_[k].idx_q];
    return qpos;
  }

  // MuJoCo qpos -> our q (inverse of toQpos).
  Eigen::VectorXd fromQpos(const Eigen::VectorXd& qpos) const {
    Eigen::VectorXd q(nq_);
    if (floating_) q.head<7>() = qpos.segment<7>(base_qpos_);
    for (std::size_t k = 0; k < joints_.size(); ++k) q[joints_[k].idx_q] = qpos[qpos_of_[k]];
    return q;
  }

  // S with v_mj = S v at configuration q (see the file comment).
  Eigen::MatrixXd velocityMap(const Eigen::VectorXd& q) const {
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(nv_, nv_);
    if (floating_) {
      S.block<3, 3>(base_dof_, 0) = baseRotation(q);
      S.block<3, 3>(base_dof_ + 3, 3).setIdentity();
    }
    for (std::size_t k = 0; k < joints_.size(); ++k) S(dof_of_[k], joints_[k].idx_v) = 1.0;
    return S;
  }

  static Eigen::Matrix3d baseRotation(const Eigen::VectorXd& q) {
    return Eigen::Quaterniond(q[3], q[4], q[5], q[6]).normalized().toRotationMatrix();
  }

  // Runs MuJoCo at (q, v) and fills every result below.
  void compute(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    const mjModel* m = m_.get();
    mjData* d = d_.get();
    S = velocityMap(q);
    const Eigen::VectorXd qpos = toQpos(q);
    const Eigen::VectorXd qvel = S * v;
    Eigen::VectorXd a_mj = Eigen::VectorXd::Zero(nv_);  // Sdot v
    if (floating_) {
      const Eigen::Vector3d vb = v.head<3>(), wb = v.segment<3>(3);
      a_mj.segment<3>(base_dof_) = baseRotation(q) * wb.cross(vb);
    }

    // Zero velocity: G.
    Eigen::Map<Eigen::VectorXd>(d0_->qpos, nq_) = qpos;
    Eigen::Map<Eigen::VectorXd>(d0_->qvel, nv_).setZero();
    mj_forward(m, d0_.get());
    g = S.transpose() * Eigen::Map<const Eigen::VectorXd>(d0_->qfrc_bias, nv_);

    // Full state: M, h, kinematics.
    Eigen::Map<Eigen::VectorXd>(d->qpos, nq_) = qpos;
    Eigen::Map<Eigen::VectorXd>(d->qvel, nv_) = qvel;
    mj_forward(m, d);
    using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    RowMat M_mj(nv_, nv_);
    mj_fullM(m, M_mj.data(), d->qM);
    M = S.transpose() * M_mj * S;
    M_mujoco = M_mj;
    h_mujoco = Eigen::Map<const Eigen::VectorXd>(d->qfrc_bias, nv_);

    Eigen::Map<Eigen::VectorXd>(d->qacc, nv_) = a_mj;
    Eigen::VectorXd rne(nv_);
    mj_rne(m, d, 1, rne.data());
    h = S.transpose() * rne;

    // Classical accelerations at vdot = 0 without gravity (cacc for Jdot v and dAg_v).
    mjModel* mm = m_.get();
    const double grav[3] = {mm->opt.gravity[0], mm->opt.gravity[1], mm->opt.gravity[2]};
    mm->opt.gravity[0] = mm->opt.gravity[1] = mm->opt.gravity[2] = 0.0;
    mj_rnePostConstraint(m, d);
    for (int k = 0; k < 3; ++k) mm->opt.gravity[k] = grav[k];

    mj_subtreeVel(m, d);
    computeCentroidal();
  }

  // ---- frames (every URDF link is a MuJoCo body of the same name: fusestatic="false") ----
  Eigen::Isometry3d placement(const std::string& link) const {
    const int b = bodyId(link);
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Eigen::Map<const Eigen::Vector3d>(d_->xpos + 3 * b);
    X.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d_->xmat + 9 * b);
    return X;
  }

  // 6 x nv, world-aligned at the link origin, rows [linear; angular], columns our v.
  Eigen::MatrixXd jacobian(const std::string& link) const {
    using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    RowMat jp(3, nv_), jr(3, nv_);
    mj_jacBody(m_.get(), d_.get(), jp.data(), jr.data(), bodyId(link));
    Eigen::MatrixXd J(6, nv_);
    J.topRows<3>() = jp;
    J.bottomRows<3>() = jr;
    return J * S;
  }

  // [pdot; w] of the link origin, world-aligned (MuJoCo returns [w; pdot]).
  Vector6d velocity(const std::string& link) const {
    return swapHalves(objectVel(mjOBJ_XBODY, bodyId(link)));
  }

  // Classical [pddot; wdot] of the link origin at our vdot = 0: our Jdot v.
  Vector6d biasAcceleration(const std::string& link) const {
    return swapHalves(objectAcc(mjOBJ_XBODY, bodyId(link)));
  }

  // ---- results of compute() ----
  Eigen::MatrixXd S;          // v_mj = S v                  (nv x nv)
  Eigen::MatrixXd M;          // mass matrix, our v          (nv x nv)
  Eigen::VectorXd h;          // C v + G, our v              (nv)
  Eigen::VectorXd g;          // G                           (nv)
  Eigen::MatrixXd M_mujoco;   // MuJoCo's own M, its v       (nv x nv)
  Eigen::VectorXd h_mujoco;   // MuJoCo's qfrc_bias          (nv)
  double mass = 0.0;          // mass that moves with q
  Eigen::Vector3d com;        // CoM, world                  (3)
  Eigen::Vector3d vcom;       // CoM velocity, world         (3)
  Eigen::MatrixXd Jcom;       // CoM Jacobian, our v         (3 x nv)
  Eigen::MatrixXd Ag;         // centroidal momentum matrix, our v, per-body sums (6 x nv)
  Vector6d hG;                // [P; L_G]                    (6)
  Vector6d hG_bodies;         // same, always from per-body sums (cross-check of hG)
  Vector6d dhG;               // d/dt h_G at vdot = 0: our dAg_v (6)

  const mjModel* model() const { return m_.get(); }
  mjData* data() { return d_.get(); }
  bool floating() const { return floating_; }
  int baseBody() const { return base_body_; }

  static Vector6d swapHalves(const Vector6d& x) {
    Vector6d y;
    y << x.tail<3>(), x.head<3>();
    return y;
  }

  // MuJoCo's raw [w; v] / [wdot; a] (world orientation) of an object.
  Vector6d objectVel(int objtype, int id) const {
    Vector6d r;
    mj_objectVelocity(m_.get(), d_.get(), objtype, id, r.data(), 0);
    return r;
  }
  Vector6d objectAcc(int objtype, int id) const {
    Vector6d r;
    mj_objectAcceleration(m_.get(), d_.get(), objtype, id, r.data(), 0);
    return r;
  }

 private:
  Eigen::Matrix3d worldInertia(int b) const {
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Ri(d_->ximat + 9 * b);
    const Eigen::Vector3d I = Eigen::Map<const Eigen::Vector3d>(m_->body_inertia + 3 * b);
    return Ri * I.asDiagonal() * Ri.transpose();
  }

  void computeCentroidal() {
    const mjModel* m = m_.get();
    mjData* d = d_.get();
    // Per-body sums over the bodies that move (all of them with a floating base).
    double mb = 0.0;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    RowMat jp(3, nv_), jr(3, nv_);
    Eigen::MatrixXd Jc_mj = Eigen::MatrixXd::Zero(3, nv_);
    for (int b : moving_bodies_) {
      const double mi = m->body_mass[b];
      mb += mi;
      c += mi * Eigen::Map<const Eigen::Vector3d>(d->xipos + 3 * b);
      mj_jacBodyCom(m, d, jp.data(), nullptr, b);
      Jc_mj += mi * Eigen::MatrixXd(jp);
    }
    c /= mb;
    Jc_mj /= mb;
    // A_G column by column: sum [m_i Jp_i; I_i Jr_i + m_i (p_i - c) x Jp_i] (Jacobians at the body CoM).
    Eigen::MatrixXd A_mj = Eigen::MatrixXd::Zero(6, nv_);
    for (int b : moving_bodies_) {
      const double mi = m->body_mass[b];
      const Eigen::Vector3d r = Eigen::Map<const Eigen::Vector3d>(d->xipos + 3 * b) - c;
      mj_jacBodyCom(m, d, jp.data(), jr.data(), b);
      Eigen::Matrix3d rx;
      rx << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
      A_mj.topRows<3>() += mi * jp;
      A_mj.bottomRows<3>() += worldInertia(b) * jr + mi * rx * jp;
    }
    Ag = A_mj * S;
    Eigen::Vector3d P = Eigen::Vector3d::Zero(), L = Eigen::Vector3d::Zero();
    Eigen::Vector3d dP = Eigen::Vector3d::Zero(), dL = Eigen::Vector3d::Zero();
    for (int b : moving_bodies_) {
      const double mi = m->body_mass[b];
      const Eigen::Vector3d r = Eigen::Map<const Eigen::Vector3d>(d->xipos + 3 * b) - c;
      const Vector6d vel = objectVel(mjOBJ_BODY, b);  // [w; pdot] at the body CoM
      const Vector6d acc = objectAcc(mjOBJ_BODY, b);  // [wdot; pddot] classical
      const Eigen::Vector3d w = vel.head<3>(), pd = vel.tail<3>();
      const Eigen::Vector3d wd = acc.head<3>(), pdd = acc.tail<3>();
      const Eigen::Matrix3d I = worldInertia(b);
      P += mi * pd;
      L += I * w + mi * r.cross(pd);
      dP += mi * pdd;
      dL += I * wd + w.cross(I * w) + mi * r.cross(pdd);
    }
    hG_bodies << P, L;
    dhG << dP, dL;

    if (floating_) {
      const int b = base_body_;
      mass = m->body_subtreemass[b];
      com = Eigen::Map<const Eigen::Vector3d>(d->subtree_com + 3 * b);
      mj_jacSubtreeCom(m, d, jp.data(), b);
      Jcom = Eigen::MatrixXd(jp) * S;
      vcom = Eigen::Map<const Eigen::Vector3d>(d->subtree_linvel + 3 * b);
      hG << mass * vcom, Eigen::Map<const Eigen::Vector3d>(d->subtree_angmom + 3 * b);
    } else {
      mass = mb;
      com = c;
      Jcom = Jc_mj * S;
      vcom = P / mb;
      hG = hG_bodies;
    }
  }

  MjModelPtr m_;
  MjDataPtr d_, d0_;
  bool floating_;
  std::vector<JointSlot> joints_;
  int nq_, nv_;
  int base_body_ = 0, base_qpos_ = 0, base_dof_ = 0;
  std::vector<int> qpos_of_, dof_of_;
  std::vector<int> moving_bodies_;
};

// A reference for a generated robot description (docs/generated-model.md): joint names and
// slots come from Robot::bodies.
// exact_inertia: see urdf_to_mujoco.hpp.
template <class Robot>
MujocoReference makeMujocoReference(const std::string& urdf_path, bool exact_inertia = true) {
  std::vector<JointSlot> joints;
  for (int i = Robot::floating_base ? 1 : 0; i < Robot::nb; ++i) {
    joints.push_back({Robot::bodies[i].joint, Robot::bodies[i].idx_q, Robot::bodies[i].idx_v});
  }
  return MujocoReference(loadUrdfFileIntoMujoco(urdf_path, Robot::floating_base, exact_inertia),
                         Robot::floating_base, Robot::bodies[0].name, std::move(joints), Robot::nq,
                         Robot::nv);
}

}  // namespace hqp::test
