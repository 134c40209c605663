#include "io/vps_io.h"

#include <algorithm>
#include <sstream>

#include "core/check.h"
#include "core/strings.h"
#include "io/camera_io.h"
#include "io/files.h"

namespace jvl::io {

void WriteVps(H5Writer& writer, const VpsData& data) {
  const int64_t m = static_cast<int64_t>(data.vps.size());
  writer.WriteArray("frames", data.frames);
  WriteCameraArray(writer, "camera", data.camera);
  WriteCameraChoice(writer, data.camera_choice);
  std::vector<int64_t> frame;
  std::vector<int32_t> index, inliers;
  std::vector<double> uv, direction, residual, score;
  std::vector<uint8_t> forward;
  for (const VpRecord& r : data.vps) {
    frame.push_back(r.frame);
    index.push_back(r.index);
    uv.insert(uv.end(), {r.uv.x(), r.uv.y()});
    direction.insert(direction.end(), {r.direction.x(), r.direction.y(), r.direction.z()});
    inliers.push_back(r.inliers);
    residual.push_back(r.residual_deg);
    score.push_back(r.score);
    forward.push_back(r.is_forward ? 1 : 0);
  }
  writer.WriteArray("vps/frame", frame);
  writer.WriteArray("vps/index", index);
  writer.WriteArray("vps/uv", uv, {m, 2});
  writer.WriteArray("vps/direction", direction, {m, 3});
  writer.WriteArray("vps/inliers", inliers);
  writer.WriteArray("vps/residual_deg", residual);
  writer.WriteArray("vps/score", score);
  writer.WriteArray("vps/is_forward", forward);
}

void WriteVpsArtifact(const std::string& path, const VpsData& data, const Provenance& provenance) {
  H5Writer writer(path, kVpsSchema, kVpsSchemaVersion);
  WriteVps(writer, data);
  writer.Commit(provenance);
}

VpsData ReadVpsArtifact(const std::string& path) {
  H5Reader reader(path, kVpsSchema, kVpsSchemaVersion);
  VpsData data;
  data.frames = reader.ReadArray<int64_t>("frames");
  data.camera = ReadCameraArray(reader, "camera");
  data.camera_choice = ReadCameraChoice(reader);
  const auto frame = reader.ReadArray<int64_t>("vps/frame");
  const auto index = reader.ReadArray<int32_t>("vps/index");
  const auto uv = reader.ReadArray<double>("vps/uv", 2);
  const auto direction = reader.ReadArray<double>("vps/direction", 3);
  const auto inliers = reader.ReadArray<int32_t>("vps/inliers");
  const auto residual = reader.ReadArray<double>("vps/residual_deg");
  const auto score = reader.ReadArray<double>("vps/score");
  const auto forward = reader.ReadArray<uint8_t>("vps/is_forward");
  const size_t m = frame.size();
  JVL_CHECK(index.size() == m && uv.size() == 2 * m && direction.size() == 3 * m &&
                inliers.size() == m && residual.size() == m && score.size() == m &&
                forward.size() == m,
            path << ": the vps/* datasets disagree in length (vps/frame has " << m << " rows)");
  for (size_t i = 0; i < m; ++i) {
    JVL_CHECK(std::binary_search(data.frames.begin(), data.frames.end(), frame[i]),
              path << ": VP row " << i << " names frame " << frame[i] << ", not in 'frames'");
    VpRecord r;
    r.frame = frame[i];
    r.index = index[i];
    r.uv = {uv[2 * i], uv[2 * i + 1]};
    r.direction = {direction[3 * i], direction[3 * i + 1], direction[3 * i + 2]};
    r.inliers = inliers[i];
    r.residual_deg = residual[i];
    r.score = score[i];
    r.is_forward = forward[i] != 0;
    data.vps.push_back(r);
  }
  return data;
}

std::string FormatVpsCsv(const VpsData& data) {
  std::ostringstream out;
  out << "frame,vp_index,u,v,dx,dy,dz,inliers,residual_deg,score,is_forward\n";
  for (const VpRecord& r : data.vps) {
    out << r.frame << ',' << r.index << ',' << FormatDouble(r.uv.x()) << ','
        << FormatDouble(r.uv.y()) << ',' << FormatDouble(r.direction.x()) << ','
        << FormatDouble(r.direction.y()) << ',' << FormatDouble(r.direction.z()) << ',' << r.inliers
        << ',' << FormatDouble(r.residual_deg) << ',' << FormatDouble(r.score) << ','
        << (r.is_forward ? 1 : 0) << '\n';
  }
  return out.str();
}

void WriteVpsCsv(const std::string& path, const VpsData& data) {
  WriteTextFileAtomic(path, FormatVpsCsv(data));
}

}  // namespace jvl::io
