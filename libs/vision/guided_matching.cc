#include "vision/guided_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"

namespace jvl::vision {
namespace {

// Resolves keypoints claimed by several queries: the one with the smallest distance keeps it.
void ResolveConflicts(std::vector<int>* match, const std::vector<int>& distance,
                      size_t n_keypoints) {
  std::vector<int> owner(n_keypoints, -1);
  for (size_t i = 0; i < match->size(); ++i) {
    const int k = (*match)[i];
    if (k < 0) continue;
    const int o = owner[k];
    if (o < 0 || distance[i] < distance[o]) {
      if (o >= 0) (*match)[o] = -1;
      owner[k] = static_cast<int>(i);
    } else {
      (*match)[i] = -1;
    }
  }
}

void ApplyRotationCheck(std::vector<int>* match, const std::vector<float>& angle_diff) {
  std::vector<int> rows;
  std::vector<float> diffs;
  for (size_t i = 0; i < match->size(); ++i) {
    if ((*match)[i] < 0) continue;
    rows.push_back(static_cast<int>(i));
    diffs.push_back(angle_diff[i]);
  }
  const std::vector<bool> keep = RotationConsistent(diffs);
  for (size_t r = 0; r < rows.size(); ++r) {
    if (!keep[r]) (*match)[rows[r]] = -1;
  }
}

}  // namespace

KeypointGrid::KeypointGrid(const std::vector<OrbKeypoint>& keypoints, int width, int height,
                           int cell)
    : keypoints_(&keypoints),
      cell_(cell),
      nx_(std::max(1, (width + cell - 1) / cell)),
      ny_(std::max(1, (height + cell - 1) / cell)),
      cells_(static_cast<size_t>(nx_) * ny_) {
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const int cx = std::clamp(static_cast<int>(keypoints[i].uv.x()) / cell_, 0, nx_ - 1);
    const int cy = std::clamp(static_cast<int>(keypoints[i].uv.y()) / cell_, 0, ny_ - 1);
    cells_[static_cast<size_t>(cy) * nx_ + cx].push_back(static_cast<int>(i));
  }
}

std::vector<int> KeypointGrid::InWindow(const Eigen::Vector2d& uv, double radius, int min_octave,
                                        int max_octave) const {
  std::vector<int> out;
  const int x0 = std::max(0, static_cast<int>(std::floor((uv.x() - radius) / cell_)));
  const int x1 = std::min(nx_ - 1, static_cast<int>(std::floor((uv.x() + radius) / cell_)));
  const int y0 = std::max(0, static_cast<int>(std::floor((uv.y() - radius) / cell_)));
  const int y1 = std::min(ny_ - 1, static_cast<int>(std::floor((uv.y() + radius) / cell_)));
  for (int cy = y0; cy <= y1; ++cy) {
    for (int cx = x0; cx <= x1; ++cx) {
      for (int i : cells_[static_cast<size_t>(cy) * nx_ + cx]) {
        const OrbKeypoint& k = (*keypoints_)[i];
        if (k.octave < min_octave || k.octave > max_octave) continue;
        if (std::abs(k.uv.x() - uv.x()) > radius || std::abs(k.uv.y() - uv.y()) > radius) continue;
        out.push_back(i);
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

void KeypointGrid::NearLine(const Eigen::Vector3d& line, double band, std::vector<int>* out,
                            double lo_axis, double hi_axis) const {
  out->clear();
  const double a = line.x(), b = line.y(), c = line.z();
  const double norm = std::sqrt(a * a + b * b);
  if (norm < 1e-300) return;
  // Walk along the axis the line is closer to; for each cell column (row) the band covers a
  // contiguous range of cell rows (columns).
  const bool by_column = std::abs(b) >= std::abs(a);
  const int n_steps = by_column ? nx_ : ny_, n_other = by_column ? ny_ : nx_;
  const double slope_den = by_column ? b : a, slope_num = by_column ? a : b;
  const double extent = band * norm / std::abs(slope_den);  // Band height along the other axis.
  const int i_begin = std::max(0, static_cast<int>(std::floor(std::max(-1.0, lo_axis) / cell_)));
  const int i_end =
      std::min(n_steps - 1, static_cast<int>(std::floor(
                                std::min(static_cast<double>(n_steps) * cell_, hi_axis) / cell_)));
  for (int i = i_begin; i <= i_end; ++i) {
    const double t0 = static_cast<double>(i) * cell_, t1 = t0 + cell_;
    const double o0 = -(slope_num * t0 + c) / slope_den, o1 = -(slope_num * t1 + c) / slope_den;
    const double lo = std::min(o0, o1) - extent, hi = std::max(o0, o1) + extent;
    if (hi < 0 || lo >= static_cast<double>(n_other) * cell_) continue;
    const int j0 = std::max(0, static_cast<int>(std::floor(lo / cell_)));
    const int j1 = std::min(n_other - 1, static_cast<int>(std::floor(hi / cell_)));
    for (int j = j0; j <= j1; ++j) {
      const int cx = by_column ? i : j, cy = by_column ? j : i;
      const auto& cell = cells_[static_cast<size_t>(cy) * nx_ + cx];
      out->insert(out->end(), cell.begin(), cell.end());
    }
  }
}

std::vector<bool> RotationConsistent(const std::vector<float>& angle_diff_deg, int bins) {
  std::vector<int> bin(angle_diff_deg.size());
  std::vector<int> count(bins, 0);
  for (size_t i = 0; i < angle_diff_deg.size(); ++i) {
    double d = std::fmod(static_cast<double>(angle_diff_deg[i]), 360.0);
    if (d < 0) d += 360.0;
    bin[i] = std::min(bins - 1, static_cast<int>(d * bins / 360.0));
    ++count[bin[i]];
  }
  // Three largest bins; a bin far below the largest (< 10 %) does not count (ORB-SLAM2).
  std::vector<int> order(bins);
  for (int b = 0; b < bins; ++b) order[b] = b;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return count[a] > count[b]; });
  std::vector<bool> good_bin(bins, false);
  for (int r = 0; r < std::min(3, bins); ++r) {
    if (count[order[r]] > 0 && (r == 0 || count[order[r]] >= 0.1 * count[order[0]])) {
      good_bin[order[r]] = true;
    }
  }
  std::vector<bool> keep(angle_diff_deg.size());
  for (size_t i = 0; i < keep.size(); ++i) keep[i] = good_bin[bin[i]];
  return keep;
}

void ProjectionMatchOptions::Check() const {
  JVL_CHECK(window_px > 0, "matching: window_px must be > 0");
  JVL_CHECK(max_distance > 0 && max_distance <= 256, "matching: max_distance in (0, 256]");
  JVL_CHECK(ratio > 0 && ratio <= 1, "matching: ratio must be in (0, 1]");
}

void EpipolarMatchOptions::Check() const {
  JVL_CHECK(max_distance > 0 && max_distance <= 256, "matching: max_distance in (0, 256]");
  JVL_CHECK(ratio > 0 && ratio <= 1, "matching: ratio must be in (0, 1]");
  JVL_CHECK(epipolar_chi2 > 0, "matching: epipolar_chi2 must be > 0");
  JVL_CHECK(min_epipole_px >= 0, "matching: min_epipole_px must be >= 0");
  JVL_CHECK(max_octave_difference >= 0, "matching: max_octave_difference must be >= 0");
  JVL_CHECK(min_depth > 0, "matching: min_depth must be > 0");
}

std::vector<int> MatchByProjection(const std::vector<ProjectedPoint>& points,
                                   const OrbFeatures& frame, const KeypointGrid& grid,
                                   const std::vector<double>& level_scales,
                                   const ProjectionMatchOptions& options,
                                   const std::vector<bool>& taken) {
  const int max_level = static_cast<int>(level_scales.size()) - 1;
  std::vector<int> match(points.size(), -1), dist(points.size(), 256);
  std::vector<float> angle_diff(points.size(), 0.f);
  for (size_t i = 0; i < points.size(); ++i) {
    const ProjectedPoint& p = points[i];
    const int level = std::clamp(p.predicted_octave, 0, max_level);
    const double radius = options.window_px * level_scales[level];
    int best = 256, second = 256, best_level = -1, second_level = -1, best_k = -1;
    for (int k : grid.InWindow(p.uv, radius, level - 1, level)) {
      if (!taken.empty() && taken[k]) continue;
      const int d = HammingDistance(p.descriptor, frame.descriptors[k]);
      if (d < best) {
        second = best, second_level = best_level;
        best = d, best_level = frame.keypoints[k].octave, best_k = k;
      } else if (d < second) {
        second = d, second_level = frame.keypoints[k].octave;
      }
    }
    if (best_k < 0 || best > options.max_distance) continue;
    if (best_level == second_level && best > options.ratio * second) continue;
    match[i] = best_k;
    dist[i] = best;
    angle_diff[i] = frame.keypoints[best_k].angle - p.reference_angle;
  }
  ResolveConflicts(&match, dist, frame.size());
  if (options.check_orientation) ApplyRotationCheck(&match, angle_diff);
  return match;
}

namespace {

// The image-2 segment of the epipolar line of a view-1 ray: in normalised coordinates the point at
// depth lambda projects to v + s D with v the vanishing point of the ray, D = (t_xy a_z - t_z a_xy)
// / a_z and s = 1 / (lambda a_z + t_z), where a = R21 x1 and t = t21 (derived from
// x2 = (lambda a + t) / (lambda a_z + t_z)). Depths >= min_depth with positive depth in view 2
// give s in (0, s_max].
struct EpipolarSegment {
  bool bounded = false;  // False: ray points backwards in view 2; no restriction applied.
  Eigen::Vector2d v, d;  // Normalised coordinates.
  double s_max = 0;
};

EpipolarSegment SegmentOf(const Rigid3d& cam2_from_cam1, const Eigen::Vector2d& xn1,
                          double min_depth) {
  EpipolarSegment seg;
  const Eigen::Vector3d a = cam2_from_cam1.rotation() * xn1.homogeneous();
  const Eigen::Vector3d& t = cam2_from_cam1.translation();
  if (a.z() <= 1e-9) return seg;
  seg.bounded = true;
  seg.v = a.head<2>() / a.z();
  seg.d = (t.head<2>() * a.z() - t.z() * a.head<2>()) / a.z();
  const double den = min_depth * a.z() + t.z();
  seg.s_max = den > 1e-9 ? 1.0 / den : std::numeric_limits<double>::infinity();
  return seg;
}

}  // namespace

Eigen::Matrix3d FundamentalFromPoses(const PinholeCamera& camera, const Rigid3d& cam1_from_world,
                                     const Rigid3d& cam2_from_world) {
  const Rigid3d cam2_from_cam1 = cam2_from_world * cam1_from_world.Inverse();
  const Eigen::Matrix3d e = Skew(cam2_from_cam1.translation()) * cam2_from_cam1.RotationMatrix();
  const Eigen::Matrix3d k_inv = camera.K().inverse();
  return k_inv.transpose() * e * k_inv;
}

namespace {

// Keypoints of view 2 that may be matched: unused and not too close to the epipole, where the
// epipolar lines converge and parallax vanishes (ORB-SLAM2 SearchForTriangulation).
std::vector<bool> AllowedInView2(const PinholeCamera& camera, const OrbFeatures& f2,
                                 const Rigid3d& cam2_from_cam1, const std::vector<bool>& used2,
                                 const std::vector<double>& level_scales,
                                 const EpipolarMatchOptions& options) {
  const Eigen::Vector3d c1_in_2 = cam2_from_cam1.translation();
  const bool has_epipole = c1_in_2.z() > 1e-9;
  const Eigen::Vector2d epipole = has_epipole ? camera.Project(c1_in_2) : Eigen::Vector2d::Zero();
  std::vector<bool> allowed(f2.size(), true);
  for (size_t j = 0; j < f2.size(); ++j) {
    const OrbKeypoint& k = f2.keypoints[j];
    const double s = level_scales[std::min<size_t>(k.octave, level_scales.size() - 1)];
    if (!used2.empty() && used2[j]) allowed[j] = false;
    if (has_epipole && (k.uv.cast<double>() - epipole).squaredNorm() <
                           options.min_epipole_px * options.min_epipole_px * s) {
      allowed[j] = false;
    }
  }
  return allowed;
}

// Keypoints in the grid cells along the segment (or the whole line when unbounded).
void SegmentCandidates(const KeypointGrid& grid, const PinholeCamera& camera,
                       const Eigen::Vector3d& line, const EpipolarSegment& seg, double band,
                       std::vector<int>* near) {
  if (!seg.bounded || seg.d.squaredNorm() < 1e-24) {
    grid.NearLine(line, band, near);
    return;
  }
  auto to_pixel = [&camera](const Eigen::Vector2d& xn) {
    return Eigen::Vector2d(camera.fx * xn.x() + camera.cx, camera.fy * xn.y() + camera.cy);
  };
  const Eigen::Vector2d p0 = to_pixel(seg.v);
  const Eigen::Vector2d p1 = to_pixel(seg.v + std::min(seg.s_max, 1e6) * seg.d);
  const bool by_column = std::abs(line.y()) >= std::abs(line.x());  // As NearLine walks.
  const double a0 = by_column ? p0.x() : p0.y(), a1 = by_column ? p1.x() : p1.y();
  grid.NearLine(line, band, near, std::min(a0, a1) - band, std::max(a0, a1) + band);
}

// Whether a view-2 pixel projects within the depth segment (with a margin of `band` px).
bool OnSegment(const PinholeCamera& camera, const EpipolarSegment& seg, const Eigen::Vector2f& uv,
               double band) {
  const double d2 = seg.d.squaredNorm();
  if (!seg.bounded || d2 < 1e-24) return true;
  const Eigen::Vector2d xn2 = camera.Unproject(uv.cast<double>()).head<2>();
  const double along = (xn2 - seg.v).dot(seg.d) / d2;
  const double margin = band / camera.fx / std::sqrt(d2);
  return along >= -margin && along <= seg.s_max + margin;
}

}  // namespace

std::vector<std::pair<int, int>> MatchEpipolar(
    const PinholeCamera& camera, const OrbFeatures& f1, const Rigid3d& cam1_from_world,
    const std::vector<bool>& used1, const OrbFeatures& f2, const Rigid3d& cam2_from_world,
    const std::vector<bool>& used2, const std::vector<double>& level_scales,
    const EpipolarMatchOptions& options) {
  const Eigen::Matrix3d f21 = FundamentalFromPoses(camera, cam1_from_world, cam2_from_world);
  const Rigid3d cam2_from_cam1 = cam2_from_world * cam1_from_world.Inverse();
  const std::vector<bool> allowed2 =
      AllowedInView2(camera, f2, cam2_from_cam1, used2, level_scales, options);
  const KeypointGrid grid2(f2.keypoints, camera.width, camera.height, 16);
  const double max_band = std::sqrt(options.epipolar_chi2) * level_scales.back();
  std::vector<int> near;
  std::vector<int> match(f1.size(), -1), dist(f1.size(), 256);
  std::vector<float> angle_diff(f1.size(), 0.f);
  for (size_t i = 0; i < f1.size(); ++i) {
    if (!used1.empty() && used1[i]) continue;
    const OrbKeypoint& k1 = f1.keypoints[i];
    const Eigen::Vector3d line = f21 * k1.uv.cast<double>().homogeneous();
    const double inv_norm2 = 1.0 / std::max(1e-30, line.head<2>().squaredNorm());
    const EpipolarSegment seg = SegmentOf(
        cam2_from_cam1, camera.Unproject(k1.uv.cast<double>()).head<2>(), options.min_depth);
    SegmentCandidates(grid2, camera, line, seg, max_band, &near);
    int best = 256, second = 256, best_j = -1;
    for (int j : near) {
      const OrbKeypoint& k = f2.keypoints[j];
      if (!allowed2[j] || std::abs(k.octave - k1.octave) > options.max_octave_difference) continue;
      const double r = line.x() * k.uv.x() + line.y() * k.uv.y() + line.z();
      const double s = level_scales[std::min<size_t>(k.octave, level_scales.size() - 1)];
      if (r * r * inv_norm2 >= options.epipolar_chi2 * s * s) continue;
      if (!OnSegment(camera, seg, k.uv, max_band)) continue;
      const int d = HammingDistance(f1.descriptors[i], f2.descriptors[j]);
      if (d < best || (d == best && j < best_j)) {  // Ties: lower index, whatever the cell order.
        second = best;
        best = d, best_j = j;
      } else if (d < second) {
        second = d;
      }
    }
    if (best_j < 0 || best > options.max_distance || best > options.ratio * second) continue;
    match[i] = best_j;
    dist[i] = best;
    angle_diff[i] = f2.keypoints[best_j].angle - k1.angle;
  }
  ResolveConflicts(&match, dist, f2.size());
  if (options.check_orientation) ApplyRotationCheck(&match, angle_diff);
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < match.size(); ++i) {
    if (match[i] >= 0) pairs.emplace_back(static_cast<int>(i), match[i]);
  }
  return pairs;
}

}  // namespace jvl::vision
