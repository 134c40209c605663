#include "io/camera_io.h"

#include <cmath>

#include "core/check.h"

namespace jvl::io {

void WriteCameraArray(H5Writer& writer, const std::string& name, const PinholeCamera& c) {
  writer.WriteArray<double>(name, {c.fx, c.fy, c.cx, c.cy, static_cast<double>(c.width),
                                   static_cast<double>(c.height)});
}

PinholeCamera ReadCameraArray(const H5Reader& reader, const std::string& name) {
  const auto v = reader.ReadArray<double>(name);
  JVL_CHECK(v.size() == 6, reader.path() << ": '" << name << "' must hold 6 values (fx fy cx cy "
                                            "width height), found " << v.size());
  for (int i = 4; i < 6; ++i) {
    JVL_CHECK(v[i] >= 0 && v[i] <= 1e6 && v[i] == std::floor(v[i]),
              reader.path() << ": '" << name << "' has an image size of " << v[4] << " x " << v[5]);
  }
  return {v[0], v[1], v[2], v[3], static_cast<int>(v[4]), static_cast<int>(v[5])};
}

}  // namespace jvl::io
