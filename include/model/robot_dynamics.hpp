#pragma once
// RobotDynamics: the paper's class (§IV-A). calcWbcDependence(q, v) computes
// everything the whole-body controller needs in one forward and one backward
// sweep: M and h = C + G (eq. 1), the task frames' J and J̇v (eq. 2), their
// placements and velocities, the CoM, its Jacobian, the centroidal momentum
// matrix A_G and Ȧ_G v (the linear-momentum task, eq. 2).

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/backward_pass.hpp"
#include "model/centroidal.hpp"
#include "model/configuration.hpp"
#include "model/crba.hpp"
#include "model/data.hpp"
#include "model/frames.hpp"
#include "model/kinematics.hpp"
#include "model/rnea.hpp"

namespace hqp::model {

template <class Robot, int NumFrames>
class RobotDynamics {
 public:
  using VectorQ = typename Data<Robot>::VectorQ;
  using VectorV = typename Data<Robot>::VectorV;
  using MatrixV = typename Data<Robot>::MatrixV;
  using Jacobian = typename Data<Robot>::Jacobian;
  static constexpr int nq = Robot::nq;
  static constexpr int nv = Robot::nv;
  static constexpr int num_frames = NumFrames;
  static_assert(NumFrames >= 0, "number of task frames");

  // Task frames by index into Robot::frames (e.g. Robot::frameIndex("l_sole")).
  // Validated here, once: an index out of range is replaced by -1 (a world
  // frame with zero Jacobian) and reported by valid().
  explicit RobotDynamics(const std::array<int, NumFrames>& task_frames) noexcept
      : frames_(task_frames) {
    for (int k = 0; k < NumFrames; ++k) {
      if (frames_[k] < 0 || frames_[k] >= Robot::nframes) {
        frames_[k] = -1;
        valid_ = false;
      }
      J_[k].setZero();
      dJv_[k].setZero();
      vel_[k].setZero();
      X_[k].setIdentity();
    }
  }

  bool valid() const noexcept { return valid_; }
  int frame(int k) const noexcept { return frames_[k]; }

  // One pass: M, h, J, J̇v, placements, velocities of the task frames, CoM,
  // Jcom, A_G, Ȧ_G v.
  void calcWbcDependence(const VectorQ& q, const VectorV& v) noexcept {
    detail::forwardPass<Robot, detail::kMotion | detail::kForces>(d_, q, v, v);
    detail::backwardPass<Robot, detail::kComposite | detail::kMassMatrix | detail::kTau>(d_, d_.h);
    detail::centroidalFromComposite(d_, v);
    detail::centroidalBias(d_);
    for (int k = 0; k < NumFrames; ++k) updateFrame(k);
  }

  const MatrixV& M() const noexcept { return d_.M; }
  const VectorV& h() const noexcept { return d_.h; }
  const Jacobian& J(int k) const noexcept { return J_[k]; }
  const Vector6& dJv(int k) const noexcept { return dJv_[k]; }
  const Eigen::Isometry3d& placement(int k) const noexcept { return X_[k]; }
  const Vector6& velocity(int k) const noexcept { return vel_[k]; }
  const Eigen::Vector3d& com() const noexcept { return d_.com; }
  const Eigen::Vector3d& vcom() const noexcept { return d_.vcom; }
  const Eigen::Matrix<double, 3, Robot::nv>& Jcom() const noexcept { return d_.Jcom; }
  const Eigen::Matrix<double, 6, Robot::nv>& Ag() const noexcept { return d_.Ag; }
  const Vector6& dAg_v() const noexcept { return d_.dAg_v; }
  const Vector6& hg() const noexcept { return d_.hg; }  // [P; L_G] = A_G v
  double mass() const noexcept { return d_.mass; }
  const Data<Robot>& data() const noexcept { return d_; }

 private:
  void updateFrame(int k) noexcept {
    const int fi = frames_[k];
    if (fi < 0) return;
    const int b = Robot::frames[static_cast<std::size_t>(fi)].body;
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    detail::framePose(d_, fi, R, p);
    X_[k].linear() = R;
    X_[k].translation() = p;
    if (b < 0) return;  // a world-fixed frame: J, J̇v, velocity stay zero
    // Columns outside the frame's chain were zeroed by the constructor and are never written.
    detail::pointJacobian(d_, b, p, J_[k]);
    vel_[k] = shiftMotionTo(d_.V[b], p);
    dJv_[k] = detail::classicalAcceleration(d_.V[b], d_.A[b], p);
  }

  Data<Robot> d_;
  std::array<int, NumFrames> frames_;
  bool valid_ = true;
  std::array<Jacobian, NumFrames> J_;
  std::array<Vector6, NumFrames> dJv_;
  std::array<Vector6, NumFrames> vel_;
  std::array<Eigen::Isometry3d, NumFrames> X_;
};

}  // namespace hqp::model
