// New map points of a keyframe (ORB-SLAM2 LocalMapping::CreateNewMapPoints, SearchInNeighbors
// and MapPointCulling), with the prior poses in place of the optimised ones.
#include <algorithm>
#include <utility>
#include <vector>

#include "core/threads.h"
#include "mapping/visual/map_builder.h"

namespace jvl::mapping {
namespace {

// Median depth of the points a keyframe observes (for the baseline test), 0 if it has none.
double MedianDepth(const VisualMap& map, const Keyframe& kf) {
  std::vector<double> depth;
  for (int p : kf.mappoint) {
    if (p >= 0 && !map.points[p].bad)
      depth.push_back((kf.cam_from_world * map.points[p].position).z());
  }
  if (depth.empty()) return 0;
  std::nth_element(depth.begin(), depth.begin() + depth.size() / 2, depth.end());
  return depth[depth.size() / 2];
}

std::vector<bool> Used(const Keyframe& kf) {
  std::vector<bool> used(kf.mappoint.size());
  for (size_t i = 0; i < used.size(); ++i) used[i] = kf.mappoint[i] >= 0;
  return used;
}

}  // namespace

// The previous keyframes, most recent first. For a camera moving along a road these are the
// keyframes with the largest overlap, which ORB-SLAM2 finds through the covisibility graph.
std::vector<int> VisualMapBuilder::NeighbourKeyframes(int keyframe) const {
  std::vector<int> out;
  for (int k = keyframe - 1; k >= 0 && static_cast<int>(out.size()) < options_.local_keyframes;
       --k) {
    out.push_back(k);
  }
  return out;
}

int VisualMapBuilder::CreateNewPoints(int keyframe) {
  const std::vector<int> neighbours = NeighbourKeyframes(keyframe);
  int created = 0;
  for (size_t n = 0;
       n < neighbours.size() && static_cast<int>(n) < options_.triangulation_neighbors; ++n) {
    const Keyframe& kf = map_.keyframes[keyframe];
    const Keyframe& nb = map_.keyframes[neighbours[n]];
    // Too short a baseline for the scene depth gives no usable parallax (ORB-SLAM2, monocular).
    const double baseline =
        (kf.world_from_cam.translation() - nb.world_from_cam.translation()).norm();
    const double depth = MedianDepth(map_, nb);
    if (depth > 0 && baseline / depth < options_.min_baseline_ratio) continue;
    const auto pairs =
        vision::MatchEpipolar(map_.camera, kf.features, kf.cam_from_world, Used(kf), nb.features,
                              nb.cam_from_world, Used(nb), map_.level_scales, options_.epipolar);
    // The points of this neighbour are triangulated first, their keypoints in the neighbour
    // aligned in parallel (each alignment reads its own point only), then inserted in order.
    std::vector<std::pair<int, int>> created_pairs;  // (point, keypoint in the neighbour)
    std::vector<int> keypoint_in_kf;
    for (const auto& [i, j] : pairs) {
      const vision::OrbKeypoint& a = kf.features.keypoints[i];
      const vision::OrbKeypoint& b = nb.features.keypoints[j];
      const vision::TriangulationResult t = vision::TriangulateTwoViews(
          map_.camera, {kf.cam_from_world, a.uv.cast<double>(), map_.level_scales[a.octave]},
          {nb.cam_from_world, b.uv.cast<double>(), map_.level_scales[b.octave]},
          options_.triangulation);
      if (t.status != vision::TriangulationStatus::kOk) continue;
      MapPoint point;
      point.position = t.position;
      point.created_keyframe = keyframe;
      map_.points.push_back(point);
      const int p = static_cast<int>(map_.points.size()) - 1;
      SetPatch(p, keyframe, i);
      created_pairs.emplace_back(p, j);
      keypoint_in_kf.push_back(i);
    }
    const std::vector<Alignment> aligned = ComputeAlignments(created_pairs, neighbours[n]);
    for (size_t c = 0; c < created_pairs.size(); ++c) {
      const auto [p, j] = created_pairs[c];
      const int i = keypoint_in_kf[c];
      if (!ApplyAlignment(aligned[c], neighbours[n], j) && options_.require_alignment) {
        map_.points[p].bad = true;
        continue;
      }
      AddObservation(&map_, p, neighbours[n], j);
      AddObservation(&map_, p, keyframe, i);
      if (options_.refine_on_insert) {
        RefineAndCheck(p);
        if (map_.points[p].bad) continue;
      } else {
        UpdatePointGeometry(&map_, p);
      }
      recent_points_.push_back(p);
      ++created;
    }
  }
  return created;
}

// Adds observations of the new points in the other local keyframes (the "fuse" step of
// ORB-SLAM2 restricted to keypoints without a map point).
int VisualMapBuilder::FusePoints(int keyframe, const std::vector<int>& new_points) {
  int fused = 0;
  std::vector<int> touched;
  for (int k : NeighbourKeyframes(keyframe)) {
    Keyframe& nb = map_.keyframes[k];
    std::vector<int> candidates;
    for (int p : new_points) {
      const auto& obs = map_.points[p].observations;
      const bool seen = std::any_of(obs.begin(), obs.end(),
                                    [k](const Observation& o) { return o.keyframe == k; });
      if (!seen && !map_.points[p].bad) candidates.push_back(p);
    }
    std::vector<int> predicted;
    const auto projected =
        PredictInView(map_, candidates, nb.cam_from_world, options_.min_view_cos, &predicted);
    if (projected.empty()) continue;
    const vision::KeypointGrid grid(nb.features.keypoints, map_.camera.width, map_.camera.height);
    const std::vector<int> match = vision::MatchByProjection(
        projected, nb.features, grid, map_.level_scales, options_.projection, Used(nb));
    std::vector<std::pair<int, int>> pairs;  // (point, keypoint); one keypoint per point
    for (size_t i = 0; i < match.size(); ++i) {
      if (match[i] >= 0) pairs.emplace_back(predicted[i], match[i]);
    }
    const std::vector<Alignment> aligned = ComputeAlignments(pairs, k);
    for (size_t i = 0; i < pairs.size(); ++i) {
      const auto [p, keypoint] = pairs[i];
      if (!ApplyAlignment(aligned[i], k, keypoint) && options_.require_alignment) continue;
      const vision::OrbKeypoint& kp = nb.features.keypoints[keypoint];
      const double s = map_.level_scales[kp.octave];
      if (vision::SquaredReprojectionError(map_.camera, nb.cam_from_world, map_.points[p].position,
                                           kp.uv.cast<double>()) >
          options_.triangulation.max_reprojection_chi2 * s * s) {
        continue;
      }
      AddObservation(&map_, p, k, keypoint);
      touched.push_back(p);
      ++fused;
    }
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (int p : touched) {
    if (options_.refine_on_insert) {
      RefineAndCheck(p);
    } else {
      UpdatePointGeometry(&map_, p);
    }
  }
  return fused;
}

void VisualMapBuilder::SetPatch(int point, int keyframe, int keypoint) {
  MapPoint& p = map_.points[point];
  const vision::OrbFeatures& f = map_.keyframes[keyframe].features;
  if (!options_.align_patches || f.pyramid.empty()) return;
  const vision::OrbKeypoint& kp = f.keypoints[keypoint];
  const cv::Mat& level = f.pyramid[kp.octave];
  p.patch = vision::MakePatchTemplate(
      level, vision::ImageToLevel(kp.uv.cast<double>(), level.size(), f.pyramid[0].size()));
  p.patch_keyframe = keyframe;
  p.patch_octave = kp.octave;
}

VisualMapBuilder::Alignment VisualMapBuilder::ComputeAlignment(int point, int keyframe,
                                                               int keypoint) const {
  Alignment out;
  const MapPoint& p = map_.points[point];
  const Keyframe& kf = map_.keyframes[keyframe];
  if (!options_.align_patches || !p.patch.valid || kf.features.pyramid.empty()) return out;
  const vision::OrbKeypoint& kp = kf.features.keypoints[keypoint];
  const cv::Mat& level = kf.features.pyramid[kp.octave];
  const cv::Size image = kf.features.pyramid[0].size();
  // A patch pixel of the reference level, in pixels of this keypoint's level.
  const Keyframe& ref = map_.keyframes[p.patch_keyframe];
  const double d_ref = (p.position - ref.world_from_cam.translation()).norm();
  const double d = (p.position - kf.world_from_cam.translation()).norm();
  const double scale = std::clamp(
      d_ref * map_.level_scales[p.patch_octave] / (d * map_.level_scales[kp.octave]), 0.7, 1.4);
  const vision::PatchAlignment a = vision::AlignPatch(
      level, p.patch, vision::ImageToLevel(kp.uv.cast<double>(), level.size(), image), scale,
      options_.align);
  out.ok = a.ok;
  if (!a.ok) return out;
  out.moved = true;
  out.uv = vision::LevelToImage(a.level_xy, level.size(), image).cast<float>();
  return out;
}

bool VisualMapBuilder::ApplyAlignment(const Alignment& a, int keyframe, int keypoint) {
  if (a.moved) map_.keyframes[keyframe].features.keypoints[keypoint].uv = a.uv;
  return a.ok;
}

std::vector<VisualMapBuilder::Alignment> VisualMapBuilder::ComputeAlignments(
    const std::vector<std::pair<int, int>>& pairs, int keyframe) const {
  std::vector<Alignment> out(pairs.size());
  // Each alignment reads its own point and keypoint only, so the order does not matter.
  ParallelFor(static_cast<int64_t>(pairs.size()), threads_, [&](int64_t i) {
    out[i] = ComputeAlignment(pairs[i].first, keyframe, pairs[i].second);
  });
  return out;
}

int VisualMapBuilder::RefineAndCheck(int point) {
  MapPoint& p = map_.points[point];
  if (p.bad) return 0;
  int dropped = 0;
  for (int round = 0;; ++round) {
    std::vector<vision::PointView> views;
    for (const Observation& o : p.observations) {
      const Keyframe& kf = map_.keyframes[o.keyframe];
      const vision::OrbKeypoint& kp = kf.features.keypoints[o.keypoint];
      views.push_back({kf.cam_from_world, kp.uv.cast<double>(), map_.level_scales[kp.octave]});
    }
    if (views.size() >= 2) p.position = vision::RefinePoint(map_.camera, views, p.position);
    // Drop the worst observation beyond the bound, then refine again without it.
    int worst = -1;
    double worst_chi2 = options_.max_final_chi2;
    for (size_t v = 0; v < views.size(); ++v) {
      const double chi2 = vision::SquaredReprojectionError(map_.camera, views[v].cam_from_world,
                                                           p.position, views[v].uv) /
                          (views[v].level_scale * views[v].level_scale);
      if (chi2 > worst_chi2) worst_chi2 = chi2, worst = static_cast<int>(v);
    }
    if (worst < 0 || round == 3) break;
    const Observation o = p.observations[worst];
    map_.keyframes[o.keyframe].mappoint[o.keypoint] = -1;
    p.observations.erase(p.observations.begin() + worst);
    ++dropped;
    if (p.observations.size() < 2) {
      RemovePoint(&map_, point);
      return dropped;
    }
  }
  UpdatePointGeometry(&map_, point);
  return dropped;
}

// ORB-SLAM2 MapPointCulling: a recent point must be found in >= 25 % of the frames predicting it
// and, once cull_after_keyframes keyframes have passed, be observed by >= min_observations
// keyframes; a point that survives one more keyframe is kept for good.
int VisualMapBuilder::CullRecentPoints(int keyframe) {
  int culled = 0;
  std::vector<int> still_recent;
  for (int p : recent_points_) {
    MapPoint& point = map_.points[p];
    if (point.bad) continue;
    const int age = keyframe - point.created_keyframe;
    const bool rarely_found = point.found < options_.min_found_ratio * point.visible;
    const bool few_views = age >= options_.cull_after_keyframes &&
                           static_cast<int>(point.observations.size()) < options_.min_observations;
    if (rarely_found || few_views) {
      RemovePoint(&map_, p);
      ++culled;
    } else if (age <= options_.cull_after_keyframes) {
      still_recent.push_back(p);
    }
  }
  recent_points_ = std::move(still_recent);
  return culled;
}

}  // namespace jvl::mapping
