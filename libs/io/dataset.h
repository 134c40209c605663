// Datasets named by folder: KITTI odometry sequence folders (also written by sim_sequence) and
// KITTI raw drive folders. Frames are loaded lazily, one at a time.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/strings.h"
#include "geometry/calibration.h"
#include "geometry/point_cloud.h"
#include "geometry/trajectory.h"

namespace jvl::io {

enum class DatasetFormat { kAuto, kKittiOdometry, kKittiRaw };
DatasetFormat ParseDatasetFormat(const std::string& name);  // auto|kitti|kitti-raw

class Dataset {
 public:
  virtual ~Dataset() = default;

  DatasetFormat format() const { return format_; }
  const std::string& root() const { return root_; }
  // Stable identity of the sequence ("kitti:04", "kitti-raw:2011_09_26_drive_0001_sync").
  const std::string& id() const { return id_; }
  // Selected frame ids (dataset numbering), increasing.
  const std::vector<int64_t>& frames() const { return frames_; }
  // Timestamps (s) of the selected frames.
  const std::vector<double>& timestamps() const { return timestamps_; }
  const Calibration& calibration() const { return calibration_; }
  // world_from_cam0 of the selected frames when the dataset has ground truth.
  const std::optional<Trajectory>& ground_truth() const { return ground_truth_; }

  // LiDAR scan of `frame` in the velodyne frame. Non-finite points are dropped and counted in
  // *dropped (a warning is logged). Throws naming the file on a missing or malformed scan.
  virtual PointCloud LoadScan(int64_t frame, size_t* dropped = nullptr) const = 0;
  // Image of camera `camera` (0/1 greyscale, 2/3 colour as stored). Throws naming the file.
  virtual cv::Mat LoadImage(int64_t frame, int camera = 0) const = 0;
  virtual std::string ScanPath(int64_t frame) const = 0;
  virtual std::string ImagePath(int64_t frame, int camera = 0) const = 0;
  // Key files that identify the content (calibration, times) for provenance.
  virtual std::vector<std::string> KeyFiles() const = 0;

 protected:
  DatasetFormat format_ = DatasetFormat::kAuto;
  std::string root_, id_;
  std::vector<int64_t> frames_;
  std::vector<double> timestamps_;
  Calibration calibration_;
  std::optional<Trajectory> ground_truth_;
};

// Opens `dir` (format detected unless given) and selects the frames in `range`.
std::unique_ptr<Dataset> OpenDataset(const std::string& dir,
                                     DatasetFormat format = DatasetFormat::kAuto,
                                     const FrameRange& range = {});
DatasetFormat DetectDatasetFormat(const std::string& dir);

}  // namespace jvl::io
