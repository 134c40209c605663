// Autodiff Ceres cost functors of the joint energy (Eq. 4 and Eq. 7 of the paper).
//
// Pose blocks are world_from_cam [qx qy qz qw tx ty tz] (see pose_block.h); the paper writes
// T_nw = (world_from_cam_n)^-1, so R_nw = R_wn^T and t_nw = -R_wn^T t_wn.
// Every functor stores its measurement and square-root information as const members; residuals
// are "measured minus predicted" as in the paper. Weights (alpha, beta, gamma) and robust kernels
// are applied at problem building through ceres::ScaledLoss, not here.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "geometry/camera.h"

namespace jvl::optim {

// Pinhole projection pi of a camera-frame point or direction (Eq. 1), templated for Jets.
template <typename T>
void ProjectPinhole(const PinholeCamera& camera, const Eigen::Matrix<T, 3, 1>& p, T* uv) {
  uv[0] = T(camera.fx) * p.x() / p.z() + T(camera.cx);
  uv[1] = T(camera.fy) * p.y() / p.z() + T(camera.cy);
}

// Visual reprojection error e_V(i, j) (Sec. 4.2 step 1, as in ORB-SLAM):
//   X_c = R_iw X + t_iw = R_wi^T (X - t_wi),   r = sqrt_info * (x - pi(X_c))   [2]
// sqrt_info = 1 / sigma with sigma = 1.2^octave px (ORB-SLAM's information is 1 / sigma^2).
// A point at depth <= kMinDepth makes the evaluation fail (Ceres then rejects the step); the
// problem builder drops observations that are behind the camera at the initial estimate.
class VisualReprojectionCost {
 public:
  static constexpr double kMinDepth = 1e-6;

  // offset: the observing camera's offset from the pose's frame (x_camera = x_pose + offset;
  // a rectified camera other than camera 0, Calibration::CameraOffset).
  VisualReprojectionCost(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                         double sqrt_information,
                         const Eigen::Vector3d& offset = Eigen::Vector3d::Zero())
      : camera_(camera), uv_(uv), sqrt_information_(sqrt_information), offset_(offset) {}

  template <typename T>
  bool operator()(const T* world_from_cam, const T* point_world, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_wc(world_from_cam);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wc(world_from_cam + 4);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> x_w(point_world);
    const Eigen::Matrix<T, 3, 1> x_c = q_wc.conjugate() * (x_w - t_wc) + offset_.cast<T>();
    if (!(x_c.z() > T(kMinDepth))) return false;
    T uv[2];
    ProjectPinhole(camera_, x_c, uv);
    residual[0] = T(sqrt_information_) * (T(uv_.x()) - uv[0]);
    residual[1] = T(sqrt_information_) * (T(uv_.y()) - uv[1]);
    return true;
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sqrt_information,
                                     const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
    return new ceres::AutoDiffCostFunction<VisualReprojectionCost, 2, 7, 3>(
        new VisualReprojectionCost(camera, uv, sqrt_information, offset));
  }

 private:
  const PinholeCamera camera_;
  const Eigen::Vector2d uv_;
  const double sqrt_information_;
  const Eigen::Vector3d offset_;
};

// Point-to-IMLS-surface error e_L(n, j) (Eq. 3; supplement Eq. 1 for reused correspondences):
//   c_p_x = T_cw T_nw^-1 p_x = R_wc^T (R_wn p_x + t_wn - t_wc)
//   r = sqrt_info * (c_p_x - c_p_y) . n_c                                         [1]
// p_x is the sampled point in keyframe n's frame; c_p_y (its projection onto the IMLS surface)
// and the unit normal n_c are in keyframe c's frame. n != c (the builder rejects n == c: the
// residual would not depend on the pose at all).
class PointToImlsCost {
 public:
  PointToImlsCost(const Eigen::Vector3d& p_x, const Eigen::Vector3d& c_p_y,
                  const Eigen::Vector3d& c_normal, double sqrt_information)
      : p_x_(p_x), c_p_y_(c_p_y), c_normal_(c_normal), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* world_from_n, const T* world_from_c, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_wn(world_from_n);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wn(world_from_n + 4);
    const Eigen::Map<const Eigen::Quaternion<T>> q_wc(world_from_c);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wc(world_from_c + 4);
    const Eigen::Matrix<T, 3, 1> p_w = q_wn * p_x_.cast<T>() + t_wn;
    const Eigen::Matrix<T, 3, 1> c_p_x = q_wc.conjugate() * (p_w - t_wc);
    residual[0] = T(sqrt_information_) * (c_p_x - c_p_y_.cast<T>()).dot(c_normal_.cast<T>());
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_x, const Eigen::Vector3d& c_p_y,
                                     const Eigen::Vector3d& c_normal, double sqrt_information) {
    return new ceres::AutoDiffCostFunction<PointToImlsCost, 1, 7, 7>(
        new PointToImlsCost(p_x, c_p_y, c_normal, sqrt_information));
  }

 private:
  const Eigen::Vector3d p_x_;
  const Eigen::Vector3d c_p_y_;
  const Eigen::Vector3d c_normal_;
  const double sqrt_information_;
};

// Visual-point-on-LiDAR-surface error e_S(k, j) (beyond the paper, docs/global_opt.md "Surface
// term"): a map point X observed by keyframe k lies on the surface of k's own scan,
//   X_k = R_wk^T (X - t_wk),   r = sqrt_info * (X_k - k_p_y) . n_k                     [1]
// with k_p_y the projection of X_k onto the IMLS surface of k's scan and n_k its unit normal,
// both in k's frame (found at the start of the round). Together with the point's reprojections
// it fixes how far the cameras moved also where the scans alone cannot (a street without cross
// structure), as a depth measurement would.
// The block has two residuals, [r, 0]: every residual block on a map point then has the size of
// a reprojection error (2), so Ceres' Schur elimination runs its code specialised for 2 x 3 x 6
// blocks instead of the generic dynamic-size one it falls back to when the sizes differ (the
// cost and its derivatives are those of r alone; JointSolveResult::schur_structure).
class PointToSurfaceCost {
 public:
  PointToSurfaceCost(const Eigen::Vector3d& k_p_y, const Eigen::Vector3d& k_normal,
                     double sqrt_information)
      : k_p_y_(k_p_y), k_normal_(k_normal), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* world_from_k, const T* point, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_wk(world_from_k);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wk(world_from_k + 4);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> x_w(point);
    const Eigen::Matrix<T, 3, 1> x_k = q_wk.conjugate() * (x_w - t_wk);
    residual[0] = T(sqrt_information_) * (x_k - k_p_y_.cast<T>()).dot(k_normal_.cast<T>());
    residual[1] = T(0);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& k_p_y, const Eigen::Vector3d& k_normal,
                                     double sqrt_information) {
    return new ceres::AutoDiffCostFunction<PointToSurfaceCost, 2, 7, 3>(
        new PointToSurfaceCost(k_p_y, k_normal, sqrt_information));
  }

 private:
  const Eigen::Vector3d k_p_y_;
  const Eigen::Vector3d k_normal_;
  const double sqrt_information_;
};

// Direction projection error e_D(n) (Eq. 5-6): the direction prior d_w = [d_w, 0] is a point at
// infinity, so its image is the vanishing point
//   d_n = R_nw d_w = R_wn^T d_w,   r = sqrt_info * (v - pi(d_n))                   [2]
// Only the rotation enters: the derivative with respect to the translation part of the block is
// exactly zero. Guards (not in the paper):
//  - a line direction is unoriented and pi(d) = pi(-d), so d_n is flipped to z >= 0;
//  - if z < min_z (direction nearly parallel to the image plane, the VP runs to infinity) z is
//    clamped to min_z: the residual stays finite (large) and still pulls the direction back
//    towards the optical axis through its x/y derivatives.
class DirectionProjectionCost {
 public:
  DirectionProjectionCost(const PinholeCamera& camera, const Eigen::Vector2d& vp,
                          const Eigen::Vector3d& direction_world,
                          const Eigen::Vector2d& sqrt_information, double min_z)
      : camera_(camera),
        vp_(vp),
        direction_world_(direction_world.normalized()),
        sqrt_information_(sqrt_information),
        min_z_(min_z) {}

  template <typename T>
  bool operator()(const T* world_from_cam, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_wc(world_from_cam);
    Eigen::Matrix<T, 3, 1> d_n = q_wc.conjugate() * direction_world_.cast<T>();
    if (d_n.z() < T(0)) d_n = -d_n;
    if (d_n.z() < T(min_z_)) d_n.z() = T(min_z_);
    T uv[2];
    ProjectPinhole(camera_, d_n, uv);
    residual[0] = T(sqrt_information_.x()) * (T(vp_.x()) - uv[0]);
    residual[1] = T(sqrt_information_.y()) * (T(vp_.y()) - uv[1]);
    return true;
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& vp,
                                     const Eigen::Vector3d& direction_world,
                                     const Eigen::Vector2d& sqrt_information, double min_z) {
    return new ceres::AutoDiffCostFunction<DirectionProjectionCost, 2, 7>(
        new DirectionProjectionCost(camera, vp, direction_world, sqrt_information, min_z));
  }

 private:
  const PinholeCamera camera_;
  const Eigen::Vector2d vp_;
  const Eigen::Vector3d direction_world_;
  const Eigen::Vector2d sqrt_information_;  // per image axis (u, v)
  const double min_z_;
};

// Relative-motion error e_O(i, j) of two keyframes against a measured motion Z = T_i^-1 T_j (an
// odometry's motion between their frames; beyond the paper, docs/global_opt.md "Odometry term"):
//   E = Z^-1 (T_i^-1 T_j),   r = [sqrt_info_rot .* 2 vec(q_E); sqrt_info_trans .* t_E]   [6]
// with q_E taken with w >= 0 (2 vec(q) is the rotation vector to second order) and a square-root
// information per axis of the frame j.
class RelativePoseCost {
 public:
  RelativePoseCost(const Eigen::Quaterniond& q_ij, const Eigen::Vector3d& t_ij,
                   const Eigen::Vector3d& sqrt_info_rot, const Eigen::Vector3d& sqrt_info_trans)
      : q_ij_inverse_(q_ij.conjugate().normalized()),
        t_ij_(t_ij),
        sqrt_info_rot_(sqrt_info_rot),
        sqrt_info_trans_(sqrt_info_trans) {}

  template <typename T>
  bool operator()(const T* world_from_i, const T* world_from_j, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_wi(world_from_i);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wi(world_from_i + 4);
    const Eigen::Map<const Eigen::Quaternion<T>> q_wj(world_from_j);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wj(world_from_j + 4);
    const Eigen::Quaternion<T> q_inv = q_ij_inverse_.cast<T>();
    const Eigen::Quaternion<T> q_i_inv = q_wi.conjugate();
    const Eigen::Matrix<T, 3, 1> t_rel = q_i_inv * (t_wj - t_wi);
    Eigen::Quaternion<T> q_err = q_inv * (q_i_inv * q_wj);
    if (q_err.w() < T(0)) q_err.coeffs() = -q_err.coeffs();
    const Eigen::Matrix<T, 3, 1> t_err = q_inv * (t_rel - t_ij_.cast<T>());
    for (int k = 0; k < 3; ++k) {
      residual[k] = T(2.0 * sqrt_info_rot_(k)) * q_err.vec()(k);
      residual[3 + k] = T(sqrt_info_trans_(k)) * t_err(k);
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Quaterniond& q_ij, const Eigen::Vector3d& t_ij,
                                     const Eigen::Vector3d& sqrt_info_rot,
                                     const Eigen::Vector3d& sqrt_info_trans) {
    return new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 7, 7>(
        new RelativePoseCost(q_ij, t_ij, sqrt_info_rot, sqrt_info_trans));
  }

 private:
  const Eigen::Quaterniond q_ij_inverse_;
  const Eigen::Vector3d t_ij_;
  const Eigen::Vector3d sqrt_info_rot_;
  const Eigen::Vector3d sqrt_info_trans_;
};

// Vehicle-motion error e_M(a, b, c) of three consecutive keyframes (beyond the paper,
// docs/global_opt.md "Motion term"): the change of the body-frame velocity per frame,
//   v_ab = R_m(a,b)^T (t_wb - t_wa) / n_ab,   v_bc = R_m(b,c)^T (t_wc - t_wb) / n_bc,
//   r = sqrt_info .* (v_bc - v_ab)   [3]
// with n_ab, n_bc the frames between the keyframes and R_m(a,b) the rotation halfway between a's
// and b's (R_wa sqrt(R_wa^T R_wb)): on a turn the chord of an interval points along the path's
// tangent at its middle, so a car at constant speed and turn rate gives r = 0 for any spacing
// of the keyframes (to (n theta)^2 / 24 of the speed). r is the acceleration per frame.
class MotionSmoothnessCost {
 public:
  MotionSmoothnessCost(double frames_ab, double frames_bc, const Eigen::Vector3d& sqrt_info)
      : inv_ab_(1.0 / frames_ab), inv_bc_(1.0 / frames_bc), sqrt_info_(sqrt_info) {}

  template <typename T>
  bool operator()(const T* world_from_a, const T* world_from_b, const T* world_from_c,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_wa(world_from_a);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wa(world_from_a + 4);
    const Eigen::Map<const Eigen::Quaternion<T>> q_wb(world_from_b);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wb(world_from_b + 4);
    const Eigen::Map<const Eigen::Quaternion<T>> q_wc(world_from_c);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_wc(world_from_c + 4);
    const Eigen::Matrix<T, 3, 1> v_ab =
        Midway<T>(q_wa, q_wb).conjugate() * (t_wb - t_wa) * T(inv_ab_);
    const Eigen::Matrix<T, 3, 1> v_bc =
        Midway<T>(q_wb, q_wc).conjugate() * (t_wc - t_wb) * T(inv_bc_);
    for (int k = 0; k < 3; ++k) residual[k] = T(sqrt_info_(k)) * (v_bc(k) - v_ab(k));
    return true;
  }

  // q_1 sqrt(q_1^-1 q_2): the square root of a unit quaternion q (w >= 0) is (q + 1) / |q + 1|.
  template <typename T>
  static Eigen::Quaternion<T> Midway(const Eigen::Quaternion<T>& q_1,
                                     const Eigen::Quaternion<T>& q_2) {
    Eigen::Quaternion<T> d = q_1.conjugate() * q_2;
    if (d.w() < T(0)) d.coeffs() = -d.coeffs();
    d.w() += T(1);
    d.normalize();
    return q_1 * d;
  }

  static ceres::CostFunction* Create(double frames_ab, double frames_bc,
                                     const Eigen::Vector3d& sqrt_info) {
    return new ceres::AutoDiffCostFunction<MotionSmoothnessCost, 3, 7, 7, 7>(
        new MotionSmoothnessCost(frames_ab, frames_bc, sqrt_info));
  }

 private:
  const double inv_ab_;
  const double inv_bc_;
  const Eigen::Vector3d sqrt_info_;
};

}  // namespace jvl::optim
