// The "directions" artifact (schema "directions" v1, schemas/directions.schema.json): direction
// priors d_w (clusters) and the VPs associated to them (at most one per frame); its CSV export.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "io/artifact.h"

namespace jvl::io {

struct DirectionClusterRow {
  int32_t id = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // Unit, world.
  double std_deg = 0;
  int32_t size = 0;
  int64_t first_frame = 0, last_frame = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

struct DirectionAssociationRow {
  int64_t frame = 0;
  int32_t vp_index = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  int32_t cluster = 0;
};

struct DirectionsData {
  std::vector<DirectionClusterRow> clusters;
  std::vector<DirectionAssociationRow> associations;
  nlohmann::json summary = nlohmann::json::object();  // Counts per step, ground frame, ...
  // The camera of the VP pixels (associations/uv): the vps artifact's (camera 0 when absent).
  CameraChoice camera_choice;
};

void WriteDirectionsArtifact(const std::string& path, const DirectionsData& data,
                             const Provenance& provenance);
// Checks schema, shapes, that cluster ids exist and that no frame appears twice.
DirectionsData ReadDirectionsArtifact(const std::string& path);

// "frame,cluster,u,v,dwx,dwy,dwz": one row per association, d_w of its cluster.
std::string FormatDirectionsCsv(const DirectionsData& data);
void WriteDirectionsCsv(const std::string& path, const DirectionsData& data);

}  // namespace jvl::io
