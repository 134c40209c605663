// KITTI raw drive folders (YYYY_MM_DD_drive_NNNN_sync): velodyne_points/data/*.bin,
// image_0X/data/*.png, oxts/data/*.txt, */timestamps.txt, and calib_*.txt one level up.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/strings.h"
#include "geometry/rigid3.h"
#include "io/dataset.h"

namespace jvl::io {

struct OxtsPacket {
  double lat = 0, lon = 0, alt = 0;     // degrees, degrees, metres
  double roll = 0, pitch = 0, yaw = 0;  // radians
};

// The first six of the 30 values of an OXTS packet line.
OxtsPacket ParseOxtsPacket(const std::string& text, const std::string& name);

// imu0_from_imu for every packet, following the KITTI raw devkit: Mercator projection with the
// scale of the first packet's latitude (earth radius 6378137 m), R = Rz(yaw) Ry(pitch) Rx(roll),
// then expressed relative to the first packet.
std::vector<Rigid3d> OxtsToImuPoses(const std::vector<OxtsPacket>& packets);

// "2011-09-26 13:02:25.964389445" -> seconds since 1970-01-01 UTC (nanoseconds kept).
double ParseKittiRawTimestamp(const std::string& text, const std::string& name);
// The same as whole seconds and the fraction, so that differences keep nanoseconds (a double
// of seconds since 1970 resolves only about 2e-7 s).
struct KittiRawTime {
  int64_t seconds = 0;
  double fraction = 0;
};
KittiRawTime ParseKittiRawTime(const std::string& text, const std::string& name);
// Timestamps of `frames` relative to the first line of a KITTI raw / KITTI-360 timestamps.txt,
// which must have a line for every frame up to last_frame.
std::vector<double> RelativeKittiRawTimes(const std::string& path, int64_t last_frame,
                                          const std::vector<int64_t>& frames);

std::unique_ptr<Dataset> OpenKittiRawDataset(const std::string& dir, const FrameRange& range);

}  // namespace jvl::io
