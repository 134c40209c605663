#include "geometry/calibration.h"

#include "core/check.h"

namespace jvl {

PinholeCamera Calibration::Camera(int i) const {
  JVL_CHECK(i >= 0 && i < 4, "camera index " << i << " out of range 0..3");
  const auto& p = P[i];
  PinholeCamera cam{p(0, 0), p(1, 1), p(0, 2), p(1, 2), image_width, image_height};
  return cam;
}

}  // namespace jvl
