#include "assemble.h"

#include <map>
#include <utility>

#include "core/check.h"

namespace jvl::global_opt {

mapping::GlobalMapInput AssembleGlobalInput(const io::VisualMapData& visual, LocalInput&& local,
                                            const io::DirectionsData* directions) {
  JVL_CHECK(local.keyframes.frames == visual.keyframes.frames,
            "local and visual artifacts have different keyframes ("
                << local.keyframes.size() << " vs " << visual.keyframes.size() << ")");
  mapping::GlobalMapInput in;
  in.camera = visual.camera;
  in.keyframes = local.keyframes;
  const size_t m = visual.num_mappoints();
  if (!local.mappoints.empty()) {
    JVL_CHECK(local.mappoints.size() == m,
              "local has " << local.mappoints.size() << " map points, visual " << m);
    in.map_points = std::move(local.mappoints);
  } else {
    for (size_t i = 0; i < m; ++i)
      in.map_points.emplace_back(visual.mappoint_position[3 * i],
                                 visual.mappoint_position[3 * i + 1],
                                 visual.mappoint_position[3 * i + 2]);
  }
  in.observations.reserve(visual.num_observations());
  for (size_t o = 0; o < visual.num_observations(); ++o) {
    const int32_t kp = visual.observation_keypoint[o];
    optim::VisualObservation obs;
    obs.keyframe = visual.observation_keyframe[o];
    obs.map_point = visual.observation_mappoint[o];
    obs.uv = Eigen::Vector2d(visual.keypoint_uv[2 * kp], visual.keypoint_uv[2 * kp + 1]);
    obs.octave = visual.keypoint_octave[kp];
    in.observations.push_back(obs);
  }
  in.saved_imls = std::move(local.imls);
  in.scans = std::move(local.scans);
  if (directions != nullptr) {
    std::map<int32_t, Eigen::Vector3d> d_w;
    for (const auto& c : directions->clusters) d_w[c.id] = c.direction;
    for (const auto& a : directions->associations) {
      const auto it = d_w.find(a.cluster);
      JVL_CHECK(it != d_w.end(),
                "association of frame " << a.frame << " names unknown cluster " << a.cluster);
      in.directions.push_back({a.frame, a.uv, it->second, a.cluster});
    }
  }
  return in;
}

}  // namespace jvl::global_opt
