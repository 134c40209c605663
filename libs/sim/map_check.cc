#include "sim/map_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "core/statistics.h"
#include "core/threads.h"

namespace jvl::sim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

SurfaceDistanceStats Stats(const std::vector<SurfaceDistance>& distances, double min_depth,
                           double max_depth, double threshold) {
  SurfaceDistanceStats s;
  s.min_depth = min_depth;
  s.max_depth = max_depth;
  std::vector<double> perpendicular, along, signed_along;
  int64_t within = 0;
  for (const SurfaceDistance& d : distances) {
    if (!(d.depth >= min_depth && d.depth < max_depth)) continue;
    ++s.points;
    if (!d.hit) {
      ++s.no_hit;
      continue;
    }
    s.moving_car += d.moving_car ? 1 : 0;
    perpendicular.push_back(d.perpendicular);
    along.push_back(std::abs(d.along_ray));
    signed_along.push_back(d.along_ray);
    within += d.perpendicular <= threshold ? 1 : 0;
  }
  s.median_perpendicular = Quantile(perpendicular, 0.5);
  s.p90_perpendicular = Quantile(perpendicular, 0.9);
  s.median_along = Quantile(along, 0.5);
  s.p90_along = Quantile(along, 0.9);
  s.median_signed_along = Quantile(signed_along, 0.5);
  s.within_threshold = s.points > 0 ? static_cast<double>(within) / s.points : kNaN;
  return s;
}

nlohmann::json StatsJson(const SurfaceDistanceStats& s) {
  return {{"min_depth_m", s.min_depth},
          {"max_depth_m", s.max_depth},
          {"points", s.points},
          {"no_hit", s.no_hit},
          {"moving_car", s.moving_car},
          {"median_perpendicular_m", s.median_perpendicular},
          {"p90_perpendicular_m", s.p90_perpendicular},
          {"median_along_ray_m", s.median_along},
          {"p90_along_ray_m", s.p90_along},
          {"median_signed_along_ray_m", s.median_signed_along},
          {"within_threshold", s.within_threshold}};
}

}  // namespace

void SurfaceCheckOptions::Check() const {
  JVL_CHECK(max_depth > 0, "max_depth must be > 0, got " << max_depth);
  JVL_CHECK(threshold > 0, "threshold must be > 0, got " << threshold);
  JVL_CHECK(depth_bins.size() >= 2, "depth_bins need at least two edges");
  for (size_t i = 1; i < depth_bins.size(); ++i) {
    JVL_CHECK(depth_bins[i] > depth_bins[i - 1], "depth_bins edges must increase");
  }
}

std::vector<PointView> NearestViews(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<Rigid3d>& map_from_cam,
                                    const std::vector<double>& times,
                                    const std::vector<int32_t>& obs_keyframe,
                                    const std::vector<int32_t>& obs_point) {
  JVL_CHECK(times.size() == map_from_cam.size(), "keyframe poses and times differ in count");
  JVL_CHECK(obs_keyframe.size() == obs_point.size(), "observation arrays differ in length");
  std::vector<PointView> views(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    views[i].point = points[i];
    views[i].depth = kInf;
  }
  for (size_t o = 0; o < obs_point.size(); ++o) {
    const int32_t k = obs_keyframe[o], p = obs_point[o];
    JVL_CHECK(k >= 0 && static_cast<size_t>(k) < map_from_cam.size(),
              "observation " << o << ": keyframe " << k << " out of range");
    JVL_CHECK(p >= 0 && static_cast<size_t>(p) < points.size(),
              "observation " << o << ": map point " << p << " out of range");
    const Rigid3d& pose = map_from_cam[static_cast<size_t>(k)];
    const double depth = (pose.Inverse() * points[static_cast<size_t>(p)]).z();
    PointView& v = views[static_cast<size_t>(p)];
    // Ties go to the earlier keyframe, so the result does not depend on the observation order.
    if (depth > 0 && (depth < v.depth || (depth == v.depth && k < v.keyframe))) {
      v.depth = depth;
      v.camera_center = pose.translation();
      v.time = times[static_cast<size_t>(k)];
      v.keyframe = k;
    }
  }
  return views;
}

std::vector<SurfaceDistance> MeasureSurfaceDistances(const Scene& scene, const RayCaster& caster,
                                                     const std::vector<PointView>& views,
                                                     int threads) {
  std::vector<SurfaceDistance> out(views.size());
  ParallelFor(static_cast<int64_t>(views.size()), threads, [&](int64_t i) {
    const PointView& v = views[static_cast<size_t>(i)];
    SurfaceDistance& d = out[static_cast<size_t>(i)];
    d.depth = v.depth;
    const Eigen::Vector3d ray = v.point - v.camera_center;
    const double r = ray.norm();
    if (!std::isfinite(v.depth) || r <= 0) return;
    const Eigen::Vector3d dir = ray / r;
    // Far enough past the point for any plausible surface behind it.
    const double t_max = 10 * r + 100;
    Hit hit = caster.Intersect(v.camera_center, dir, 1e-3, t_max);
    std::vector<Box> cars;
    for (size_t c = 0; c < scene.moving_cars.size(); ++c) {
      cars.push_back(scene.MovingCarBox(c, v.time));
    }
    IntersectBoxes(cars, v.camera_center, dir, &hit);
    if (!hit.valid() || !(hit.t < t_max)) return;
    d.hit = true;
    d.moving_car = hit.dynamic >= 0;
    d.along_ray = hit.t - r;
    d.cos_incidence = std::abs(dir.dot(hit.normal));
    d.perpendicular = std::abs(d.along_ray) * d.cos_incidence;
    d.face = hit.face;
  });
  return out;
}

SurfaceCheckSummary SummarizeSurfaceDistances(const std::vector<SurfaceDistance>& distances,
                                              const SurfaceCheckOptions& options) {
  options.Check();
  SurfaceCheckSummary s;
  s.total_points = static_cast<int64_t>(distances.size());
  s.threshold = options.threshold;
  for (const SurfaceDistance& d : distances) {
    s.beyond_max_depth += d.depth >= options.max_depth ? 1 : 0;
  }
  s.all = Stats(distances, 0, options.max_depth, options.threshold);
  for (size_t b = 0; b + 1 < options.depth_bins.size(); ++b) {
    s.bins.push_back(
        Stats(distances, options.depth_bins[b], options.depth_bins[b + 1], options.threshold));
  }
  return s;
}

nlohmann::json ToJson(const SurfaceCheckSummary& summary) {
  nlohmann::json bins = nlohmann::json::array();
  for (const SurfaceDistanceStats& b : summary.bins) bins.push_back(StatsJson(b));
  return {{"total_points", summary.total_points},
          {"beyond_max_depth", summary.beyond_max_depth},
          {"threshold_m", summary.threshold},
          {"all", StatsJson(summary.all)},
          {"depth_bins", bins}};
}

}  // namespace jvl::sim
