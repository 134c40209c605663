// libFuzzer target: trajectory text (KITTI poses, KITTI with frame index, TUM). The first byte
// picks the reader: ReadTrajectoryText with auto, kitti, kitti-indexed or tum, or evaluate's
// ParsePoseMatricesKitti; the rest is the file. A malformed file must raise jvl::Error, nothing
// else; an accepted one must hold a valid trajectory.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "core/check.h"
#include "io/eval_report_io.h"
#include "io/trajectory_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  using jvl::io::TrajectoryFormat;
  const TrajectoryFormat formats[] = {TrajectoryFormat::kAuto, TrajectoryFormat::kKitti,
                                      TrajectoryFormat::kKittiIndexed, TrajectoryFormat::kTum};
  std::istringstream in(std::string(reinterpret_cast<const char*>(data) + 1, size - 1));
  try {
    if (data[0] % 5 == 4) {
      jvl::io::ParsePoseMatricesKitti(in, "poses.txt");
    } else {
      const jvl::Trajectory t = jvl::io::ReadTrajectoryText(in, formats[data[0] % 5], "poses.txt");
      t.Check("poses.txt");
    }
  } catch (const jvl::Error&) {
  }
  return 0;
}
