// The body of sim_map_check, callable without a command line: rebuild the world of a simulated
// sequence from its sim/scene.json and measure how far the points of a visual map lie from the
// true scene surface (sim/map_check.h).
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/trajectory.h"
#include "io/visual_io.h"
#include "sim/map_check.h"
#include "sim/sequence.h"

namespace jvl::tools {

// The options that rebuild the world described by a scene.json body (scenario, seed, frames,
// stop, moving cars), without images or scans; `what` names the file in errors.
sim::SequenceOptions WorldOptionsFromScene(const nlohmann::json& scene, const std::string& what);

// Throws unless `world` is the one scene.json describes (frames, world_from_map, mesh size,
// buildings) and, when given, its ground truth equals `poses` (the sequence's poses file).
void CheckSameWorld(const sim::World& world, const nlohmann::json& scene,
                    const std::optional<Trajectory>& poses, const std::string& what);

// Rebuilds the world of a sequence folder (sequences/NN with sim/scene.json; poses/NN.txt two
// levels up is compared when present) and checks it is the same.
std::unique_ptr<sim::World> RebuildSequenceWorld(const std::string& sequence_dir);

struct MapCheckRunResult {
  std::vector<sim::PointView> views;  // Map frame.
  std::vector<sim::SurfaceDistance> distances;
  sim::SurfaceCheckSummary summary;
  // Keyframe poses of the visual map against the ground truth: a map built from another prior
  // carries that prior's pose errors into the measured distances.
  double max_keyframe_position_error_m = 0;
  double max_keyframe_rotation_error_deg = 0;
};

MapCheckRunResult RunMapCheck(const sim::World& world, const io::VisualMapData& visual,
                              const sim::SurfaceCheckOptions& options, int threads);

nlohmann::json ToJson(const MapCheckRunResult& result);

// Per map point: how well its observations agree with one true surface point. The point seen
// behind its keypoint in the nearest keyframe (ray cast) is projected into every observing
// keyframe; the result is the largest distance to the observing keypoint in units of that
// keypoint's sigma (scale^octave px). NaN when that ray hits nothing, +inf when the surface point
// is behind an observing camera.
std::vector<double> KeypointConsistency(const sim::World& world, const io::VisualMapData& visual,
                                        const std::vector<sim::PointView>& views);

// One line per map point: "point,x,y,z,frame,depth,hit,surface,along_ray,perpendicular,
// cos_incidence,observations,parallax_deg,keypoint_error_sigma" (x, y, z in the pose world
// frame; frame: the keyframe measured from, -1 for none; surface: the material hit, moving_car
// or none; parallax: the largest angle between two of the point's viewing rays;
// keypoint_error_sigma: KeypointConsistency, -1 when not finite).
std::string FormatPointsCsv(const MapCheckRunResult& result, const sim::World& world,
                            const io::VisualMapData& visual);

}  // namespace jvl::tools
