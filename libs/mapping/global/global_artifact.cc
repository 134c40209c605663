#include "mapping/global/global_artifact.h"

#include <map>
#include <utility>

#include "core/check.h"
#include "mapping/local/local_artifact.h"

namespace jvl::mapping {

namespace {

template <typename T>
Eigen::Vector3d Row3(const std::vector<T>& a, size_t i) {
  return Eigen::Vector3d(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
}

// One keyframe's stored scan from its float x y z rows (single precision, as in the file); sized
// up front: grown by push_back, the scans of a long sequence took up to twice their size.
lidar::StoredScan ScanOfRows(const float* points, const float* normals, size_t rows) {
  lidar::StoredScan scan;
  scan.points.reserve(rows);
  scan.normals.reserve(rows);
  for (size_t j = 0; j < 3 * rows; j += 3) {
    scan.points.emplace_back(points[j], points[j + 1], points[j + 2]);
    scan.normals.emplace_back(normals[j], normals[j + 1], normals[j + 2]);
  }
  return scan;
}

// The stored scans, one per keyframe; all empty if the data has none.
std::vector<lidar::StoredScan> ScansOf(const io::LocalMapData& d) {
  const size_t k = d.keyframes.size();
  std::vector<lidar::StoredScan> scans(k);
  if (d.scan_offset.empty()) return scans;
  for (size_t i = 0; i < k; ++i) {
    const size_t at = 3 * static_cast<size_t>(d.scan_offset[i]);
    scans[i] = ScanOfRows(d.scan_points.data() + at, d.scan_normals.data() + at,
                          static_cast<size_t>(d.scan_offset[i + 1] - d.scan_offset[i]));
  }
  return scans;
}

// Everything of the artifact but the scans.
StoredLocalMap WithoutScans(const io::LocalMapData& d) {
  StoredLocalMap out;
  out.keyframes = d.keyframes;
  out.imls.reserve(d.num_correspondences());
  for (size_t i = 0; i < d.num_correspondences(); ++i)
    out.imls.push_back({d.imls_n[i], d.imls_c[i], Row3(d.imls_p_x, i), Row3(d.imls_p_y, i),
                        Row3(d.imls_normal, i).normalized()});
  out.mappoints.reserve(d.num_mappoints());
  for (size_t i = 0; i < d.num_mappoints(); ++i)
    out.mappoints.push_back(Row3(d.mappoint_position, i));
  out.prior = d.prior;
  return out;
}

}  // namespace

StoredLocalMap ToStoredLocalMap(const io::LocalMapData& d) {
  StoredLocalMap out = WithoutScans(d);
  out.scans = ScansOf(d);
  return out;
}

StoredLocalMap ReadStoredLocalMap(const std::string& path) {
  // The scans are streamed into their own layout, and the file's flat correspondence arrays are
  // gone before they are read: on a 4500-frame drive holding both copies of both took global_opt
  // past 2 GiB.
  StoredLocalMap out = WithoutScans(io::ReadLocalMap(path, io::LocalMapParts::kWithoutScans));
  out.scans = ReadStoredScans(path);
  JVL_CHECK(out.scans.size() == out.keyframes.size(),
            path << ": " << out.scans.size() << " stored scans for " << out.keyframes.size()
                 << " keyframes (was the file replaced while it was read?)");
  return out;
}

std::vector<lidar::StoredScan> ReadStoredScans(const std::string& path) {
  std::vector<lidar::StoredScan> scans;
  io::ReadLocalScans(path, [&](size_t, const float* points, const float* normals, size_t rows) {
    scans.push_back(ScanOfRows(points, normals, rows));  // keyframes come in order
  });
  return scans;
}

GlobalMapInput AssembleGlobalInput(const io::VisualMapData& visual, StoredLocalMap&& local,
                                   const io::DirectionsData* directions) {
  JVL_CHECK(local.keyframes.frames == visual.keyframes.frames,
            "local and visual artifacts have different keyframes ("
                << local.keyframes.size() << " vs " << visual.keyframes.size() << ")");
  GlobalMapInput in;
  in.camera = visual.camera;
  in.camera_choice = visual.camera_choice;
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
  in.observations = VisualObservations(visual);
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

}  // namespace jvl::mapping
