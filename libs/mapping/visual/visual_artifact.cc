#include "mapping/visual/visual_artifact.h"

#include <algorithm>
#include <cstdio>
#include <map>

#include "core/check.h"
#include "core/statistics.h"

namespace jvl::mapping {
namespace {

// The summaries report 0 for an empty sample (the artifact's statistics are numbers).
double MedianOrZero(const std::vector<double>& v) { return v.empty() ? 0.0 : Median(v); }

double QuantileOrZero(const std::vector<double>& v, double q) {
  return v.empty() ? 0.0 : Quantile(v, q);
}

}  // namespace

Trajectory SelectPriorPoses(const Trajectory& prior, const std::vector<int64_t>& frames,
                            const std::string& what) {
  Trajectory out;
  for (int64_t f : frames) {
    const auto i = prior.IndexOf(f);
    JVL_CHECK(i, what << ": prior trajectory has no pose for frame " << f);
    out.Append(f, prior.world_from_cam[*i],
               prior.has_timestamps() ? std::optional<double>(prior.timestamps[*i]) : std::nullopt);
  }
  return out;
}

nlohmann::json Summarize(const VisualMapResult& result, const VisualMapStats& stats) {
  std::map<std::string, int> reasons;
  std::vector<double> total_ms, assoc_ms, change_deg, change_m;
  int refined = 0;
  for (size_t i = 0; i < result.frames.size(); ++i) {
    const FrameReport& f = result.frames[i];
    refined += f.pose_refined ? 1 : 0;
    change_deg.push_back(f.pose_change_deg);
    change_m.push_back(f.pose_change_m);
    if (f.keyframe) ++reasons[ToString(f.reason)];
    assoc_ms.push_back(f.ms);
    total_ms.push_back(f.ms + (i < result.orb_ms.size() ? result.orb_ms[i] : 0.0));
  }
  nlohmann::json j;
  j["frames"] = result.frames.size();
  j["keyframes"] = stats.keyframes;
  j["keyframe_reasons"] = reasons;
  j["mappoints"] = stats.mappoints;
  j["observations"] = stats.observations;
  j["covisibility_edges"] = stats.edges;
  j["median_points_per_keyframe"] = stats.median_points_per_keyframe;
  j["min_points_per_keyframe"] = stats.min_points_per_keyframe;
  j["mean_observations_per_point"] = stats.mean_observations_per_point;
  j["median_reprojection_px"] = stats.median_reprojection_px;
  j["p90_reprojection_px"] = stats.p90_reprojection_px;
  j["median_frame_ms"] = MedianOrZero(total_ms);
  j["median_association_ms"] = MedianOrZero(assoc_ms);
  j["median_orb_ms"] = MedianOrZero(result.orb_ms);
  if (result.track_pose) {  // Pose tracking: how far the poses used are from the prior's.
    j["pose_refined_frames"] = refined;
    j["median_pose_change_deg"] = MedianOrZero(change_deg);
    j["max_pose_change_deg"] =
        change_deg.empty() ? 0.0 : *std::max_element(change_deg.begin(), change_deg.end());
    j["median_pose_change_m"] = MedianOrZero(change_m);
    j["max_pose_change_m"] =
        change_m.empty() ? 0.0 : *std::max_element(change_m.begin(), change_m.end());
  }
  return j;
}

std::string FormatSummary(const nlohmann::json& s) {
  char buf[1024];
  std::snprintf(
      buf, sizeof(buf),
      "frames %d  keyframes %d  map points %d  observations %d  covisibility edges %d\n"
      "map points per keyframe: median %.0f  min %.0f;  observations per point %.2f\n"
      "reprojection error: median %.3f px  p90 %.3f px\n"
      "time per frame (median): %.1f ms (ORB %.1f ms, association %.1f ms)\n"
      "keyframe reasons: %s",
      s.at("frames").get<int>(), s.at("keyframes").get<int>(), s.at("mappoints").get<int>(),
      s.at("observations").get<int>(), s.at("covisibility_edges").get<int>(),
      s.at("median_points_per_keyframe").get<double>(),
      s.at("min_points_per_keyframe").get<double>(),
      s.at("mean_observations_per_point").get<double>(),
      s.at("median_reprojection_px").get<double>(), s.at("p90_reprojection_px").get<double>(),
      s.at("median_frame_ms").get<double>(), s.at("median_orb_ms").get<double>(),
      s.at("median_association_ms").get<double>(), s.at("keyframe_reasons").dump().c_str());
  return buf;
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

std::unordered_map<int64_t, std::pair<size_t, size_t>> KeypointRowsByFrame(
    const io::VisualMapData& data) {
  std::unordered_map<int64_t, std::pair<size_t, size_t>> rows;
  for (size_t p = 0; p < data.num_keypoints(); ++p) {
    const int32_t k = data.keypoint_keyframe[p];
    JVL_CHECK(
        k >= 0 && static_cast<size_t>(k) < data.keyframes.size(),
        "keypoint " << p << " refers to keyframe row " << k << " of " << data.keyframes.size());
    const int64_t f = data.keyframes.frames[static_cast<size_t>(k)];
    auto [it, added] = rows.emplace(f, std::make_pair(p, p + 1));
    JVL_CHECK(added || it->second.second == p,
              "keypoints of frame " << f << " are not contiguous (row " << p << ")");
    it->second.second = p + 1;
  }
  return rows;
}

vision::OrbFeatures KeyframeFeatures(const io::VisualMapData& data, size_t first, size_t last) {
  JVL_CHECK(first <= last && last <= data.num_keypoints(),
            "keypoint rows [" << first << ", " << last << ") outside the " << data.num_keypoints()
                              << " of the visual map");
  vision::OrbFeatures out;
  out.keypoints.reserve(last - first);
  out.descriptors.reserve(last - first);
  for (size_t p = first; p < last; ++p) {
    vision::OrbKeypoint k;
    k.uv = Eigen::Vector2f(data.keypoint_uv[2 * p], data.keypoint_uv[2 * p + 1]);
    k.octave = data.keypoint_octave[p];
    k.angle = data.keypoint_angle[p];
    out.keypoints.push_back(k);
    vision::Descriptor d;
    std::copy_n(data.keypoint_descriptor.begin() + static_cast<std::ptrdiff_t>(32 * p), 32,
                d.begin());
    out.descriptors.push_back(d);
  }
  return out;
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
    const Eigen::Vector3d pc = cam_from_world[k] * x + d.camera_choice.offset;
    const Eigen::Vector2d uv(d.keypoint_uv[2 * kp], d.keypoint_uv[2 * kp + 1]);
    errors.push_back(pc.z() > 0 ? (d.camera.Project(pc) - uv).norm() : 1e9);
  }
  s.median_points_per_keyframe = MedianOrZero(per_kf);
  s.min_points_per_keyframe = per_kf.empty() ? 0 : *std::min_element(per_kf.begin(), per_kf.end());
  s.mean_observations_per_point = s.mappoints ? double(s.observations) / s.mappoints : 0.0;
  s.median_reprojection_px = MedianOrZero(errors);
  s.p90_reprojection_px = QuantileOrZero(errors, 0.9);
  return s;
}

}  // namespace jvl::mapping
