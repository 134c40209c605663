#include "io/visual_io.h"

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "core/check.h"
#include "io/camera_io.h"
#include "io/trajectory_io.h"

namespace jvl::io {
namespace {

template <typename T>
void CheckSize(const std::vector<T>& v, size_t n, const char* name, const std::string& what) {
  JVL_CHECK(v.size() == n,
            what << ": " << name << " has " << v.size() << " values, expected " << n);
}

template <typename T>
void CheckIndices(const std::vector<T>& v, size_t bound, const char* name,
                  const std::string& what) {
  for (size_t i = 0; i < v.size(); ++i) {
    JVL_CHECK(
        v[i] >= 0 && static_cast<size_t>(v[i]) < bound,
        what << ": " << name << "[" << i << "] = " << v[i] << " out of range [0, " << bound << ")");
  }
}

}  // namespace

std::vector<int64_t> VisualMapData::CovisibilityPartStarts() const {
  std::vector<std::vector<int32_t>> adjacency(keyframes.size());
  for (size_t e = 0; e < num_edges(); ++e) {
    const int32_t a = covisibility_edges[2 * e], b = covisibility_edges[2 * e + 1];
    adjacency[static_cast<size_t>(a)].push_back(b);
    adjacency[static_cast<size_t>(b)].push_back(a);
  }
  std::vector<uint8_t> seen(keyframes.size(), 0);
  std::vector<int64_t> starts;
  for (size_t root = 0; root < adjacency.size(); ++root) {
    if (seen[root]) continue;
    starts.push_back(keyframes.frames[root]);
    std::vector<size_t> stack = {root};
    seen[root] = 1;
    while (!stack.empty()) {
      const size_t k = stack.back();
      stack.pop_back();
      for (const int32_t next : adjacency[k]) {
        if (seen[static_cast<size_t>(next)]) continue;
        seen[static_cast<size_t>(next)] = 1;
        stack.push_back(static_cast<size_t>(next));
      }
    }
  }
  return starts;
}

void VisualMapData::Check(const std::string& what, VisualMapParts parts) const {
  const bool descriptors = parts == VisualMapParts::kAll;
  keyframes.Check((what + " keyframes").c_str());
  const size_t p = num_keypoints(), m = num_mappoints(), o = num_observations(), e = num_edges();
  CheckSize(keypoint_uv, 2 * p, "keypoints/uv", what);
  CheckSize(keypoint_octave, p, "keypoints/octave", what);
  CheckSize(keypoint_angle, p, "keypoints/angle", what);
  CheckSize(keypoint_descriptor, descriptors ? 32 * p : 0, "keypoints/descriptor", what);
  CheckSize(mappoint_position, 3 * m, "mappoints/position", what);
  CheckSize(mappoint_descriptor, descriptors ? 32 * m : 0, "mappoints/descriptor", what);
  CheckSize(mappoint_normal, 3 * m, "mappoints/normal", what);
  CheckSize(observation_keyframe, o, "observations/keyframe", what);
  CheckSize(observation_keypoint, o, "observations/keypoint", what);
  CheckSize(covisibility_edges, 2 * e, "covisibility/edges", what);
  CheckIndices(keypoint_keyframe, keyframes.size(), "keypoints/keyframe", what);
  CheckIndices(observation_keyframe, keyframes.size(), "observations/keyframe", what);
  CheckIndices(observation_keypoint, p, "observations/keypoint", what);
  CheckIndices(observation_mappoint, m, "observations/mappoint", what);
  CheckIndices(covisibility_edges, keyframes.size(), "covisibility/edges", what);
  for (size_t i = 0; i < o; ++i) {
    JVL_CHECK(keypoint_keyframe[observation_keypoint[i]] == observation_keyframe[i],
              what << ": observation " << i << " refers to a keypoint of another keyframe");
  }
  for (size_t i = 0; i < 3 * m; ++i) {
    JVL_CHECK(std::isfinite(mappoint_position[i]) && std::isfinite(mappoint_normal[i]),
              what << ": map point " << i / 3 << " has a non-finite "
                   << (std::isfinite(mappoint_position[i]) ? "normal" : "position"));
  }
  for (size_t i = 0; i < 2 * p; ++i) {
    JVL_CHECK(std::isfinite(keypoint_uv[i]),
              what << ": keypoint " << i / 2 << " has a non-finite position");
  }
}

void WriteVisualMap(const std::string& path, const VisualMapData& d, const Provenance& provenance) {
  d.Check(path);
  const int64_t p = static_cast<int64_t>(d.num_keypoints());
  const int64_t m = static_cast<int64_t>(d.num_mappoints());
  H5Writer w(path, kVisualSchema, kVisualSchemaVersion);
  WriteCameraArray(w, "camera", d.camera);
  WriteCameraChoice(w, d.camera_choice);
  w.WriteJson("orb", {{"scale_factor", d.scale_factor}, {"num_levels", d.num_levels}});
  WriteTrajectoryGroup(w, "keyframes", d.keyframes);
  w.WriteArray("keypoints/keyframe", d.keypoint_keyframe);
  w.WriteArray("keypoints/uv", d.keypoint_uv, {p, 2});
  w.WriteArray("keypoints/octave", d.keypoint_octave);
  w.WriteArray("keypoints/angle", d.keypoint_angle);
  w.WriteArray("keypoints/descriptor", d.keypoint_descriptor, {p, 32});
  w.WriteArray("mappoints/position", d.mappoint_position, {m, 3});
  w.WriteArray("mappoints/descriptor", d.mappoint_descriptor, {m, 32});
  w.WriteArray("mappoints/normal", d.mappoint_normal, {m, 3});
  w.WriteArray("observations/keyframe", d.observation_keyframe);
  w.WriteArray("observations/keypoint", d.observation_keypoint);
  w.WriteArray("observations/mappoint", d.observation_mappoint);
  w.WriteArray("covisibility/edges", d.covisibility_edges,
               {static_cast<int64_t>(d.num_edges()), 2});
  w.WriteArray("covisibility/weight", d.covisibility_weight);
  WriteTrajectoryGroup(w, "prior", d.prior);
  w.WriteJson("summary", d.summary);
  w.Commit(provenance);
}

namespace {

// The camera choice, the ORB pyramid and the keyframes of a visual map.
void ReadHeader(H5Reader& r, const std::string& path, VisualMapData* d) {
  d->camera_choice = ReadCameraChoice(r);
  const nlohmann::json orb = r.ReadJson("orb");
  JVL_CHECK(orb.is_object() && orb.contains("scale_factor") && orb["scale_factor"].is_number() &&
                orb.contains("num_levels") && orb["num_levels"].is_number_integer(),
            path << ": attribute 'orb' lacks a numeric scale_factor / integer num_levels");
  d->scale_factor = orb["scale_factor"].get<double>();
  d->num_levels = orb["num_levels"].get<int>();
  JVL_CHECK(std::isfinite(d->scale_factor) && d->scale_factor > 1.0 && d->scale_factor < 2.0 &&
                d->num_levels >= 1 && d->num_levels <= 32,
            path << ": attribute 'orb' has scale_factor " << d->scale_factor << " and num_levels "
                 << d->num_levels << " (expected in (1, 2) and 1..32)");
  d->keyframes = ReadTrajectoryGroup(r, "keyframes");
}

}  // namespace

VisualMapData ReadVisualMapHeader(const std::string& path) {
  H5Reader r(path, kVisualSchema, kVisualSchemaVersion);
  VisualMapData d;
  ReadHeader(r, path, &d);
  d.keyframes.Check((path + ": keyframes").c_str());
  return d;
}

VisualMapData ReadVisualMap(const std::string& path, VisualMapParts parts) {
  const bool descriptors = parts == VisualMapParts::kAll;
  H5Reader r(path, kVisualSchema, kVisualSchemaVersion);
  VisualMapData d;
  d.camera = ReadCameraArray(r, "camera");
  ReadHeader(r, path, &d);
  d.keypoint_keyframe = r.ReadArray<int32_t>("keypoints/keyframe");
  d.keypoint_uv = r.ReadArray<float>("keypoints/uv", 2);
  d.keypoint_octave = r.ReadArray<int32_t>("keypoints/octave");
  d.keypoint_angle = r.ReadArray<float>("keypoints/angle");
  if (descriptors) d.keypoint_descriptor = r.ReadArray<uint8_t>("keypoints/descriptor", 32);
  d.mappoint_position = r.ReadArray<double>("mappoints/position", 3);
  if (descriptors) d.mappoint_descriptor = r.ReadArray<uint8_t>("mappoints/descriptor", 32);
  d.mappoint_normal = r.ReadArray<double>("mappoints/normal", 3);
  d.observation_keyframe = r.ReadArray<int32_t>("observations/keyframe");
  d.observation_keypoint = r.ReadArray<int32_t>("observations/keypoint");
  d.observation_mappoint = r.ReadArray<int32_t>("observations/mappoint");
  d.covisibility_edges = r.ReadArray<int32_t>("covisibility/edges", 2);
  d.covisibility_weight = r.ReadArray<int32_t>("covisibility/weight");
  d.prior = ReadTrajectoryGroup(r, "prior");
  d.summary = r.ReadJson("summary");
  d.Check(path, parts);
  return d;
}

VisualMapData ReadVisualKeypoints(const std::string& path, const std::vector<int64_t>& frames) {
  H5Reader r(path, kVisualSchema, kVisualSchemaVersion);
  VisualMapData d;
  d.camera = ReadCameraArray(r, "camera");
  ReadHeader(r, path, &d);
  d.keyframes.Check((path + ": keyframes").c_str());
  const std::vector<int32_t> keyframe_of = r.ReadArray<int32_t>("keypoints/keyframe");
  CheckIndices(keyframe_of, d.keyframes.size(), "keypoints/keyframe", path);
  // Rows [first, last) of each keyframe row; a keyframe's keypoints are contiguous.
  std::vector<std::pair<int64_t, int64_t>> rows_of(d.keyframes.size(), {-1, -1});
  for (size_t p = 0; p < keyframe_of.size(); ++p) {
    auto& rows = rows_of[static_cast<size_t>(keyframe_of[p])];
    const auto row = static_cast<int64_t>(p);
    JVL_CHECK(rows.first < 0 || rows.second == row,
              path << ": keypoints of keyframe row " << keyframe_of[p]
                   << " are not contiguous (row " << p << ")");
    if (rows.first < 0) rows.first = row;
    rows.second = row + 1;
  }
  std::vector<std::pair<int64_t, int64_t>> wanted;
  for (const int64_t f : frames) {
    const std::optional<size_t> k = d.keyframes.IndexOf(f);
    if (k && rows_of[*k].first >= 0) wanted.push_back(rows_of[*k]);
  }
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  for (const auto& [first, last] : wanted) {
    d.keypoint_keyframe.insert(d.keypoint_keyframe.end(), keyframe_of.begin() + first,
                               keyframe_of.begin() + last);
  }
  d.keypoint_uv = r.ReadRows<float>("keypoints/uv", wanted, 2);
  d.keypoint_octave = r.ReadRows<int32_t>("keypoints/octave", wanted);
  d.keypoint_angle = r.ReadRows<float>("keypoints/angle", wanted);
  d.keypoint_descriptor = r.ReadRows<uint8_t>("keypoints/descriptor", wanted, 32);
  d.Check(path);
  return d;
}

void WarnIfCovisibilitySplit(const VisualMapData& data, const std::string& path) {
  const std::vector<int64_t> parts = data.CovisibilityPartStarts();
  if (parts.size() <= 1) return;
  spdlog::warn(
      "{}: the covisibility graph has {} parts (starting at frames {}); keyframes of different "
      "parts share no map point and are joined only by the LiDAR terms",
      path, parts.size(), fmt::join(parts, ", "));
}

}  // namespace jvl::io
