// The pinhole camera inside artifacts: a float64[6] dataset (fx fy cx cy width height).
#pragma once

#include <string>

#include "geometry/calibration.h"
#include "geometry/camera.h"
#include "io/artifact.h"

namespace jvl::io {

void WriteCameraArray(H5Writer& writer, const std::string& name, const PinholeCamera& camera);
// Throws naming the file when the dataset is missing or does not hold 6 values.
PinholeCamera ReadCameraArray(const H5Reader& reader, const std::string& name);

// The camera choice as "camera_index" int32[1] and "camera_offset" float64[3]; nothing is written
// for camera 0 with a zero offset (an artifact of camera 0 is the same as before the choice
// existed), and a file without them reads as camera 0.
void WriteCameraChoice(H5Writer& writer, const CameraChoice& choice);
CameraChoice ReadCameraChoice(const H5Reader& reader);

}  // namespace jvl::io
