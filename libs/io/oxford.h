// Oxford Radar RobotCar traversals (Barnes et al., ICRA 2020; formats of the dataset's SDK,
// ori-mrg/robotcar-dataset-sdk; docs/datasets.md):
//
//   DIR/stereo.timestamps, DIR/stereo/centre/<t>.png      raw Bayer GBRG images, <t> in µs
//   DIR/velodyne_left.timestamps, DIR/velodyne_left/<t>.bin   float32 planar x.., y.., z.., i..
//   DIR/gps/ins.csv                                        INS poses (north, east, down, r, p, y)
//   extrinsics/ and models/ of the SDK, in DIR or one or two folders above it
//
// A frame is a centre-camera image, paired with the left Velodyne sweep nearest in time (at most
// kOxfordMaxPairGapS away; a frame without one has no scan). Scans are returned in a frame at the
// LiDAR with the vehicle's axes turned to x forward, y left, z up; images are demosaiced to grey
// and undistorted with the SDK's lookup table; the ground truth is the INS pose interpolated at
// the image times (SLERP, linear translation), as world_from_cam0 relative to the first frame.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/strings.h"
#include "geometry/rigid3.h"
#include "io/dataset.h"

namespace jvl::io {

inline constexpr double kOxfordMaxPairGapS = 0.04;  // half a 20 Hz sweep and some slack

// The SDK's x y z roll pitch yaw (m, rad) as a rigid transform, R = Rz(yaw) Ry(pitch) Rx(roll).
Rigid3d OxfordSe3(double x, double y, double z, double roll, double pitch, double yaw);
// Its inverse: x y z roll pitch yaw of a rigid transform (pitch within +-90 deg).
std::array<double, 6> OxfordXyzRpy(const Rigid3d& t);

// The timestamps (µs since 1970) of a <sensor>.timestamps file ("<t> <chunk>" lines).
std::vector<int64_t> ReadOxfordTimestamps(const std::string& path);

// Index of the element of sorted `times` nearest to t (ties to the earlier one); -1 if empty.
int64_t NearestTime(const std::vector<int64_t>& times, int64_t t);

// A Velodyne .bin of the SDK: float32, N x values, then N y, N z and N intensities (0-255).
// Points in the sensor frame; intensities scaled to 0-1. Throws naming the file.
PointCloud ReadOxfordVelodyneBin(const std::string& path);

std::unique_ptr<Dataset> OpenOxfordDataset(const std::string& dir, const FrameRange& range);

// Whether `dir` looks like a traversal (stereo.timestamps and velodyne_left.timestamps).
bool IsOxfordTraversal(const std::string& dir);

}  // namespace jvl::io
