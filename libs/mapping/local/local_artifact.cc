#include "mapping/local/local_artifact.h"

#include <type_traits>
#include <vector>

#include "core/check.h"
#include "core/memory.h"

namespace jvl::mapping {
namespace {

void AppendVector(const Eigen::Vector3d& v, std::vector<double>* out) {
  out->insert(out->end(), {v.x(), v.y(), v.z()});
}

// A non-const `result` is consumed: its correspondences and scans are freed as they are copied,
// and the heap's free pages are returned every kTrimEvery scans (the scans are many small
// allocations whose pages glibc would otherwise keep resident next to the growing flat arrays).
template <typename Result>
io::LocalMapData Export(const LocalMappingInput& input, Result& result, const Trajectory& prior,
                        const nlohmann::json& summary) {
  constexpr bool consume = !std::is_const_v<Result>;
  constexpr size_t kTrimEvery = 256;
  io::LocalMapData d;
  d.camera = input.camera;
  d.camera_choice = input.camera_choice;
  d.keyframes = RefinedKeyframes(input, result);
  const size_t l = result.correspondences.size();
  d.imls_n.reserve(l);
  d.imls_c.reserve(l);
  d.imls_p_x.reserve(3 * l);
  d.imls_p_y.reserve(3 * l);
  d.imls_normal.reserve(3 * l);
  for (const optim::ImlsCorrespondence& c : result.correspondences) {
    d.imls_n.push_back(static_cast<int32_t>(c.n));
    d.imls_c.push_back(static_cast<int32_t>(c.c));
    AppendVector(c.p_x, &d.imls_p_x);
    AppendVector(c.c_p_y, &d.imls_p_y);
    AppendVector(c.c_normal, &d.imls_normal);
  }
  if constexpr (consume) {
    std::vector<optim::ImlsCorrespondence>().swap(result.correspondences);
    ReleaseFreeHeapMemory();
  }
  d.mappoint_position.reserve(3 * result.map_points.size());
  for (const Eigen::Vector3d& p : result.map_points) AppendVector(p, &d.mappoint_position);
  size_t points = 0;
  for (const lidar::StoredScan& scan : result.scans) points += scan.points.size();
  d.scan_offset.reserve(result.scans.size() + 1);
  d.scan_points.reserve(3 * points);
  d.scan_normals.reserve(3 * points);
  d.scan_offset.push_back(0);
  for (size_t k = 0; k < result.scans.size(); ++k) {
    auto& scan = result.scans[k];
    for (size_t i = 0; i < scan.points.size(); ++i) {
      const Eigen::Vector3f& p = scan.points[i];
      const Eigen::Vector3f& n = scan.normals[i];
      d.scan_points.insert(d.scan_points.end(), {p.x(), p.y(), p.z()});
      d.scan_normals.insert(d.scan_normals.end(), {n.x(), n.y(), n.z()});
    }
    d.scan_offset.push_back(d.scan_offset.back() + static_cast<int64_t>(scan.points.size()));
    if constexpr (consume) {
      scan = lidar::StoredScan();
      if ((k + 1) % kTrimEvery == 0) ReleaseFreeHeapMemory();
    }
  }
  if constexpr (consume) {
    std::vector<lidar::StoredScan>().swap(result.scans);
    ReleaseFreeHeapMemory();
  }
  d.stats_frame.reserve(result.stats.size());
  for (const KeyframeStats& k : result.stats) {
    d.stats_frame.push_back(k.frame);
    d.stats_visual_residuals.push_back(k.visual_residuals);
    d.stats_imls_residuals.push_back(k.imls_residuals);
    d.stats_cost_before.push_back(k.cost_before);
    d.stats_cost_after.push_back(k.cost_after);
    d.stats_time_ms.push_back(k.time_ms);
  }
  d.prior = prior;
  d.summary = summary;
  return d;
}

}  // namespace

std::vector<optim::VisualObservation> VisualObservations(const io::VisualMapData& visual) {
  std::vector<optim::VisualObservation> out;
  out.reserve(visual.num_observations());
  for (size_t o = 0; o < visual.num_observations(); ++o) {
    const int32_t kp = visual.observation_keypoint[o];
    optim::VisualObservation obs;
    obs.keyframe = visual.observation_keyframe[o];
    obs.map_point = visual.observation_mappoint[o];
    obs.uv = Eigen::Vector2d(visual.keypoint_uv[2 * kp], visual.keypoint_uv[2 * kp + 1]);
    obs.octave = visual.keypoint_octave[kp];
    out.push_back(obs);
  }
  return out;
}

LocalMappingInput MakeLocalMappingInput(const io::VisualMapData& visual, const Trajectory& prior,
                                        const std::string& prior_name) {
  LocalMappingInput in;
  in.camera = visual.camera;
  in.camera_choice = visual.camera_choice;
  in.frames = visual.keyframes.frames;
  in.map_poses = visual.keyframes.world_from_cam;
  for (const int64_t f : in.frames) {
    const auto i = prior.IndexOf(f);
    JVL_CHECK(i.has_value(), prior_name << " has no pose for keyframe frame " << f);
    in.prior.push_back(prior.world_from_cam[*i]);
  }
  for (size_t m = 0; m < visual.num_mappoints(); ++m) {
    in.map_points.emplace_back(&visual.mappoint_position[3 * m]);
  }
  in.observations = VisualObservations(visual);
  for (size_t e = 0; e < visual.num_edges(); ++e) {
    in.covisibility.push_back(
        {visual.covisibility_edges[2 * e], visual.covisibility_edges[2 * e + 1]});
  }
  in.Check();
  return in;
}

io::LocalMapData ExportLocalMap(const LocalMappingInput& input, const LocalMappingResult& result,
                                const Trajectory& prior, const nlohmann::json& summary) {
  return Export(input, result, prior, summary);
}

io::LocalMapData ExportLocalMap(const LocalMappingInput& input, LocalMappingResult&& result,
                                const Trajectory& prior, const nlohmann::json& summary) {
  return Export(input, result, prior, summary);
}

}  // namespace jvl::mapping
