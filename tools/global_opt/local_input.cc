#include "local_input.h"

#include "core/check.h"
#include "io/artifact.h"
#include "io/trajectory_io.h"

namespace jvl::global_opt {

namespace {

Eigen::Vector3d Row3(const std::vector<double>& a, size_t i) {
  return {a[3 * i], a[3 * i + 1], a[3 * i + 2]};
}

}  // namespace

LocalInput ReadLocalInput(const std::string& path) {
  const io::H5Reader r(path, "local", 1);
  LocalInput out;
  out.keyframes = io::ReadTrajectoryGroup(r, "keyframes");
  const size_t k = out.keyframes.size();
  if (r.Has("imls/n")) {
    const auto n = r.ReadArray<int32_t>("imls/n");
    const auto c = r.ReadArray<int32_t>("imls/c");
    const auto px = r.ReadArray<double>("imls/p_x", 3);
    const auto py = r.ReadArray<double>("imls/p_y", 3);
    const auto nc = r.ReadArray<double>("imls/normal", 3);
    JVL_CHECK(c.size() == n.size() && px.size() == 3 * n.size() && py.size() == px.size() &&
                  nc.size() == px.size(),
              path << ": imls/* sizes disagree");
    for (size_t i = 0; i < n.size(); ++i) {
      JVL_CHECK(n[i] >= 0 && static_cast<size_t>(n[i]) < k && c[i] >= 0 &&
                    static_cast<size_t>(c[i]) < k,
                path << ": imls row " << i << " refers to keyframe rows " << n[i] << ", " << c[i]
                     << " (" << k << " keyframes)");
      out.imls.push_back({n[i], c[i], Row3(px, i), Row3(py, i), Row3(nc, i).normalized()});
    }
  }
  if (r.Has("mappoints/position")) {
    const auto mp = r.ReadArray<double>("mappoints/position", 3);
    for (size_t i = 0; i < mp.size() / 3; ++i) out.mappoints.push_back(Row3(mp, i));
  }
  if (r.Has("scans/offset")) {
    const auto offset = r.ReadArray<int64_t>("scans/offset");
    const auto pts = r.ReadArray<float>("scans/points", 3);
    const auto nrm = r.ReadArray<float>("scans/normals", 3);
    JVL_CHECK(offset.size() == k + 1, path << ": scans/offset has " << offset.size()
                                           << " entries for " << k << " keyframes (K+1)");
    JVL_CHECK(nrm.size() == pts.size() && offset.front() == 0 &&
                  static_cast<size_t>(offset.back()) == pts.size() / 3,
              path << ": scans/points, scans/normals and scans/offset disagree");
    out.scans.resize(k);
    for (size_t i = 0; i < k; ++i) {
      JVL_CHECK(offset[i] <= offset[i + 1], path << ": scans/offset decreases at row " << i);
      for (int64_t j = offset[i]; j < offset[i + 1]; ++j) {
        const size_t b = 3 * static_cast<size_t>(j);
        out.scans[i].points.emplace_back(pts[b], pts[b + 1], pts[b + 2]);
        out.scans[i].normals.emplace_back(nrm[b], nrm[b + 1], nrm[b + 2]);
      }
    }
  }
  if (r.Has("prior/frames")) out.prior = io::ReadTrajectoryGroup(r, "prior");
  return out;
}

}  // namespace jvl::global_opt
