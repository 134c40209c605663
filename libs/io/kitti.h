// KITTI file formats: velodyne .bin scans, calib.txt, times.txt, and the writers used by the
// synthetic sequence generator to produce the same layout.
#pragma once

#include <iosfwd>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "geometry/calibration.h"
#include "geometry/point_cloud.h"

namespace jvl::io {

// Points farther than this from the sensor are not measurements (automotive LiDARs reach
// 100-300 m; KITTI's HDL-64E 120 m): they are dropped and counted.
inline constexpr double kMaxScanRange = 1000.0;

// float32 x, y, z, reflectance per point. The file size must be a multiple of 16 bytes.
// Non-finite points are dropped and counted in *dropped, points beyond kMaxScanRange in
// *out_of_range.
PointCloud ReadVelodyneBin(const std::string& path, size_t* dropped = nullptr,
                           size_t* out_of_range = nullptr);
PointCloud ParseVelodyneBin(const std::string& bytes, const std::string& name,
                            size_t* dropped = nullptr, size_t* out_of_range = nullptr);
void WriteVelodyneBin(const std::string& path, const PointCloud& cloud);

// calib.txt of the odometry benchmark: lines "P0: 12 numbers" ... "Tr: 12 numbers".
Calibration ReadKittiCalibration(const std::string& path);
Calibration ParseKittiCalibration(std::istream& in, const std::string& name);
void WriteKittiCalibration(const std::string& path, const Calibration& calib);

// times.txt: one timestamp (s) per line.
std::vector<double> ReadKittiTimes(const std::string& path);
std::vector<double> ParseKittiTimes(std::istream& in, const std::string& name);
void WriteKittiTimes(const std::string& path, const std::vector<double>& times);

// Images (PNG). ReadImage throws naming the file if it is missing or does not decode.
cv::Mat ReadImage(const std::string& path, bool grayscale);
void WriteImage(const std::string& path, const cv::Mat& image);

}  // namespace jvl::io
