#include "io/camera_io.h"

#include <cmath>

#include "core/check.h"

namespace jvl::io {

void WriteCameraArray(H5Writer& writer, const std::string& name, const PinholeCamera& c) {
  writer.WriteArray<double>(
      name, {c.fx, c.fy, c.cx, c.cy, static_cast<double>(c.width), static_cast<double>(c.height)});
}

PinholeCamera ReadCameraArray(const H5Reader& reader, const std::string& name) {
  const auto v = reader.ReadArray<double>(name);
  JVL_CHECK(v.size() == 6, reader.path() << ": '" << name
                                         << "' must hold 6 values (fx fy cx cy "
                                            "width height), found "
                                         << v.size());
  for (int i = 4; i < 6; ++i) {
    JVL_CHECK(v[i] >= 0 && v[i] <= 1e6 && v[i] == std::floor(v[i]),
              reader.path() << ": '" << name << "' has an image size of " << v[4] << " x " << v[5]);
  }
  return {v[0], v[1], v[2], v[3], static_cast<int>(v[4]), static_cast<int>(v[5])};
}

void WriteCameraChoice(H5Writer& writer, const CameraChoice& choice) {
  if (choice.index == 0 && choice.offset.isZero(0)) return;
  writer.WriteArray<int32_t>("camera_index", {choice.index});
  writer.WriteArray<double>("camera_offset",
                            {choice.offset.x(), choice.offset.y(), choice.offset.z()});
}

CameraChoice ReadCameraChoice(const H5Reader& reader) {
  CameraChoice choice;
  if (!reader.Has("camera_index")) return choice;
  const auto index = reader.ReadArray<int32_t>("camera_index");
  JVL_CHECK(index.size() == 1 && index[0] >= 0 && index[0] < 4,
            reader.path() << ": 'camera_index' must hold one camera number 0..3");
  const auto offset = reader.ReadArray<double>("camera_offset");
  JVL_CHECK(offset.size() == 3 && std::isfinite(offset[0]) && std::isfinite(offset[1]) &&
                std::isfinite(offset[2]) &&
                std::abs(offset[0]) + std::abs(offset[1]) + std::abs(offset[2]) < 10.0,
            reader.path() << ": 'camera_offset' must hold 3 finite values (m, under 10 m)");
  choice.index = index[0];
  choice.offset = Eigen::Vector3d(offset[0], offset[1], offset[2]);
  return choice;
}

}  // namespace jvl::io
