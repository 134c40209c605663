#include "mapping/visual_map.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/check.h"

namespace jvl::mapping {
namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
}

}  // namespace

void UpdatePointGeometry(VisualMap* map, int point) {
  MapPoint& p = map->points[point];
  if (p.observations.empty()) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const Observation& o : p.observations) {
    const Eigen::Vector3d center = map->keyframes[o.keyframe].world_from_cam.translation();
    normal += (p.position - center).normalized();
  }
  p.normal = normal.normalized();
  // Scale range from the first (reference) observation, as ORB-SLAM2.
  const Observation& ref = p.observations.front();
  const Keyframe& kf = map->keyframes[ref.keyframe];
  const double dist = (p.position - kf.world_from_cam.translation()).norm();
  const int octave = kf.features.keypoints[ref.keypoint].octave;
  p.max_distance = dist * map->level_scales[octave];
  p.min_distance = p.max_distance / map->level_scales.back();
  // Representative descriptor: least median Hamming distance to the others.
  const size_t n = p.observations.size();
  std::vector<const vision::Descriptor*> d(n);
  for (size_t i = 0; i < n; ++i) {
    const Observation& o = p.observations[i];
    d[i] = &map->keyframes[o.keyframe].features.descriptors[o.keypoint];
  }
  size_t best = 0;
  int best_median = 1 << 30;
  for (size_t i = 0; i < n; ++i) {
    std::vector<int> dist_i(n);
    for (size_t j = 0; j < n; ++j) dist_i[j] = vision::HammingDistance(*d[i], *d[j]);
    std::nth_element(dist_i.begin(), dist_i.begin() + (n - 1) / 2, dist_i.end());
    if (dist_i[(n - 1) / 2] < best_median) best_median = dist_i[(n - 1) / 2], best = i;
  }
  p.descriptor = *d[best];
  const Observation& b = p.observations[best];
  p.reference_angle = map->keyframes[b.keyframe].features.keypoints[b.keypoint].angle;
}

void AddObservation(VisualMap* map, int point, int keyframe, int keypoint) {
  MapPoint& p = map->points[point];
  Keyframe& kf = map->keyframes[keyframe];
  JVL_CHECK(kf.mappoint[keypoint] < 0, "keypoint " << keypoint << " already has a map point");
  kf.mappoint[keypoint] = point;
  auto it = std::lower_bound(p.observations.begin(), p.observations.end(), keyframe,
                             [](const Observation& o, int k) { return o.keyframe < k; });
  p.observations.insert(it, {keyframe, keypoint});
}

void RemovePoint(VisualMap* map, int point) {
  MapPoint& p = map->points[point];
  for (const Observation& o : p.observations) map->keyframes[o.keyframe].mappoint[o.keypoint] = -1;
  p.observations.clear();
  p.bad = true;
}

int PredictOctave(const MapPoint& point, double distance, const VisualMap& map) {
  const double ratio = point.max_distance / distance;
  const int n = static_cast<int>(map.level_scales.size());
  const int level = static_cast<int>(std::ceil(std::log(ratio) / std::log(map.orb.scale_factor)));
  return std::clamp(level, 0, n - 1);
}

std::vector<vision::ProjectedPoint> PredictInView(const VisualMap& map,
                                                  const std::vector<int>& points,
                                                  const Rigid3d& cam_from_world,
                                                  double min_view_cos,
                                                  std::vector<int>* predicted) {
  const Eigen::Vector3d center = cam_from_world.Inverse().translation();
  std::vector<vision::ProjectedPoint> out;
  predicted->clear();
  for (int i : points) {
    const MapPoint& p = map.points[i];
    if (p.bad) continue;
    const Eigen::Vector3d pc = cam_from_world * p.position;
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = map.camera.Project(pc);
    if (!map.camera.InImage(uv)) continue;
    const Eigen::Vector3d ray = p.position - center;
    const double dist = ray.norm();
    if (dist < 0.8 * p.min_distance || dist > 1.2 * p.max_distance) continue;
    if (ray.dot(p.normal) < min_view_cos * dist) continue;
    out.push_back({uv, PredictOctave(p, dist, map), p.descriptor, p.reference_angle});
    predicted->push_back(i);
  }
  return out;
}

std::vector<CovisibilityEdge> Covisibility(const VisualMap& map, int min_weight) {
  std::map<std::pair<int, int>, int> weight;
  for (const MapPoint& p : map.points) {
    if (p.bad) continue;
    for (size_t i = 0; i < p.observations.size(); ++i) {
      for (size_t j = i + 1; j < p.observations.size(); ++j) {
        const int a = p.observations[i].keyframe, b = p.observations[j].keyframe;
        if (a != b) ++weight[{std::min(a, b), std::max(a, b)}];
      }
    }
  }
  std::vector<CovisibilityEdge> edges;
  for (const auto& [key, w] : weight) {
    if (w >= min_weight) edges.push_back({key.first, key.second, w});
  }
  return edges;
}

io::VisualMapData ExportVisualMap(const VisualMap& map, const Trajectory& prior, int min_weight) {
  io::VisualMapData d;
  d.camera = map.camera;
  d.scale_factor = map.orb.scale_factor;
  d.num_levels = map.orb.num_levels;
  d.prior = prior;
  std::vector<int> keypoint_offset(map.keyframes.size() + 1, 0);
  for (size_t k = 0; k < map.keyframes.size(); ++k) {
    const Keyframe& kf = map.keyframes[k];
    d.keyframes.Append(kf.frame, kf.world_from_cam);
    keypoint_offset[k + 1] = keypoint_offset[k] + static_cast<int>(kf.features.size());
    for (size_t i = 0; i < kf.features.size(); ++i) {
      const vision::OrbKeypoint& kp = kf.features.keypoints[i];
      d.keypoint_keyframe.push_back(static_cast<int32_t>(k));
      d.keypoint_uv.insert(d.keypoint_uv.end(), {kp.uv.x(), kp.uv.y()});
      d.keypoint_octave.push_back(kp.octave);
      d.keypoint_angle.push_back(kp.angle);
      const auto& desc = kf.features.descriptors[i];
      d.keypoint_descriptor.insert(d.keypoint_descriptor.end(), desc.begin(), desc.end());
    }
  }
  std::vector<int> new_index(map.points.size(), -1);
  for (size_t i = 0; i < map.points.size(); ++i) {
    const MapPoint& p = map.points[i];
    if (p.bad || p.observations.empty()) continue;
    new_index[i] = static_cast<int>(d.num_mappoints());
    d.mappoint_position.insert(d.mappoint_position.end(), p.position.data(), p.position.data() + 3);
    d.mappoint_descriptor.insert(d.mappoint_descriptor.end(), p.descriptor.begin(),
                                 p.descriptor.end());
    d.mappoint_normal.insert(d.mappoint_normal.end(), p.normal.data(), p.normal.data() + 3);
  }
  for (size_t k = 0; k < map.keyframes.size(); ++k) {
    const Keyframe& kf = map.keyframes[k];
    for (size_t i = 0; i < kf.mappoint.size(); ++i) {
      if (kf.mappoint[i] < 0 || new_index[kf.mappoint[i]] < 0) continue;
      d.observation_keyframe.push_back(static_cast<int32_t>(k));
      d.observation_keypoint.push_back(keypoint_offset[k] + static_cast<int>(i));
      d.observation_mappoint.push_back(new_index[kf.mappoint[i]]);
    }
  }
  for (const CovisibilityEdge& e : Covisibility(map, min_weight)) {
    d.covisibility_edges.insert(d.covisibility_edges.end(), {e.a, e.b});
    d.covisibility_weight.push_back(e.weight);
  }
  return d;
}

VisualMapStats ComputeStats(const io::VisualMapData& d) {
  VisualMapStats s;
  s.keyframes = static_cast<int>(d.keyframes.size());
  s.mappoints = static_cast<int>(d.num_mappoints());
  s.observations = static_cast<int>(d.num_observations());
  s.edges = static_cast<int>(d.num_edges());
  std::vector<double> per_kf(d.keyframes.size(), 0.0), errors;
  std::vector<Rigid3d> cam_from_world;
  for (const Rigid3d& t : d.keyframes.world_from_cam) cam_from_world.push_back(t.Inverse());
  for (size_t o = 0; o < d.num_observations(); ++o) {
    const int k = d.observation_keyframe[o], kp = d.observation_keypoint[o];
    const int m = d.observation_mappoint[o];
    per_kf[k] += 1;
    const Eigen::Vector3d x(d.mappoint_position[3 * m], d.mappoint_position[3 * m + 1],
                            d.mappoint_position[3 * m + 2]);
    const Eigen::Vector3d pc = cam_from_world[k] * x;
    const Eigen::Vector2d uv(d.keypoint_uv[2 * kp], d.keypoint_uv[2 * kp + 1]);
    errors.push_back(pc.z() > 0 ? (d.camera.Project(pc) - uv).norm() : 1e9);
  }
  s.median_points_per_keyframe = Median(per_kf);
  s.min_points_per_keyframe = per_kf.empty() ? 0 : *std::min_element(per_kf.begin(), per_kf.end());
  s.mean_observations_per_point = s.mappoints ? double(s.observations) / s.mappoints : 0.0;
  s.median_reprojection_px = Median(errors);
  s.p90_reprojection_px = Quantile(errors, 0.9);
  return s;
}

}  // namespace jvl::mapping
