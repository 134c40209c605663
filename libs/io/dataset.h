// Datasets named by folder: KITTI odometry sequence folders (also written by sim_sequence),
// KITTI raw drive folders, KITTI-360 drives (io/kitti360.h) and Oxford Radar RobotCar
// traversals (io/oxford.h). Frames are loaded lazily, one at a
// time.
#pragma once

#include <map>
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

enum class DatasetFormat { kAuto, kKittiOdometry, kKittiRaw, kKitti360, kOxford };
DatasetFormat ParseDatasetFormat(const std::string& name);  // auto|kitti|kitti-raw|kitti360|oxford
const char* DatasetFormatName(DatasetFormat format);        // the name ParseDatasetFormat takes
// Help text of the tools' --format option.
inline constexpr const char* kCameraHelp =
    "Camera whose images are used: 0 (left grey, the default), 1, 2 (left colour) or 3; colour "
    "is converted to grey. Poses stay world_from_cam0: the camera's offset from camera 0 comes "
    "from the calibration (P_rect) and is recorded in the artifact";
inline constexpr const char* kDatasetFormatHelp =
    "Dataset layout: auto (detected from the folder), kitti, kitti-raw, kitti360 or oxford";

// What the tools pass to the readers (--format, --lidar, --gt-source, --calib; app::Tool::
// AddDatasetOptions adds the four). "default" leaves the choice to the layout; an option other
// than "default" on a layout that does not offer it is a one-line error naming the layout.
struct DatasetOptions {
  std::string format = "auto";           // ParseDatasetFormat
  std::string lidar = "default";         // oxford: left (the default), right or both
  std::string ground_truth = "default";  // oxford: ins (the default when present) or radar
  // A calib.txt (KITTI odometry format) whose P0-P3 and Tr replace the dataset's calibration
  // (Dataset::ReplaceCalibration); empty: the dataset's own.
  std::string calibration;
};
inline constexpr const char* kDatasetCalibrationHelp =
    "calib.txt (KITTI odometry format: P0-P3, Tr) to use instead of the dataset's calibration, "
    "e.g. the one calib_check --write-calib writes; any layout; the image size stays the "
    "dataset's, and so does its id (empty: the dataset's own calibration)";
inline constexpr const char* kDatasetLidarHelp =
    "LiDAR of an Oxford RobotCar traversal: left (the default), right, or both (the right sweep "
    "merged into the left one's frame); other layouts have one LiDAR and take only 'default'";
inline constexpr const char* kDatasetGroundTruthHelp =
    "Ground truth of an Oxford RobotCar traversal: ins (gps/ins.csv, the default when present) or "
    "radar (gt/radar_odometry.csv, the default otherwise); other layouts take only 'default'";

class Dataset {
 public:
  virtual ~Dataset() = default;

  DatasetFormat format() const { return format_; }
  const std::string& root() const { return root_; }
  // Stable identity of the sequence ("kitti:04", "kitti-raw:2011_09_26_drive_0001_sync:<hash>",
  // "kitti360:2013_05_28_drive_0000_sync:<hash>").
  const std::string& id() const { return id_; }
  // Selected frame ids (dataset numbering), increasing.
  const std::vector<int64_t>& frames() const { return frames_; }
  // Timestamps (s) of the selected frames.
  const std::vector<double>& timestamps() const { return timestamps_; }
  const Calibration& calibration() const { return calibration_; }
  // world_from_cam0 of the selected frames when the dataset has ground truth.
  const std::optional<Trajectory>& ground_truth() const { return ground_truth_; }
  // Whether the scans are motion-compensated (every point in the sensor pose at the frame time).
  // KITTI odometry: yes (its readme: the ego-motion during the sweep has been compensated);
  // KITTI raw: no; a sim_sequence folder: as its sim/scene.json says (lidar.motion_distortion).
  bool scans_motion_compensated() const { return scans_motion_compensated_; }
  // Time (s) of each selected frame's scan minus its timestamp (Oxford: the sweep's time minus
  // the image's, up to half a sweep period). Empty when every scan is taken at its frame's time
  // (the KITTI layouts, whose scans and images are triggered together).
  const std::vector<double>& scan_time_offsets() const { return scan_time_offsets_; }
  // The published elevation error of the LiDAR that recorded the scans (deg): every return lies
  // this much below its beam. KITTI odometry and KITTI raw (the same Velodyne HDL-64E): 0.205,
  // the correction KISS-ICP's KITTI reader applies (IMLS-SLAM uses 0.22); on the KITTI 04
  // excerpt it takes lidar_odom's pitch drift out (docs/lidar_odom.md). 0 where none is
  // published: KITTI-360, Oxford, and every drive written by sim_sequence (sim/scene.json
  // present), whose error is the simulator's own (docs/sim.md).
  double lidar_elevation_error_deg() const { return lidar_elevation_error_deg_; }
  // Where lidar_elevation_error_deg() comes from, for the log.
  const char* lidar_elevation_error_source() const { return lidar_elevation_error_source_; }
  // scan_time_offsets()[index] in units of the frame period around frame `index` (the centred
  // difference of the timestamps, one-sided at the ends): the shift of the scan's time fractions
  // that de-skewing with a per-frame motion needs. 0 without offsets or with one frame.
  double ScanTimeOffsetInFrames(size_t index) const;

  // LiDAR scan of `frame` in the velodyne frame. Non-finite points are dropped and counted in
  // *dropped (a warning is logged). Throws naming the file on a missing or malformed scan.
  virtual PointCloud LoadScan(int64_t frame, size_t* dropped = nullptr) const = 0;
  // Grey image of camera `camera` (colour cameras converted, 0.299 R + 0.587 G + 0.114 B).
  // Throws naming the file.
  virtual cv::Mat LoadImage(int64_t frame, int camera = 0) const = 0;
  // Throws a one-line error unless the image stages can use camera `camera` of this dataset
  // (its projection is known and the layout stores its images rectified).
  void CheckCamera(int camera) const;
  virtual std::string ScanPath(int64_t frame) const = 0;
  virtual std::string ImagePath(int64_t frame, int camera = 0) const = 0;
  // Key files that identify the content (calibration, times) for provenance.
  virtual std::vector<std::string> KeyFiles() const = 0;
  // Replaces the calibration by the projections P0-P3 and Tr of the calib.txt at `path` (KITTI
  // odometry format, all of P0-P3 and Tr; DatasetOptions::calibration). Only the projections of
  // the cameras the dataset has are taken; the image size is kept. The dataset's id does not
  // change (it names the recording); the file is an input of the tools (calibration_file()).
  // Logs how far the new Tr lies from the dataset's. Throws a one-line error naming the file.
  void ReplaceCalibration(const std::string& path);
  // The file ReplaceCalibration read, or empty.
  const std::string& calibration_file() const { return calibration_file_; }
  // Every file the selected frames may be read from (key files, ground truth, the scans and the
  // images of cameras 0-3), whether present or not: what a tool must never overwrite.
  std::vector<std::string> InputFiles() const;

 protected:
  // Sets lidar_elevation_error_deg() and its source: none on a drive written by sim_sequence
  // (`scene_path`, its sim/scene.json, exists), KITTI's published error when the recording's
  // LiDAR is KITTI's HDL-64E (`kitti_hdl64e`), none otherwise.
  void SetLidarElevationError(const std::string& scene_path, bool kitti_hdl64e);
  DatasetFormat format_ = DatasetFormat::kAuto;
  std::string root_, id_;
  std::vector<int64_t> frames_;
  std::vector<double> timestamps_;
  Calibration calibration_;
  std::optional<Trajectory> ground_truth_;
  bool scans_motion_compensated_ = true;
  double lidar_elevation_error_deg_ = 0.0;
  const char* lidar_elevation_error_source_ = "none published for this layout";
  std::vector<double> scan_time_offsets_;
  std::vector<std::string> ground_truth_files_;  // the files ground_truth_ was read from
  std::string image_size_source_;                // where calibration_'s image size comes from
  std::string calibration_file_;                 // ReplaceCalibration's file, or empty
};

// --deskew of the tools that read scans: "on", "off" or "auto" (on exactly when the dataset's
// scans are not motion-compensated). Logs the decision; throws on another value.
bool ResolveDeskew(const std::string& mode, const Dataset& dataset);

// The KITTI HDL-64E's published elevation error (deg); Dataset::lidar_elevation_error_deg().
inline constexpr double kKittiLidarElevationErrorDeg = 0.205;
// --vertical-correction of the tools that read scans: "auto" (the dataset's published error,
// Dataset::lidar_elevation_error_deg(); the decision is logged) or an angle in degrees. Throws
// a one-line error on another value.
double ResolveVerticalCorrection(const std::string& value, const Dataset& dataset);
// Help text of the tools' --vertical-correction option.
inline constexpr const char* kVerticalCorrectionHelp =
    "Elevation correction of every LiDAR return (deg): auto (the error published for the "
    "dataset's LiDAR: 0.205 on KITTI odometry and raw scans, 0 elsewhere, simulated drives "
    "included), or an angle (0 = off)";

// Opens `dir` (format detected unless given) and selects the frames in `range`.
std::unique_ptr<Dataset> OpenDataset(const std::string& dir,
                                     DatasetFormat format = DatasetFormat::kAuto,
                                     const FrameRange& range = {});
// The same with the reader options of the tools (format, LiDAR, ground-truth source).
std::unique_ptr<Dataset> OpenDataset(const std::string& dir, const DatasetOptions& options,
                                     const FrameRange& range = {});
DatasetFormat DetectDatasetFormat(const std::string& dir);

// The rules every dataset reader applies (KITTI odometry, KITTI raw, KITTI-360):
// - the frames of a sequence are every number from the first to the last file found among its
//   scans and images; a frame whose file is missing is an error when a tool reads it;
// - --frames must select at least one frame and may not end past the last one;
// - a scan's non-finite points and points beyond kMaxScanRange are dropped with a warning, and
//   an empty scan is warned about.
// The files "<number><ext>" in `dir` by their number (none if `dir` is missing), and the numbers.
std::map<int64_t, std::string> ListNumberedFiles(const std::string& dir, const std::string& ext);
std::vector<int64_t> FrameIds(const std::map<int64_t, std::string>& files);
std::vector<int64_t> DatasetFrames(const std::vector<int64_t>& scan_ids,
                                   const std::vector<int64_t>& image_ids, const std::string& dir);
void SelectFrames(const std::vector<int64_t>& all, const FrameRange& range, const std::string& dir,
                  std::vector<int64_t>* selected);
// - every image has the size of the sequence (calibration.image_width/height, taken from
//   `size_source`), and at least kMinImageSide pixels a side.
PointCloud LoadScanChecked(const std::string& path, int64_t frame, size_t* dropped);
// Whether sim_sequence's scene.json at `scene_path` says the LiDAR moved during its sweeps
// (lidar.motion_distortion); false, with a warning, if the file lacks the field.
bool SimulatedWithMotionDistortion(const std::string& scene_path);
inline constexpr int kMinImageSide = 64;  // ORB's 31-pixel patches on a pyramid need room
cv::Mat LoadImageChecked(const std::string& path, int64_t frame, int camera,
                         const Calibration& calibration, const std::string& size_source);

}  // namespace jvl::io
