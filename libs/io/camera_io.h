// The pinhole camera inside artifacts: a float64[6] dataset (fx fy cx cy width height).
#pragma once

#include <string>

#include "geometry/camera.h"
#include "io/artifact.h"

namespace jvl::io {

void WriteCameraArray(H5Writer& writer, const std::string& name, const PinholeCamera& camera);
// Throws naming the file when the dataset is missing or does not hold 6 values.
PinholeCamera ReadCameraArray(const H5Reader& reader, const std::string& name);

}  // namespace jvl::io
