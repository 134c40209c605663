#include "io/local_io.h"

#include <utility>
#include <vector>

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

// scans/offset of K keyframes: K + 1 values, non-decreasing, from 0 to `points` rows.
void CheckScanOffsets(const std::vector<int64_t>& offset, size_t k, int64_t points,
                      const std::string& what) {
  CheckSize(offset, k + 1, "scans/offset", what);
  for (size_t i = 0; i < k; ++i) {
    JVL_CHECK(offset[i] <= offset[i + 1],
              what << ": scans/offset decreases at keyframe row " << i);
  }
  JVL_CHECK(offset.front() == 0 && offset.back() == points,
            what << ": scans/offset must run from 0 to " << points);
}

}  // namespace

void LocalMapData::Check(const std::string& what, LocalMapParts parts) const {
  keyframes.Check((what + " keyframes").c_str());
  const size_t k = keyframes.size(), l = num_correspondences(), s = num_scan_points();
  CheckSize(imls_c, l, "imls/c", what);
  CheckSize(imls_p_x, 3 * l, "imls/p_x", what);
  CheckSize(imls_p_y, 3 * l, "imls/p_y", what);
  CheckSize(imls_normal, 3 * l, "imls/normal", what);
  JVL_CHECK(mappoint_position.size() % 3 == 0, what << ": mappoints/position is not M x 3");
  if (parts == LocalMapParts::kWithoutScans) {
    JVL_CHECK(scan_points.empty() && scan_normals.empty(),
              what << ": scans/points and scans/normals were not to be read");
    // Their row count is not known here; ReadLocalScans checks the offsets against it.
    CheckScanOffsets(scan_offset, k, scan_offset.empty() ? 0 : scan_offset.back(), what);
  } else {
    CheckSize(scan_normals, 3 * s, "scans/normals", what);
    JVL_CHECK(scan_points.size() == 3 * s, what << ": scans/points is not S x 3");
    CheckScanOffsets(scan_offset, k, static_cast<int64_t>(s), what);
  }
  for (size_t i = 0; i < l; ++i) {
    JVL_CHECK(imls_n[i] >= 0 && imls_c[i] >= 0 && static_cast<size_t>(imls_n[i]) < k &&
                  static_cast<size_t>(imls_c[i]) < k,
              what << ": imls correspondence " << i << " refers to keyframe rows " << imls_n[i]
                   << ", " << imls_c[i] << " (have " << k << ")");
  }
  CheckSize(stats_visual_residuals, stats_frame.size(), "stats/visual_residuals", what);
  CheckSize(stats_imls_residuals, stats_frame.size(), "stats/imls_residuals", what);
  CheckSize(stats_cost_before, stats_frame.size(), "stats/cost_before", what);
  CheckSize(stats_cost_after, stats_frame.size(), "stats/cost_after", what);
  CheckSize(stats_time_ms, stats_frame.size(), "stats/time_ms", what);
  CheckSize(stats_frame, k, "stats/frame", what);
}

void WriteLocalMap(const std::string& path, const LocalMapData& d, const Provenance& provenance) {
  d.Check(path);
  const int64_t l = static_cast<int64_t>(d.num_correspondences());
  const int64_t s = static_cast<int64_t>(d.num_scan_points());
  H5Writer w(path, kLocalSchema, kLocalSchemaVersion);
  WriteCameraArray(w, "camera", d.camera);
  WriteCameraChoice(w, d.camera_choice);
  WriteTrajectoryGroup(w, "keyframes", d.keyframes);
  w.WriteArray("imls/n", d.imls_n);
  w.WriteArray("imls/c", d.imls_c);
  w.WriteArray("imls/p_x", d.imls_p_x, {l, 3});
  w.WriteArray("imls/p_y", d.imls_p_y, {l, 3});
  w.WriteArray("imls/normal", d.imls_normal, {l, 3});
  w.WriteArray("mappoints/position", d.mappoint_position,
               {static_cast<int64_t>(d.num_mappoints()), 3});
  w.WriteArray("scans/offset", d.scan_offset);
  w.WriteArray("scans/points", d.scan_points, {s, 3});
  w.WriteArray("scans/normals", d.scan_normals, {s, 3});
  w.WriteArray("stats/frame", d.stats_frame);
  w.WriteArray("stats/visual_residuals", d.stats_visual_residuals);
  w.WriteArray("stats/imls_residuals", d.stats_imls_residuals);
  w.WriteArray("stats/cost_before", d.stats_cost_before);
  w.WriteArray("stats/cost_after", d.stats_cost_after);
  w.WriteArray("stats/time_ms", d.stats_time_ms);
  WriteTrajectoryGroup(w, "prior", d.prior);
  w.WriteJson("summary", d.summary);
  w.Commit(provenance);
}

LocalMapData ReadLocalMap(const std::string& path, LocalMapParts parts) {
  H5Reader r(path, kLocalSchema, kLocalSchemaVersion);
  LocalMapData d;
  d.camera = ReadCameraArray(r, "camera");
  d.camera_choice = ReadCameraChoice(r);
  d.keyframes = ReadTrajectoryGroup(r, "keyframes");
  if (parts != LocalMapParts::kWithoutCorrespondences) {
    d.imls_n = r.ReadArray<int32_t>("imls/n");
    d.imls_c = r.ReadArray<int32_t>("imls/c");
    d.imls_p_x = r.ReadArray<double>("imls/p_x", 3);
    d.imls_p_y = r.ReadArray<double>("imls/p_y", 3);
    d.imls_normal = r.ReadArray<double>("imls/normal", 3);
    d.mappoint_position = r.ReadArray<double>("mappoints/position", 3);
  }
  d.scan_offset = r.ReadArray<int64_t>("scans/offset");
  if (parts != LocalMapParts::kWithoutScans) {
    d.scan_points = r.ReadArray<float>("scans/points", 3);
    d.scan_normals = r.ReadArray<float>("scans/normals", 3);
  }
  d.stats_frame = r.ReadArray<int64_t>("stats/frame");
  d.stats_visual_residuals = r.ReadArray<int32_t>("stats/visual_residuals");
  d.stats_imls_residuals = r.ReadArray<int32_t>("stats/imls_residuals");
  d.stats_cost_before = r.ReadArray<double>("stats/cost_before");
  d.stats_cost_after = r.ReadArray<double>("stats/cost_after");
  d.stats_time_ms = r.ReadArray<double>("stats/time_ms");
  d.prior = ReadTrajectoryGroup(r, "prior");
  d.summary = r.ReadJson("summary");
  d.Check(path, parts);
  return d;
}

void ReadLocalScans(const std::string& path, const LocalScanSink& sink, int64_t rows_per_block) {
  JVL_CHECK(rows_per_block > 0, "rows_per_block must be positive (got " << rows_per_block << ")");
  H5Reader r(path, kLocalSchema, kLocalSchemaVersion);
  const std::vector<int64_t> offset = r.ReadArray<int64_t>("scans/offset");
  const std::vector<int64_t> points = r.Dims("scans/points"), normals = r.Dims("scans/normals");
  JVL_CHECK(points.size() == 2 && points[1] == 3, path << ": scans/points is not S x 3");
  JVL_CHECK(normals == points, path << ": scans/normals and scans/points differ in shape");
  JVL_CHECK(!offset.empty(), path << ": scans/offset is empty");
  const size_t k = offset.size() - 1;
  CheckScanOffsets(offset, k, points[0], path);
  for (size_t first = 0; first < k;) {
    size_t last = first + 1;
    while (last < k && offset[last + 1] - offset[first] <= rows_per_block) ++last;
    const std::vector<std::pair<int64_t, int64_t>> rows = {{offset[first], offset[last]}};
    const std::vector<float> p = r.ReadRows<float>("scans/points", rows, 3);
    const std::vector<float> n = r.ReadRows<float>("scans/normals", rows, 3);
    for (size_t i = first; i < last; ++i) {
      const size_t at = 3 * static_cast<size_t>(offset[i] - offset[first]);
      sink(i, p.data() + at, n.data() + at, static_cast<size_t>(offset[i + 1] - offset[i]));
    }
    first = last;
  }
}

}  // namespace jvl::io
