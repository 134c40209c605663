#include "io/dataset.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/check.h"
#include "core/hash.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/kitti360.h"
#include "io/kitti_raw.h"
#include "io/oxford.h"
#include "io/trajectory_io.h"

namespace fs = std::filesystem;

namespace jvl::io {

const char* DatasetFormatName(DatasetFormat format) {
  switch (format) {
    case DatasetFormat::kKittiOdometry:
      return "kitti";
    case DatasetFormat::kKittiRaw:
      return "kitti-raw";
    case DatasetFormat::kKitti360:
      return "kitti360";
    case DatasetFormat::kOxford:
      return "oxford";
    case DatasetFormat::kAuto:
      break;
  }
  return "auto";
}

DatasetFormat ParseDatasetFormat(const std::string& name) {
  if (name == "auto") return DatasetFormat::kAuto;
  if (name == "kitti") return DatasetFormat::kKittiOdometry;
  if (name == "kitti-raw") return DatasetFormat::kKittiRaw;
  if (name == "kitti360") return DatasetFormat::kKitti360;
  if (name == "oxford") return DatasetFormat::kOxford;
  JVL_THROW("--format: unknown dataset format '" << name
                                                 << "' (auto, kitti, kitti-raw, kitti360, oxford)");
}

bool ResolveDeskew(const std::string& mode, const Dataset& dataset) {
  if (mode == "on") return true;
  if (mode == "off") return false;
  JVL_CHECK(mode == "auto", "--deskew: expected auto, on or off, got '" << mode << "'");
  const bool deskew = !dataset.scans_motion_compensated();
  spdlog::info("{}: scans {}motion-compensated: de-skewing {}", dataset.root(),
               deskew ? "not " : "", deskew ? "on" : "off");
  return deskew;
}

void Dataset::SetLidarElevationError(const std::string& scene_path, bool kitti_hdl64e) {
  if (!scene_path.empty() && FileExists(scene_path)) {
    lidar_elevation_error_deg_ = 0;
    lidar_elevation_error_source_ = "a simulated drive: its error is the simulator's own";
  } else if (kitti_hdl64e) {
    lidar_elevation_error_deg_ = kKittiLidarElevationErrorDeg;
    lidar_elevation_error_source_ = "KITTI's HDL-64E, published";
  }
}

double ResolveVerticalCorrection(const std::string& value, const Dataset& dataset) {
  if (value != "auto") {
    const auto deg = ParseDouble(value);
    JVL_CHECK(deg && std::isfinite(*deg),
              "--vertical-correction: expected auto or an angle in degrees, got '" << value << "'");
    return *deg;
  }
  const double deg = dataset.lidar_elevation_error_deg();
  spdlog::info("{}: LiDAR elevation correction {} deg ({})", dataset.root(), deg,
               dataset.lidar_elevation_error_source());
  return deg;
}

DatasetFormat DetectDatasetFormat(const std::string& dir) {
  JVL_CHECK(IsDirectory(dir), dir << ": dataset folder not found");
  const fs::path p(dir);
  // Before KITTI raw: a KITTI-360 data_3d_raw drive folder also holds velodyne_points/data.
  if (LocateKitti360(dir)) return DatasetFormat::kKitti360;
  if (IsOxfordTraversal(dir)) return DatasetFormat::kOxford;
  if (FileExists((p / "calib.txt").string()) &&
      (IsDirectory((p / "velodyne").string()) || IsDirectory((p / "image_0").string()))) {
    return DatasetFormat::kKittiOdometry;
  }
  if (IsDirectory((p / "velodyne_points" / "data").string()) ||
      IsDirectory((p / "oxts" / "data").string())) {
    return DatasetFormat::kKittiRaw;
  }
  JVL_THROW(
      dir
      << ": unknown dataset layout (expected a KITTI odometry sequence folder with "
         "calib.txt and velodyne/ or image_0/, a KITTI raw *_sync folder, or a KITTI-360 "
         "drive folder ROOT/data_3d_raw/DRIVE with ROOT/calibration/perspective.txt, or an Oxford "
         "RobotCar traversal with stereo.timestamps and velodyne_left.timestamps)");
}

std::map<int64_t, std::string> ListNumberedFiles(const std::string& dir, const std::string& ext) {
  std::map<int64_t, std::string> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() != ext) continue;
    const auto id = ParseInt(entry.path().stem().string());
    if (id && *id >= 0) files[*id] = entry.path().string();
  }
  return files;
}

std::vector<int64_t> FrameIds(const std::map<int64_t, std::string>& files) {
  std::vector<int64_t> keys;
  for (const auto& [id, path] : files) keys.push_back(id);
  return keys;
}

namespace {

std::string HashFiles(const std::vector<std::string>& paths) {
  Fnv1a64 hash;
  for (const auto& p : paths) {
    if (!FileExists(p)) continue;
    const std::string text = ReadTextFile(p);
    hash.Update(text.data(), text.size());
  }
  return hash.Hex().substr(0, 8);
}

}  // namespace

std::vector<int64_t> DatasetFrames(const std::vector<int64_t>& scan_ids,
                                   const std::vector<int64_t>& image_ids, const std::string& dir) {
  JVL_CHECK(!scan_ids.empty() || !image_ids.empty(),
            dir << ": no frames found (no scans or images)");
  int64_t first = std::numeric_limits<int64_t>::max(), last = -1;
  for (const auto* ids : {&scan_ids, &image_ids}) {
    if (ids->empty()) continue;
    first = std::min(first, ids->front());
    last = std::max(last, ids->back());
  }
  std::vector<int64_t> all;
  for (int64_t f = first; f <= last; ++f) all.push_back(f);
  return all;
}

void SelectFrames(const std::vector<int64_t>& all, const FrameRange& range, const std::string& dir,
                  std::vector<int64_t>* selected) {
  JVL_CHECK(!all.empty(), dir << ": no frames found (no scans or images)");
  for (int64_t f : all)
    if (range.Contains(f)) selected->push_back(f);
  const std::string text =
      std::to_string(range.first) + ":" +
      (range.last_exclusive < 0 ? std::string() : std::to_string(range.last_exclusive));
  JVL_CHECK(!selected->empty(), "--frames " << text << " selects no frame of " << dir << " (frames "
                                            << all.front() << ".." << all.back() << ")");
  JVL_CHECK(range.last_exclusive <= all.back() + 1,
            "--frames " << text << " goes past the last frame of " << dir << " (frames "
                        << all.front() << ".." << all.back() << "; use " << range.first
                        << ": for the rest)");
}

PointCloud LoadScanChecked(const std::string& path, int64_t frame, size_t* dropped) {
  JVL_CHECK(FileExists(path), path << ": missing scan for frame " << frame);
  size_t bad = 0, far = 0;
  PointCloud cloud = ReadVelodyneBin(path, &bad, &far);
  if (bad > 0) spdlog::warn("{}: dropped {} non-finite points (frame {})", path, bad, frame);
  if (far > 0) {
    spdlog::warn("{}: dropped {} points farther than {:.0f} m (frame {})", path, far, kMaxScanRange,
                 frame);
  }
  if (cloud.empty()) spdlog::warn("{}: empty scan (frame {})", path, frame);
  if (dropped) *dropped = bad;
  return cloud;
}

cv::Mat LoadImageChecked(const std::string& path, int64_t frame, int camera,
                         const Calibration& calibration, const std::string& size_source) {
  JVL_CHECK(FileExists(path),
            path << ": missing image of camera " << camera << " for frame " << frame);
  cv::Mat image = ReadImage(path, /*grayscale=*/true);
  JVL_CHECK(image.cols >= kMinImageSide && image.rows >= kMinImageSide,
            path << ": image is " << image.cols << "x" << image.rows << ", too small (at least "
                 << kMinImageSide << "x" << kMinImageSide << ")");
  JVL_CHECK(calibration.image_width <= 0 ||
                (image.cols == calibration.image_width && image.rows == calibration.image_height),
            path << ": image is " << image.cols << "x" << image.rows << " but the sequence's are "
                 << calibration.image_width << "x" << calibration.image_height << " (from "
                 << size_source << ")");
  return image;
}

// sim_sequence writes its options to sim/scene.json; its scans are raw when it moved the LiDAR
// during the sweep. A folder without the file (real KITTI odometry) is compensated.
bool SimulatedWithMotionDistortion(const std::string& scene_path) {
  if (!FileExists(scene_path)) return false;
  std::ifstream in(scene_path);
  const nlohmann::json scene = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  const auto lidar = scene.is_object() ? scene.find("lidar") : scene.end();
  if (!scene.is_object() || lidar == scene.end() || !lidar->is_object() ||
      !lidar->contains("motion_distortion") || !(*lidar)["motion_distortion"].is_boolean()) {
    spdlog::warn(
        "{}: no boolean lidar.motion_distortion; the scans are taken as "
        "motion-compensated",
        scene_path);
    return false;
  }
  return (*lidar)["motion_distortion"].get<bool>();
}

namespace {

// ---------------------------------------------------------------------------------------------
class KittiOdometryDataset : public Dataset {
 public:
  KittiOdometryDataset(const std::string& dir, const FrameRange& range) {
    format_ = DatasetFormat::kKittiOdometry;
    root_ = dir;
    const fs::path p(dir);
    calibration_ = ReadKittiCalibration((p / "calib.txt").string());
    const auto scans = ListNumberedFiles((p / "velodyne").string(), ".bin");
    // The images of camera 0, or of the first other camera stored (a colour-only download).
    std::map<int64_t, std::string> images;
    for (int c = 0; c < 4 && images.empty(); ++c)
      images = ListNumberedFiles((p / ("image_" + std::to_string(c))).string(), ".png");
    const std::vector<int64_t> all = DatasetFrames(FrameIds(scans), FrameIds(images), dir);
    SelectFrames(all, range, dir, &frames_);

    const std::string times_path = (p / "times.txt").string();
    if (FileExists(times_path)) {
      const auto times = ReadKittiTimes(times_path);
      JVL_CHECK(static_cast<int64_t>(times.size()) > all.back(),
                times_path << ": " << times.size() << " timestamps but the sequence has frame "
                           << all.back() << " (times, scans and images must match)");
      for (int64_t f : frames_) timestamps_.push_back(times[f]);
    } else {
      spdlog::warn("{}: no times.txt, assuming 10 Hz", dir);
      for (int64_t f : frames_) timestamps_.push_back(0.1 * f);
    }
    if (!images.empty()) {
      const cv::Mat first = ReadImage(images.begin()->second, true);
      JVL_CHECK(first.cols >= kMinImageSide && first.rows >= kMinImageSide,
                images.begin()->second << ": image is " << first.cols << "x" << first.rows
                                       << ", too small (at least " << kMinImageSide << "x"
                                       << kMinImageSide << ")");
      calibration_.image_width = first.cols;
      calibration_.image_height = first.rows;
      image_size_source_ = images.begin()->second + ", the first image";
    }
    const std::string name =
        p.filename().string().empty() ? p.parent_path().filename().string() : p.filename().string();
    const fs::path gt = p.parent_path().parent_path() / "poses" / (name + ".txt");
    if (FileExists(gt.string())) {
      const Trajectory all_gt = ReadTrajectory(gt.string(), TrajectoryFormat::kAuto);
      JVL_CHECK(all_gt.frames.back() >= all.back(),
                gt.string() << ": " << all_gt.size() << " poses but the sequence has frame "
                            << all.back() << " (poses and scans must match)");
      Trajectory selected;
      for (size_t i = 0; i < frames_.size(); ++i) {
        const auto idx = all_gt.IndexOf(frames_[i]);
        JVL_CHECK(idx, gt.string() << ": no pose for frame " << frames_[i]);
        selected.Append(frames_[i], all_gt.world_from_cam[*idx], timestamps_[i]);
      }
      ground_truth_ = selected;
      ground_truth_files_ = {gt.string()};
    }
    id_ = "kitti:" + name + ":" + HashFiles(KeyFiles());
    const std::string scene = (p / "sim" / "scene.json").string();
    scans_motion_compensated_ = !SimulatedWithMotionDistortion(scene);
    SetLidarElevationError(scene, /*kitti_hdl64e=*/true);
  }

  PointCloud LoadScan(int64_t frame, size_t* dropped) const override {
    return LoadScanChecked(ScanPath(frame), frame, dropped);
  }
  cv::Mat LoadImage(int64_t frame, int camera) const override {
    return LoadImageChecked(ImagePath(frame, camera), frame, camera, calibration_,
                            image_size_source_);
  }
  std::string ScanPath(int64_t frame) const override {
    char name[32];
    std::snprintf(name, sizeof(name), "%06lld.bin", static_cast<long long>(frame));
    return (fs::path(root_) / "velodyne" / name).string();
  }
  std::string ImagePath(int64_t frame, int camera) const override {
    char name[32];
    std::snprintf(name, sizeof(name), "%06lld.png", static_cast<long long>(frame));
    return (fs::path(root_) / ("image_" + std::to_string(camera)) / name).string();
  }
  std::vector<std::string> KeyFiles() const override {
    return {(fs::path(root_) / "calib.txt").string(), (fs::path(root_) / "times.txt").string()};
  }
};

}  // namespace

void Dataset::CheckCamera(int camera) const {
  JVL_CHECK(camera >= 0 && camera < 4, "--camera " << camera << " is not a camera (0..3)");
  JVL_CHECK(format_ != DatasetFormat::kKitti360 || camera < 2,
            root_ << ": KITTI-360 camera " << camera
                  << " is a fisheye camera; the tools read the perspective cameras 0 and 1");
  JVL_CHECK(
      format_ != DatasetFormat::kOxford || camera == 0,
      root_ << ": camera " << camera << " is not read; camera 0 is the stereo rig's centre camera");
  calibration_.CheckCamera(camera, root_);
  if (!frames_.empty()) {
    const std::string first = ImagePath(frames_.front(), camera);
    JVL_CHECK(FileExists(first), first << ": missing image of camera " << camera << " for frame "
                                       << frames_.front() << " (the first selected frame)");
  }
}

void Dataset::ReplaceCalibration(const std::string& path) {
  JVL_CHECK(FileExists(path) && !IsDirectory(path), "--calib " << path << ": file not found");
  const Calibration file = ReadKittiCalibration(path);
  Calibration replaced = calibration_;
  for (int i = 0; i < 4; ++i) {
    if (calibration_.P[static_cast<size_t>(i)].isZero()) continue;  // Not a camera of the dataset.
    file.CheckCamera(i, path);  // The file's P_i is a projection (not all zero).
    replaced.P[static_cast<size_t>(i)] = file.P[static_cast<size_t>(i)];
  }
  replaced.cam0_from_velo = file.cam0_from_velo;
  const double rotation_deg = RotationAngle(file.cam0_from_velo.rotation() *
                                            calibration_.cam0_from_velo.rotation().inverse()) *
                              180.0 / M_PI;
  spdlog::info(
      "{}: calibration from {} instead of the dataset's: its Tr differs by a rotation of {:.4f} "
      "deg and a translation of {:.4f} m",
      root_, path, rotation_deg,
      (file.cam0_from_velo.translation() - calibration_.cam0_from_velo.translation()).norm());
  calibration_ = replaced;
  calibration_file_ = path;
}

std::vector<std::string> Dataset::InputFiles() const {
  std::vector<std::string> files = KeyFiles();
  if (!calibration_file_.empty()) files.push_back(calibration_file_);
  files.insert(files.end(), ground_truth_files_.begin(), ground_truth_files_.end());
  for (const int64_t f : frames_) {
    files.push_back(ScanPath(f));
    for (int camera = 0; camera < 4; ++camera) files.push_back(ImagePath(f, camera));
  }
  return files;
}

double Dataset::ScanTimeOffsetInFrames(size_t index) const {
  if (index >= scan_time_offsets_.size() || scan_time_offsets_[index] == 0 ||
      timestamps_.size() < 2) {
    return 0;
  }
  const size_t lo = index == 0 ? 0 : index - 1;
  const size_t hi = std::min(index + 1, timestamps_.size() - 1);
  const double period = (timestamps_[hi] - timestamps_[lo]) / static_cast<double>(hi - lo);
  return period > 0 ? scan_time_offsets_[index] / period : 0;
}

namespace {

std::unique_ptr<Dataset> OpenDatasetOfFormat(const std::string& dir, DatasetFormat format,
                                             const DatasetOptions& options,
                                             const FrameRange& range) {
  if (format == DatasetFormat::kOxford) return OpenOxfordDataset(dir, options, range);
  JVL_CHECK(options.lidar == "default",
            "--lidar " << options.lidar << ": " << dir << " is a " << DatasetFormatName(format)
                       << " dataset, which has one LiDAR (the option is for oxford traversals)");
  JVL_CHECK(options.ground_truth == "default",
            "--gt-source " << options.ground_truth << ": " << dir << " is a "
                           << DatasetFormatName(format)
                           << " dataset, which has one ground truth (the option is for oxford "
                              "traversals)");
  if (format == DatasetFormat::kKittiRaw) return OpenKittiRawDataset(dir, range);
  if (format == DatasetFormat::kKitti360) return OpenKitti360Dataset(dir, range);
  return std::make_unique<KittiOdometryDataset>(dir, range);
}

}  // namespace

std::unique_ptr<Dataset> OpenDataset(const std::string& dir, DatasetFormat format,
                                     const FrameRange& range) {
  DatasetOptions options;
  options.format = DatasetFormatName(format);
  return OpenDataset(dir, options, range);
}

std::unique_ptr<Dataset> OpenDataset(const std::string& dir, const DatasetOptions& options,
                                     const FrameRange& range) {
  DatasetFormat format = ParseDatasetFormat(options.format);
  JVL_CHECK(IsDirectory(dir), dir << ": dataset folder not found");
  if (format == DatasetFormat::kAuto) format = DetectDatasetFormat(dir);
  std::unique_ptr<Dataset> dataset = OpenDatasetOfFormat(dir, format, options, range);
  if (!options.calibration.empty()) dataset->ReplaceCalibration(options.calibration);
  return dataset;
}

}  // namespace jvl::io
