#include "mapping/summary.h"

#include <algorithm>
#include <cstdio>
#include <map>

#include "core/check.h"

namespace jvl::mapping {
namespace {

double MedianOf(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
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
  std::vector<double> total_ms, assoc_ms;
  for (size_t i = 0; i < result.frames.size(); ++i) {
    const FrameReport& f = result.frames[i];
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
  j["median_frame_ms"] = MedianOf(total_ms);
  j["median_association_ms"] = MedianOf(assoc_ms);
  j["median_orb_ms"] = MedianOf(result.orb_ms);
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

}  // namespace jvl::mapping
