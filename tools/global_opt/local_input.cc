#include "local_input.h"

#include "core/check.h"
#include "io/local_io.h"

namespace jvl::global_opt {

namespace {

template <typename T>
Eigen::Vector3d Row3(const std::vector<T>& a, size_t i) {
  return Eigen::Vector3d(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
}

// The stored scans (single precision, as in the file), one per keyframe; all empty if the file
// has none.
std::vector<lidar::StoredScan> ScansOf(const io::LocalMapData& d) {
  const size_t k = d.keyframes.size();
  std::vector<lidar::StoredScan> scans(k);
  if (d.scan_offset.empty()) return scans;
  for (size_t i = 0; i < k; ++i) {
    // Sized up front: grown by push_back, the scans of a long sequence took up to twice their size.
    const auto count = static_cast<size_t>(d.scan_offset[i + 1] - d.scan_offset[i]);
    scans[i].points.reserve(count);
    scans[i].normals.reserve(count);
    for (int64_t j = d.scan_offset[i]; j < d.scan_offset[i + 1]; ++j) {
      const size_t r = 3 * static_cast<size_t>(j);
      scans[i].points.emplace_back(d.scan_points[r], d.scan_points[r + 1], d.scan_points[r + 2]);
      scans[i].normals.emplace_back(d.scan_normals[r], d.scan_normals[r + 1],
                                    d.scan_normals[r + 2]);
    }
  }
  return scans;
}

}  // namespace

LocalInput ToLocalInput(const io::LocalMapData& d) {
  LocalInput out;
  out.keyframes = d.keyframes;
  out.imls.reserve(d.num_correspondences());
  for (size_t i = 0; i < d.num_correspondences(); ++i)
    out.imls.push_back({d.imls_n[i], d.imls_c[i], Row3(d.imls_p_x, i), Row3(d.imls_p_y, i),
                        Row3(d.imls_normal, i).normalized()});
  out.mappoints.reserve(d.num_mappoints());
  for (size_t i = 0; i < d.num_mappoints(); ++i)
    out.mappoints.push_back(Row3(d.mappoint_position, i));
  out.scans = ScansOf(d);
  out.prior = d.prior;
  return out;
}

LocalInput ReadLocalInput(const std::string& path) { return ToLocalInput(io::ReadLocalMap(path)); }

std::vector<lidar::StoredScan> ReadLocalScans(const std::string& path) {
  return ScansOf(io::ReadLocalMap(path, io::LocalMapParts::kWithoutCorrespondences));
}

}  // namespace jvl::global_opt
