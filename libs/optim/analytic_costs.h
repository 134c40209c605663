// Analytic-Jacobian twins of PointToImlsCost and DirectionProjectionCost (supplement 2).
//
// Same residuals as the autodiff functors in cost_functions.h; the Jacobians are with respect to
// the ambient 7-vector [qx qy qz qw tx ty tz] (Ceres multiplies them by the manifold's
// PlusJacobian). Supplement 2 writes them on the SE(3) tangent of T_cw / T_nw; with our
// world_from_cam blocks the same chain rule is applied to R(q) v = v + 2w (u x v) + 2 u x (u x v),
// q = (u, w). They are tested against the autodiff versions and numeric differentiation
// (analytic_costs_test.cc) and benchmarked in optim_benchmark.cc.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "geometry/camera.h"

namespace jvl::optim {

// d(R(q) v)/d[qx qy qz qw] for the unit quaternion q stored as [x y z w].
Eigen::Matrix<double, 3, 4> RotateJacobian(const double* q_xyzw, const Eigen::Vector3d& v);
// d(R(q)^T v)/d[qx qy qz qw].
Eigen::Matrix<double, 3, 4> InverseRotateJacobian(const double* q_xyzw, const Eigen::Vector3d& v);

// dr/dp of a pixel residual r = s (uv - pi(p)) at a camera-frame point p (z > 0):
// -s [fx/z 0 -fx x/z^2; 0 fy/z -fy y/z^2]. Shared by e_V, e_D and the map-point information.
inline Eigen::Matrix<double, 2, 3> PixelResidualJacobian(double fx, double fy, double s,
                                                         const Eigen::Vector3d& p) {
  const double inv_z = 1.0 / p.z();
  Eigen::Matrix<double, 2, 3> j;
  j << -s * fx * inv_z, 0, s * fx * p.x() * inv_z * inv_z,  //
      0, -s * fy * inv_z, s * fy * p.y() * inv_z * inv_z;
  return j;
}

// Analytic twin of VisualReprojectionCost (same residual, same failure behind the camera). Stores
// the four intrinsics instead of a camera copy: a global problem holds millions of these.
class VisualReprojectionAnalyticCost : public ceres::SizedCostFunction<2, 7, 3> {
 public:
  // offset as in VisualReprojectionCost.
  VisualReprojectionAnalyticCost(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                 double sqrt_information,
                                 const Eigen::Vector3d& offset = Eigen::Vector3d::Zero())
      : fx_(camera.fx),
        fy_(camera.fy),
        cx_(camera.cx),
        cy_(camera.cy),
        uv_(uv),
        sqrt_information_(sqrt_information),
        offset_(offset) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const double fx_, fy_, cx_, cy_;
  const Eigen::Vector2d uv_;
  const double sqrt_information_;
  const Eigen::Vector3d offset_;
};

class PointToImlsAnalyticCost : public ceres::SizedCostFunction<1, 7, 7> {
 public:
  PointToImlsAnalyticCost(const Eigen::Vector3d& p_x, const Eigen::Vector3d& c_p_y,
                          const Eigen::Vector3d& c_normal, double sqrt_information)
      : p_x_(p_x), c_p_y_(c_p_y), c_normal_(c_normal), sqrt_information_(sqrt_information) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const Eigen::Vector3d p_x_;
  const Eigen::Vector3d c_p_y_;
  const Eigen::Vector3d c_normal_;
  const double sqrt_information_;
};

class DirectionProjectionAnalyticCost : public ceres::SizedCostFunction<2, 7> {
 public:
  DirectionProjectionAnalyticCost(const PinholeCamera& camera, const Eigen::Vector2d& vp,
                                  const Eigen::Vector3d& direction_world,
                                  const Eigen::Vector2d& sqrt_information, double min_z)
      : camera_(camera),
        vp_(vp),
        direction_world_(direction_world.normalized()),
        sqrt_information_(sqrt_information),
        min_z_(min_z) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const PinholeCamera camera_;
  const Eigen::Vector2d vp_;
  const Eigen::Vector3d direction_world_;
  const Eigen::Vector2d sqrt_information_;  // per image axis (u, v)
  const double min_z_;
};

// e_D with d_w as a second parameter block (a free direction on the unit sphere, shared by the
// keyframes of one direction cluster): the same residual as DirectionProjectionAnalyticCost;
// dr/dd_w = sign * dr/dd * R_wn^T.
class DirectionProjectionFreeCost : public ceres::SizedCostFunction<2, 7, 3> {
 public:
  DirectionProjectionFreeCost(const PinholeCamera& camera, const Eigen::Vector2d& vp,
                              const Eigen::Vector2d& sqrt_information, double min_z)
      : camera_(camera), vp_(vp), sqrt_information_(sqrt_information), min_z_(min_z) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const PinholeCamera camera_;
  const Eigen::Vector2d vp_;
  const Eigen::Vector2d sqrt_information_;  // per image axis (u, v)
  const double min_z_;
};

// A direction observed as a ray (a vanishing direction that may lie at infinity in the image,
// e.g. the vertical VP of a level camera) against a free world direction d_w (unit sphere
// block): r = s sign B^T R_wn^T d_w, B an orthonormal basis of the plane normal to the observed
// unit ray (its tangent plane), sign = that of ray . R_wn^T d_w (unoriented). Near the
// solution |r| / s is the angle between the ray and R_wn^T d_w (radians); s = 1 / sigma (rad).
class DirectionAngleFreeCost : public ceres::SizedCostFunction<2, 7, 3> {
 public:
  DirectionAngleFreeCost(const Eigen::Vector3d& ray_cam, double sqrt_information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const Eigen::Vector3d ray_;
  const Eigen::Matrix<double, 3, 2> basis_;  // orthonormal, normal to ray_ (TangentBasis)
  const double sqrt_information_;
};

}  // namespace jvl::optim
