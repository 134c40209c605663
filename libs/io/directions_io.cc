#include "io/directions_io.h"

#include <cstdio>
#include <map>
#include <set>

#include "core/check.h"
#include "io/camera_io.h"
#include "io/files.h"

namespace jvl::io {
namespace {

template <typename T>
void CheckRows(const std::string& path, const std::string& name, const std::vector<T>& v,
               size_t rows, size_t cols) {
  JVL_CHECK(v.size() == rows * cols,
            path << ": " << name << " has " << v.size() / cols << " rows, expected " << rows);
}

}  // namespace

void WriteDirectionsArtifact(const std::string& path, const DirectionsData& data,
                             const Provenance& provenance) {
  H5Writer w(path, "directions", 1);
  const int64_t c = int64_t(data.clusters.size()), a = int64_t(data.associations.size());
  std::vector<int32_t> id, size, cluster, vp_index;
  std::vector<double> direction, std_deg, centroid, uv;
  std::vector<int64_t> span, frame;
  for (const auto& k : data.clusters) {
    id.push_back(k.id);
    direction.insert(direction.end(), k.direction.data(), k.direction.data() + 3);
    std_deg.push_back(k.std_deg);
    size.push_back(k.size);
    span.insert(span.end(), {k.first_frame, k.last_frame});
    centroid.insert(centroid.end(), k.centroid.data(), k.centroid.data() + 3);
  }
  for (const auto& s : data.associations) {
    frame.push_back(s.frame);
    vp_index.push_back(s.vp_index);
    uv.insert(uv.end(), {s.uv.x(), s.uv.y()});
    cluster.push_back(s.cluster);
  }
  w.WriteArray("clusters/id", id);
  w.WriteArray("clusters/direction", direction, {c, 3});
  w.WriteArray("clusters/std_deg", std_deg);
  w.WriteArray("clusters/size", size);
  w.WriteArray("clusters/frame_span", span, {c, 2});
  w.WriteArray("clusters/centroid", centroid, {c, 3});
  w.WriteArray("associations/frame", frame);
  w.WriteArray("associations/vp_index", vp_index);
  w.WriteArray("associations/uv", uv, {a, 2});
  w.WriteArray("associations/cluster", cluster);
  WriteCameraChoice(w, data.camera_choice);
  w.WriteJson("summary", data.summary);
  w.Commit(provenance);
}

DirectionsData ReadDirectionsArtifact(const std::string& path) {
  const H5Reader r(path, "directions", 1);
  DirectionsData data;
  data.camera_choice = ReadCameraChoice(r);
  const auto id = r.ReadArray<int32_t>("clusters/id");
  const size_t c = id.size();
  const auto dir = r.ReadArray<double>("clusters/direction", 3);
  const auto std_deg = r.ReadArray<double>("clusters/std_deg");
  const auto size = r.ReadArray<int32_t>("clusters/size");
  const auto span = r.ReadArray<int64_t>("clusters/frame_span", 2);
  const auto centroid = r.ReadArray<double>("clusters/centroid", 3);
  CheckRows(path, "clusters/direction", dir, c, 3);
  CheckRows(path, "clusters/std_deg", std_deg, c, 1);
  CheckRows(path, "clusters/size", size, c, 1);
  CheckRows(path, "clusters/frame_span", span, c, 2);
  CheckRows(path, "clusters/centroid", centroid, c, 3);
  std::set<int32_t> ids;
  for (size_t i = 0; i < c; ++i) {
    DirectionClusterRow k;
    k.id = id[i];
    k.direction = {dir[3 * i], dir[3 * i + 1], dir[3 * i + 2]};
    k.std_deg = std_deg[i];
    k.size = size[i];
    k.first_frame = span[2 * i];
    k.last_frame = span[2 * i + 1];
    k.centroid = {centroid[3 * i], centroid[3 * i + 1], centroid[3 * i + 2]};
    JVL_CHECK(ids.insert(k.id).second, path << ": cluster id " << k.id << " appears twice");
    data.clusters.push_back(k);
  }
  const auto frame = r.ReadArray<int64_t>("associations/frame");
  const size_t a = frame.size();
  const auto vp_index = r.ReadArray<int32_t>("associations/vp_index");
  const auto uv = r.ReadArray<double>("associations/uv", 2);
  const auto cluster = r.ReadArray<int32_t>("associations/cluster");
  CheckRows(path, "associations/vp_index", vp_index, a, 1);
  CheckRows(path, "associations/uv", uv, a, 2);
  CheckRows(path, "associations/cluster", cluster, a, 1);
  std::set<int64_t> frames;
  for (size_t i = 0; i < a; ++i) {
    JVL_CHECK(ids.count(cluster[i]), path << ": association of frame " << frame[i]
                                          << " names unknown cluster " << cluster[i]);
    JVL_CHECK(frames.insert(frame[i]).second,
              path << ": frame " << frame[i] << " has more than one association");
    data.associations.push_back({frame[i], vp_index[i], {uv[2 * i], uv[2 * i + 1]}, cluster[i]});
  }
  data.summary = r.ReadJson("summary");
  return data;
}

std::string FormatDirectionsCsv(const DirectionsData& data) {
  std::map<int32_t, Eigen::Vector3d> dir;
  for (const auto& k : data.clusters) dir[k.id] = k.direction;
  std::string out = "frame,cluster,u,v,dwx,dwy,dwz\n";
  char line[256];
  for (const auto& s : data.associations) {
    const Eigen::Vector3d& d = dir.at(s.cluster);
    std::snprintf(line, sizeof(line), "%lld,%d,%.3f,%.3f,%.9f,%.9f,%.9f\n",
                  static_cast<long long>(s.frame), s.cluster, s.uv.x(), s.uv.y(), d.x(), d.y(),
                  d.z());
    out += line;
  }
  return out;
}

void WriteDirectionsCsv(const std::string& path, const DirectionsData& data) {
  WriteTextFileAtomic(path, FormatDirectionsCsv(data));
}

}  // namespace jvl::io
