// Oxford Radar RobotCar traversals (Barnes et al., ICRA 2020; formats of the dataset's SDK,
// ori-mrg/robotcar-dataset-sdk; docs/datasets.md):
//
//   DIR/stereo.timestamps, DIR/stereo/centre/<t>.png      raw Bayer GBRG images, <t> in µs
//   DIR/velodyne_left.timestamps, DIR/velodyne_left/<t>.bin   float32 planar x.., y.., z.., i..
//                                DIR/velodyne_left/<t>.png   raw sweep (when there is no .bin)
//   DIR/velodyne_right.timestamps, DIR/velodyne_right/<t>.bin|png   the right Velodyne (--lidar)
//   DIR/gps/ins.csv                                        INS poses (north, east, down, r, p, y)
//   DIR/gt/radar_odometry.csv                              relative radar poses (--gt-source)
//   extrinsics/ and models/ of the SDK, in DIR or one or two folders above it
//
// A frame is a centre-camera image, paired with the sweep of the chosen Velodyne (left by
// default) nearest in time (at most kOxfordMaxPairGapS away; a frame without one has no scan).
// Scans are returned in a frame at that LiDAR with the vehicle's axes turned to x forward, y
// left, z up ("both": the right sweep nearest the left one is merged into the left one's frame);
// images are demosaiced to grey and undistorted with the SDK's lookup table; the ground truth is
// the INS pose (or the composed radar odometry) interpolated at the image times (SLERP, linear
// translation), as world_from_cam0 relative to the first frame. scan_time_offsets() holds each
// frame's sweep time minus its image time.
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

// The HDL-32E constants of the SDK's python/velodyne.py: the 32 laser elevations (rad, the
// rows of a raw sweep), the range unit (m), the shortest valid range (m) and the height of the
// firing centre above the sensor's base (subtracted from z).
inline constexpr std::array<double, 32> kHdl32eElevations = {
    -0.1862, -0.1628, -0.1396, -0.1164, -0.0930, -0.0698, -0.0466, -0.0232, 0.,     0.0232, 0.0466,
    0.0698,  0.0930,  0.1164,  0.1396,  0.1628,  0.1862,  0.2094,  0.2327,  0.2560, 0.2793, 0.3025,
    0.3259,  0.3491,  0.3723,  0.3957,  0.4189,  0.4421,  0.4655,  0.4887,  0.5119, 0.5353};
inline constexpr double kHdl32eRangeResolution = 0.002;
inline constexpr double kHdl32eMinimumRange = 1.0;
inline constexpr double kHdl32eBaseToFireHeight = 0.090805;
inline constexpr int kOxfordRawSweepRows = 32 + 64 + 2 + 8;

// A raw Velodyne sweep of the SDK (<t>.png, 8-bit grey, 106 rows, one column per firing): rows
// 0-31 the intensities of the 32 lasers, rows 32-95 their ranges (uint16, little-endian byte
// pairs down the column, in kHdl32eRangeResolution), rows 96-97 the azimuth (uint16, 1/100
// degree), rows 98-105 the column's time (int64 µs). Returns the points of the returns longer
// than kHdl32eMinimumRange in the sensor frame (x = sin(azimuth) r cos(elevation), y = -cos(
// azimuth) r cos(elevation), z = r sin(elevation) - kHdl32eBaseToFireHeight), laser by laser
// then column by column as the SDK orders them, intensities scaled to 0-1; `times` (if given)
// receives each point's column time. Throws naming the file.
PointCloud ReadOxfordVelodynePng(const std::string& path, std::vector<int64_t>* times = nullptr);

// Which Velodyne an Oxford traversal's scans come from (DatasetOptions::lidar).
enum class OxfordLidar { kLeft, kRight, kBoth };
OxfordLidar ParseOxfordLidar(const std::string& name);  // default|left, right, both

std::unique_ptr<Dataset> OpenOxfordDataset(const std::string& dir, const FrameRange& range);
std::unique_ptr<Dataset> OpenOxfordDataset(const std::string& dir, const DatasetOptions& options,
                                           const FrameRange& range);

// Whether `dir` looks like a traversal (stereo.timestamps and velodyne_left.timestamps).
bool IsOxfordTraversal(const std::string& dir);

}  // namespace jvl::io
