#include "mapping/visual/visual_map.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/check.h"

namespace jvl::mapping {
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

}  // namespace jvl::mapping
