#include "vision/vanishing_points.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/check.h"

namespace jvl {

void VpOptions::Check() const {
  JVL_CHECK(max_vps >= 0 && max_vps <= 10, "max VPs must be in [0, 10], got " << max_vps);
  JVL_CHECK(inlier_threshold_deg > 0 && inlier_threshold_deg < 45,
            "VP inlier threshold must be in (0, 45) deg, got " << inlier_threshold_deg);
  JVL_CHECK(ransac_iterations >= 1, "RANSAC iterations must be >= 1, got " << ransac_iterations);
  JVL_CHECK(min_inliers >= 2, "min VP inliers must be >= 2, got " << min_inliers);
  JVL_CHECK(refine_iterations >= 0, "refine iterations must be >= 0, got " << refine_iterations);
  JVL_CHECK(min_separation_deg >= 0 && min_separation_deg <= 90,
            "min VP separation must be in [0, 90] deg, got " << min_separation_deg);
  JVL_CHECK(forward_max_angle_deg >= 0 && forward_max_angle_deg <= 90,
            "forward max angle must be in [0, 90] deg, got " << forward_max_angle_deg);
}

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// A segment on the Gaussian sphere: the normal of its interpretation plane (through the camera
// centre and both endpoints), the unit ray of its midpoint, and its weight (pixel length).
struct SphereSegment {
  Eigen::Vector3d normal;
  Eigen::Vector3d mid;
  double weight = 0;
  bool valid = false;
};

SphereSegment ToSphere(const LineSegment& s, const PinholeCamera& camera) {
  SphereSegment out;
  const Eigen::Vector3d a = camera.Unproject(s.p0);
  const Eigen::Vector3d b = camera.Unproject(s.p1);
  const Eigen::Vector3d n = a.cross(b);
  out.mid = (a + b).normalized();
  out.weight = s.length();
  out.valid = n.norm() > 1e-12 && out.weight > 0;
  out.normal = out.valid ? n.normalized() : Eigen::Vector3d::Zero();
  return out;
}

// Signed sine of the angle between the segment's plane and the plane (mid, d). Its magnitude is
// the residual of Eq. "segment points at the VP"; sin ~ angle below the inlier threshold.
double SignedResidual(const SphereSegment& s, const Eigen::Vector3d& d) {
  const Eigen::Vector3d c = s.mid.cross(d);
  const double norm = c.norm();
  if (norm < 1e-12) return 0.0;  // d is the midpoint ray itself: consistent with any line.
  // Both normals are orthogonal to the midpoint ray, so their cross product is along it.
  return s.normal.cross(c).dot(s.mid) / norm;
}

double AngleResidual(const SphereSegment& s, const Eigen::Vector3d& d) {
  const Eigen::Vector3d c = s.mid.cross(d);
  const double norm = c.norm();
  if (norm < 1e-12) return 0.0;
  return std::atan2(s.normal.cross(c).norm(), std::abs(s.normal.dot(c)));
}

// MSAC support of d over the segments still unassigned. The hot loop of the hypothesis search:
// it compares squared sines (sin ~ angle below the threshold) to avoid atan2 and square roots.
double Support(const std::vector<SphereSegment>& segs, const std::vector<int>& label,
               const Eigen::Vector3d& d, double threshold) {
  const double sin2_threshold = std::sin(threshold) * std::sin(threshold);
  double score = 0;
  for (size_t i = 0; i < segs.size(); ++i) {
    if (label[i] != -1 || !segs[i].valid) continue;
    const Eigen::Vector3d c = segs[i].mid.cross(d);
    const double c2 = c.squaredNorm();
    if (c2 < 1e-24) continue;
    const double r2 = segs[i].normal.cross(c).squaredNorm() / (c2 * sin2_threshold);
    if (r2 < 1.0) score += segs[i].weight * (1.0 - r2);
  }
  return score;
}

// Least squares on the inliers: start from the direction closest to all interpretation planes
// (smallest eigenvector of sum w n n^T), then Gauss-Newton on the angular residual over a
// 2-D tangent parametrisation of the sphere (numeric Jacobian, 2x2 normal equations).
Eigen::Vector3d RefineDirection(const std::vector<SphereSegment>& segs,
                                const std::vector<int>& inliers, const Eigen::Vector3d& start) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (int i : inliers) m += segs[i].weight * segs[i].normal * segs[i].normal.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  Eigen::Vector3d d = eig.eigenvectors().col(0).normalized();
  if (d.dot(start) < 0) d = -d;
  for (int iter = 0; iter < 5; ++iter) {
    Eigen::Vector3d b1 = d.unitOrthogonal();
    Eigen::Vector3d b2 = d.cross(b1);
    Eigen::Matrix2d h = Eigen::Matrix2d::Zero();
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    constexpr double kStep = 1e-6;
    for (int i : inliers) {
      const double r = SignedResidual(segs[i], d);
      const Eigen::Vector2d j((SignedResidual(segs[i], (d + kStep * b1).normalized()) - r) / kStep,
                              (SignedResidual(segs[i], (d + kStep * b2).normalized()) - r) / kStep);
      h += segs[i].weight * j * j.transpose();
      g += segs[i].weight * j * r;
    }
    if (std::abs(h.determinant()) < 1e-30) break;
    const Eigen::Vector2d delta = -h.ldlt().solve(g);
    if (!delta.allFinite()) break;
    d = (d + delta.x() * b1 + delta.y() * b2).normalized();
    if (delta.norm() < 1e-10) break;
  }
  return d;
}

std::vector<int> Inliers(const std::vector<SphereSegment>& segs, const std::vector<int>& label,
                         const Eigen::Vector3d& d, double threshold) {
  std::vector<int> in;
  for (size_t i = 0; i < segs.size(); ++i) {
    if (label[i] == -1 && segs[i].valid && AngleResidual(segs[i], d) < threshold) {
      in.push_back(static_cast<int>(i));
    }
  }
  return in;
}

// Best hypothesis from random pairs of unassigned segments (MSAC score).
bool BestHypothesis(const std::vector<SphereSegment>& segs, const std::vector<int>& label,
                    const VpOptions& options, std::mt19937_64& rng, Eigen::Vector3d* best) {
  std::vector<int> pool;
  for (size_t i = 0; i < segs.size(); ++i) {
    if (label[i] == -1 && segs[i].valid) pool.push_back(static_cast<int>(i));
  }
  if (pool.size() < 2) return false;
  const double threshold = options.inlier_threshold_deg * kDegToRad;
  // Collinear pieces of one edge share a plane; their intersection is undefined.
  const double min_sin = std::sin(0.5 * kDegToRad);
  double best_score = 0;
  for (int it = 0; it < options.ransac_iterations; ++it) {
    const int i = pool[rng() % pool.size()];
    const int j = pool[rng() % pool.size()];
    const Eigen::Vector3d d = segs[i].normal.cross(segs[j].normal);
    if (d.norm() < min_sin) continue;
    const double score = Support(segs, label, d.normalized(), threshold);
    if (score > best_score) {
      best_score = score;
      *best = d.normalized();
    }
  }
  return best_score > 0;
}

}  // namespace

Eigen::Vector3d CanonicalDirection(const Eigen::Vector3d& d) {
  const Eigen::Vector3d u = d.normalized();
  // z >= 0; on the image plane's parallel (z == 0) break the tie by x, then y.
  if (u.z() < 0 || (u.z() == 0 && (u.x() < 0 || (u.x() == 0 && u.y() < 0)))) return -u;
  return u;
}

Eigen::Vector2d DirectionToPixel(const Eigen::Vector3d& d, const PinholeCamera& camera) {
  const Eigen::Vector3d u = CanonicalDirection(d);
  if (u.z() < kInfinityDz)
    return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  return camera.Project(u);
}

double SegmentVpResidual(const LineSegment& segment, const PinholeCamera& camera,
                         const Eigen::Vector3d& d) {
  const SphereSegment s = ToSphere(segment, camera);
  return s.valid ? AngleResidual(s, d.normalized()) : 0.0;
}

VpResult EstimateVanishingPoints(const std::vector<LineSegment>& segments,
                                 const PinholeCamera& camera, const VpOptions& options) {
  options.Check();
  VpResult result;
  result.segments = segments;
  result.segment_vp.assign(segments.size(), -1);
  std::vector<SphereSegment> segs;
  segs.reserve(segments.size());
  for (const LineSegment& s : segments) segs.push_back(ToSphere(s, camera));
  const double threshold = options.inlier_threshold_deg * kDegToRad;
  std::mt19937_64 rng(options.seed);
  std::vector<int>& label = result.segment_vp;
  while (static_cast<int>(result.vps.size()) < options.max_vps) {
    Eigen::Vector3d d;
    if (!BestHypothesis(segs, label, options, rng, &d)) break;
    std::vector<int> inliers = Inliers(segs, label, d, threshold);
    for (int it = 0; it < options.refine_iterations && inliers.size() >= 2; ++it) {
      d = RefineDirection(segs, inliers, d);
      inliers = Inliers(segs, label, d, threshold);
    }
    if (static_cast<int>(inliers.size()) < options.min_inliers) break;
    bool duplicate = false;
    for (const VanishingPoint& vp : result.vps) {
      const double angle = std::acos(std::min(1.0, std::abs(vp.direction.dot(d))));
      duplicate = duplicate || angle < options.min_separation_deg * kDegToRad;
    }
    if (duplicate) break;
    VanishingPoint vp;
    vp.direction = CanonicalDirection(d);
    vp.uv = DirectionToPixel(vp.direction, camera);
    vp.inliers = static_cast<int>(inliers.size());
    double sum_sq = 0;
    for (int i : inliers) {
      const double r = AngleResidual(segs[i], d);
      sum_sq += r * r;
      vp.score += segs[i].weight * (1.0 - (r / threshold) * (r / threshold));
      label[i] = static_cast<int>(result.vps.size());
    }
    vp.residual_deg = std::sqrt(sum_sq / inliers.size()) / kDegToRad;
    result.vps.push_back(vp);
  }
  // Forward VP: the smallest angle to the optical axis (Sec. 4.3 uses it as direction prior).
  double best_angle = options.forward_max_angle_deg * kDegToRad;
  for (size_t k = 0; k < result.vps.size(); ++k) {
    const double angle = std::acos(std::min(1.0, result.vps[k].direction.z()));
    if (angle <= best_angle) {
      best_angle = angle;
      result.forward_index = static_cast<int>(k);
    }
  }
  if (result.forward_index >= 0) result.vps[result.forward_index].is_forward = true;
  return result;
}

VpResult DetectVanishingPoints(const cv::Mat& image, const PinholeCamera& camera,
                               const VpDetectOptions& options) {
  options.Check();
  return EstimateVanishingPoints(DetectLineSegments(image, options.segments), camera, options.vp);
}

}  // namespace jvl
