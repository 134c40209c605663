#include "vision/triangulation.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"

namespace jvl::vision {

std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3d& cam1_from_world,
                                              const Rigid3d& cam2_from_world,
                                              const Eigen::Vector2d& xn1,
                                              const Eigen::Vector2d& xn2) {
  const Eigen::Matrix<double, 3, 4> p1 = cam1_from_world.Matrix3x4();
  const Eigen::Matrix<double, 3, 4> p2 = cam2_from_world.Matrix3x4();
  Eigen::Matrix4d a;
  a.row(0) = xn1.x() * p1.row(2) - p1.row(0);
  a.row(1) = xn1.y() * p1.row(2) - p1.row(1);
  a.row(2) = xn2.x() * p2.row(2) - p2.row(0);
  a.row(3) = xn2.y() * p2.row(2) - p2.row(1);
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d x = svd.matrixV().col(3);
  if (std::abs(x(3)) < 1e-12) return std::nullopt;
  return Eigen::Vector3d(x.head<3>() / x(3));
}

std::optional<Eigen::Vector3d> TriangulateMidpoint(const Rigid3d& cam1_from_world,
                                                   const Rigid3d& cam2_from_world,
                                                   const Eigen::Vector2d& xn1,
                                                   const Eigen::Vector2d& xn2) {
  const Rigid3d w1 = cam1_from_world.Inverse(), w2 = cam2_from_world.Inverse();
  const Eigen::Vector3d c1 = w1.translation(), c2 = w2.translation();
  const Eigen::Vector3d d1 = w1.rotation() * xn1.homogeneous();
  const Eigen::Vector3d d2 = w2.rotation() * xn2.homogeneous();
  // Minimise |c1 + s d1 - c2 - t d2|^2 over s, t.
  Eigen::Matrix2d m;
  m << d1.dot(d1), -d1.dot(d2), d1.dot(d2), -d2.dot(d2);
  const Eigen::Vector2d rhs((c2 - c1).dot(d1), (c2 - c1).dot(d2));
  if (std::abs(m.determinant()) < 1e-12 * d1.squaredNorm() * d2.squaredNorm()) return std::nullopt;
  const Eigen::Vector2d st = m.inverse() * rhs;
  return Eigen::Vector3d(0.5 * (c1 + st(0) * d1 + c2 + st(1) * d2));
}

void TriangulationOptions::Check() const {
  JVL_CHECK(max_cos_parallax > 0 && max_cos_parallax < 1,
            "triangulation: max_cos_parallax must be in (0, 1)");
  JVL_CHECK(max_reprojection_chi2 > 0, "triangulation: max_reprojection_chi2 must be > 0");
  JVL_CHECK(scale_consistency >= 1, "triangulation: scale_consistency must be >= 1");
}

const char* ToString(TriangulationStatus status) {
  switch (status) {
    case TriangulationStatus::kOk:
      return "ok";
    case TriangulationStatus::kLowParallax:
      return "low_parallax";
    case TriangulationStatus::kNoSolution:
      return "no_solution";
    case TriangulationStatus::kBehindCamera:
      return "behind_camera";
    case TriangulationStatus::kReprojection:
      return "reprojection";
    case TriangulationStatus::kScaleInconsistent:
      return "scale_inconsistent";
  }
  return "unknown";
}

double SquaredReprojectionError(const PinholeCamera& camera, const Rigid3d& cam_from_world,
                                const Eigen::Vector3d& point_world, const Eigen::Vector2d& uv) {
  const Eigen::Vector3d p = cam_from_world * point_world;
  if (p.z() <= 0) return std::numeric_limits<double>::infinity();
  return (camera.Project(p) - uv).squaredNorm();
}

TriangulationResult TriangulateTwoViews(const PinholeCamera& camera, const PointView& a,
                                        const PointView& b, const TriangulationOptions& options) {
  TriangulationResult result;
  const Eigen::Vector2d xa = camera.Unproject(a.uv).head<2>();
  const Eigen::Vector2d xb = camera.Unproject(b.uv).head<2>();
  const Eigen::Vector3d ray_a = a.cam_from_world.rotation().conjugate() * xa.homogeneous();
  const Eigen::Vector3d ray_b = b.cam_from_world.rotation().conjugate() * xb.homogeneous();
  result.cos_parallax = ray_a.normalized().dot(ray_b.normalized());
  if (result.cos_parallax >= options.max_cos_parallax) {
    result.status = TriangulationStatus::kLowParallax;
    return result;
  }
  const auto x = TriangulateDlt(a.cam_from_world, b.cam_from_world, xa, xb);
  if (!x || !x->allFinite()) return result;
  result.position = *x;
  const Eigen::Vector3d pa = a.cam_from_world * *x, pb = b.cam_from_world * *x;
  if (pa.z() <= 0 || pb.z() <= 0) {
    result.status = TriangulationStatus::kBehindCamera;
    return result;
  }
  for (const PointView* v : {&a, &b}) {
    const double sigma2 = v->level_scale * v->level_scale;
    if (SquaredReprojectionError(camera, v->cam_from_world, *x, v->uv) >
        options.max_reprojection_chi2 * sigma2) {
      result.status = TriangulationStatus::kReprojection;
      return result;
    }
  }
  // A point seen at a finer level must be closer: distance ratio ~ octave scale ratio.
  const double ratio_dist = pa.norm() / pb.norm();
  const double ratio_octave = a.level_scale / b.level_scale;
  if (ratio_dist * options.scale_consistency < ratio_octave ||
      ratio_dist > ratio_octave * options.scale_consistency) {
    result.status = TriangulationStatus::kScaleInconsistent;
    return result;
  }
  result.status = TriangulationStatus::kOk;
  return result;
}

Eigen::Vector3d RefinePoint(const PinholeCamera& camera, const std::vector<PointView>& views,
                            const Eigen::Vector3d& initial, int iterations, double huber_px) {
  Eigen::Vector3d x = initial;
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const PointView& v : views) {
      const Eigen::Matrix3d r = v.cam_from_world.RotationMatrix();
      const Eigen::Vector3d p = v.cam_from_world * x;
      if (p.z() <= 1e-6) continue;
      const Eigen::Vector2d e = camera.Project(p) - v.uv;
      Eigen::Matrix<double, 2, 3> j_proj;
      const double iz = 1.0 / p.z();
      j_proj << camera.fx * iz, 0, -camera.fx * p.x() * iz * iz, 0, camera.fy * iz,
          -camera.fy * p.y() * iz * iz;
      const Eigen::Matrix<double, 2, 3> j = j_proj * r;
      const double info = 1.0 / (v.level_scale * v.level_scale);
      const double norm = std::sqrt(e.squaredNorm() * info);
      const double w = info * (norm <= huber_px ? 1.0 : huber_px / norm);
      h += w * j.transpose() * j;
      g += w * j.transpose() * e;
    }
    Eigen::LDLT<Eigen::Matrix3d> ldlt(h);
    if (ldlt.info() != Eigen::Success || h.determinant() < 1e-18) return x;
    const Eigen::Vector3d dx = -ldlt.solve(g);
    if (!dx.allFinite()) return x;
    x += dx;
    if (dx.norm() < 1e-9 * (1.0 + x.norm())) break;
  }
  return x;
}

void PoseRefinementOptions::Check() const {
  JVL_CHECK(rounds >= 1 && iterations >= 1, "pose refinement: rounds and iterations must be >= 1");
  JVL_CHECK(chi2 > 0 && huber > 0, "pose refinement: chi2 and huber must be positive");
  JVL_CHECK(center_sigma >= 0, "pose refinement: center_sigma must be >= 0");
}

PoseRefinement RefinePose(const PinholeCamera& camera,
                          const std::vector<PointObservation>& observations,
                          const Rigid3d& initial_cam_from_world,
                          const PoseRefinementOptions& options,
                          const Eigen::Vector3d& center_prior) {
  options.Check();
  PoseRefinement out;
  out.cam_from_world = initial_cam_from_world;
  const size_t n = observations.size();
  out.inlier.assign(n, 1);
  // Squared whitened error at a pose (infinity behind the camera).
  const auto whitened2 = [&](const Rigid3d& t, const PointObservation& o) {
    return SquaredReprojectionError(camera, t, o.point_world, o.uv) /
           (o.level_scale * o.level_scale);
  };
  bool well_conditioned = false;
  for (int round = 0; round < options.rounds; ++round) {
    well_conditioned = false;
    for (int it = 0; it < options.iterations; ++it) {
      Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
      int used = 0;
      for (size_t i = 0; i < n; ++i) {
        if (!out.inlier[i]) continue;
        const PointObservation& o = observations[i];
        const Eigen::Vector3d p = out.cam_from_world * o.point_world;
        if (p.z() <= 1e-6) continue;
        const Eigen::Vector2d e = camera.Project(p) - o.uv;
        const double iz = 1.0 / p.z();
        Eigen::Matrix<double, 2, 3> j_proj;
        j_proj << camera.fx * iz, 0, -camera.fx * p.x() * iz * iz, 0, camera.fy * iz,
            -camera.fy * p.y() * iz * iz;
        // Left perturbation of cam_from_world: p' = p + rho + omega x p.
        Eigen::Matrix<double, 3, 6> j_pose;
        j_pose.leftCols<3>().setIdentity();
        j_pose.rightCols<3>() = -Skew(p);
        const Eigen::Matrix<double, 2, 6> j = j_proj * j_pose;
        const double info = 1.0 / (o.level_scale * o.level_scale);
        const double norm = std::sqrt(e.squaredNorm() * info);
        const double w = info * (norm <= options.huber ? 1.0 : options.huber / norm);
        h += w * j.transpose() * j;
        g += w * j.transpose() * e;
        ++used;
      }
      if (used < 6) break;
      if (options.center_sigma > 0) {
        // Camera centre c = -R^T t; under the left perturbation dc = -R^T rho.
        const Eigen::Matrix3d r = out.cam_from_world.RotationMatrix();
        const Eigen::Vector3d c = -(r.transpose() * out.cam_from_world.translation());
        const double info = 1.0 / (options.center_sigma * options.center_sigma);
        h.topLeftCorner<3, 3>() += info * Eigen::Matrix3d::Identity();
        g.head<3>() += info * (-r * (c - center_prior));
      }
      const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(h);
      if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-9)) break;
      const Eigen::Matrix<double, 6, 1> dx = -ldlt.solve(g);
      if (!dx.allFinite()) break;
      well_conditioned = true;
      out.cam_from_world = Rigid3d(ExpSO3(dx.tail<3>()), dx.head<3>()) * out.cam_from_world;
      if (dx.norm() < 1e-10) break;
    }
    for (size_t i = 0; i < n; ++i) {
      out.inlier[i] = whitened2(out.cam_from_world, observations[i]) <= options.chi2 ? 1 : 0;
    }
  }
  out.inliers = static_cast<int>(std::count(out.inlier.begin(), out.inlier.end(), 1));
  out.ok = well_conditioned && out.inliers >= 6;
  return out;
}

}  // namespace jvl::vision
