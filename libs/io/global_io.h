// The "global" artifact (schema "global" v1, schemas/global.schema.json), written by global_opt
// (Sec. 4.3):
//
//   keyframes/{frames, poses}               the optimised keyframe poses (world_from_cam0)
//   trajectory/{frames, poses, timestamps}  full rate: every prior frame, corrected
//   prior/{frames, poses, timestamps}       the prior the full-rate trajectory was built from
//   attribute "stats" (JSON)                residual counts and costs before/after by type,
//                                           weights used, solver summary
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "geometry/trajectory.h"
#include "io/artifact.h"

namespace jvl::io {

inline constexpr const char* kGlobalSchema = "global";
inline constexpr int kGlobalSchemaVersion = 1;

struct GlobalData {
  Trajectory keyframes;
  Trajectory trajectory;
  Trajectory prior;
  nlohmann::json stats = nlohmann::json::object();
};

void WriteGlobalArtifact(const std::string& path, const GlobalData& data,
                         const Provenance& provenance);
// Checks schema and that every keyframe is a frame of the full-rate trajectory.
GlobalData ReadGlobalArtifact(const std::string& path);

}  // namespace jvl::io
