// libFuzzer target: KITTI calib.txt parser. A malformed file must raise jvl::Error, nothing else.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "core/check.h"
#include "io/kitti.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    jvl::io::ParseKittiCalibration(in, "calib.txt");
  } catch (const jvl::Error&) {
  }
  return 0;
}
