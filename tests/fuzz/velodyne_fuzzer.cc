// libFuzzer target: velodyne .bin scans. Sizes that are not a multiple of 16 must raise
// jvl::Error; otherwise every finite point within kMaxScanRange is kept and the others are
// counted (non-finite and out of range apart).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/check.h"
#include "io/kitti.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    size_t dropped = 0, far = 0;
    const jvl::PointCloud cloud = jvl::io::ParseVelodyneBin(bytes, "scan.bin", &dropped, &far);
    if (cloud.size() + dropped + far != size / 16 || cloud.intensity.size() != cloud.size())
      std::abort();
    for (const auto& p : cloud.points)
      if (!p.allFinite() || p.norm() > jvl::io::kMaxScanRange * (1 + 1e-12)) std::abort();
  } catch (const jvl::Error&) {
    if (size % 16 == 0) std::abort();
  }
  return 0;
}
