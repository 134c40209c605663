#include "io/dataset.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "core/check.h"
#include "core/hash.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/trajectory_io.h"

namespace fs = std::filesystem;

namespace jvl::io {

DatasetFormat ParseDatasetFormat(const std::string& name) {
  if (name == "auto") return DatasetFormat::kAuto;
  if (name == "kitti") return DatasetFormat::kKittiOdometry;
  if (name == "kitti-raw") return DatasetFormat::kKittiRaw;
  JVL_THROW("--format: unknown dataset format '" << name << "' (auto, kitti, kitti-raw)");
}

DatasetFormat DetectDatasetFormat(const std::string& dir) {
  JVL_CHECK(IsDirectory(dir), dir << ": dataset folder not found");
  const fs::path p(dir);
  if (FileExists((p / "calib.txt").string()) &&
      (IsDirectory((p / "velodyne").string()) || IsDirectory((p / "image_0").string()))) {
    return DatasetFormat::kKittiOdometry;
  }
  if (IsDirectory((p / "velodyne_points" / "data").string()) ||
      IsDirectory((p / "oxts" / "data").string())) {
    return DatasetFormat::kKittiRaw;
  }
  JVL_THROW(dir << ": unknown dataset layout (expected a KITTI odometry sequence folder with "
                   "calib.txt and velodyne/ or image_0/, or a KITTI raw *_sync folder)");
}

namespace {

// Frame ids of the files "<number><ext>" in `dir`, sorted.
std::map<int64_t, std::string> ListNumberedFiles(const fs::path& dir, const std::string& ext) {
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

std::string HashFiles(const std::vector<std::string>& paths) {
  Fnv1a64 hash;
  for (const auto& p : paths) {
    if (!FileExists(p)) continue;
    const std::string text = ReadTextFile(p);
    hash.Update(text.data(), text.size());
  }
  return hash.Hex().substr(0, 8);
}

void SelectFrames(const std::vector<int64_t>& all, const FrameRange& range, const std::string& dir,
                  std::vector<int64_t>* selected) {
  JVL_CHECK(!all.empty(), dir << ": no frames found (no scans or images)");
  for (int64_t f : all)
    if (range.Contains(f)) selected->push_back(f);
  JVL_CHECK(!selected->empty(), "--frames " << range.first << ":"
                                            << (range.last_exclusive < 0 ? std::string()
                                                                         : std::to_string(range.last_exclusive))
                                            << " selects no frame of " << dir << " (frames "
                                            << all.front() << ".." << all.back() << ")");
}

PointCloud LoadScanChecked(const std::string& path, int64_t frame, size_t* dropped) {
  JVL_CHECK(FileExists(path), path << ": missing scan for frame " << frame);
  size_t bad = 0;
  PointCloud cloud = ReadVelodyneBin(path, &bad);
  if (bad > 0) {
    spdlog::warn("{}: dropped {} non-finite points (frame {})", path, bad, frame);
  }
  if (cloud.empty()) spdlog::warn("{}: empty scan (frame {})", path, frame);
  if (dropped) *dropped = bad;
  return cloud;
}

cv::Mat LoadImageChecked(const std::string& path, int64_t frame, int camera) {
  JVL_CHECK(FileExists(path), path << ": missing image of camera " << camera << " for frame " << frame);
  return ReadImage(path, camera < 2);
}

// ---------------------------------------------------------------------------------------------
class KittiOdometryDataset : public Dataset {
 public:
  KittiOdometryDataset(const std::string& dir, const FrameRange& range) {
    format_ = DatasetFormat::kKittiOdometry;
    root_ = dir;
    const fs::path p(dir);
    calibration_ = ReadKittiCalibration((p / "calib.txt").string());
    const auto scans = ListNumberedFiles(p / "velodyne", ".bin");
    const auto images = ListNumberedFiles(p / "image_0", ".png");
    std::vector<int64_t> all;
    for (const auto& [id, path] : scans.empty() ? images : scans) all.push_back(id);
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
      calibration_.image_width = first.cols;
      calibration_.image_height = first.rows;
    }
    const std::string name = p.filename().string().empty() ? p.parent_path().filename().string()
                                                           : p.filename().string();
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
    }
    id_ = "kitti:" + name + ":" + HashFiles(KeyFiles());
  }

  PointCloud LoadScan(int64_t frame, size_t* dropped) const override {
    return LoadScanChecked(ScanPath(frame), frame, dropped);
  }
  cv::Mat LoadImage(int64_t frame, int camera) const override {
    return LoadImageChecked(ImagePath(frame, camera), frame, camera);
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

}  // namespace jvl::io
#include "io/kitti_raw.h"
namespace jvl::io {

std::unique_ptr<Dataset> OpenDataset(const std::string& dir, DatasetFormat format,
                                     const FrameRange& range) {
  JVL_CHECK(IsDirectory(dir), dir << ": dataset folder not found");
  if (format == DatasetFormat::kAuto) format = DetectDatasetFormat(dir);
  if (format == DatasetFormat::kKittiRaw) return OpenKittiRawDataset(dir, range);
  return std::make_unique<KittiOdometryDataset>(dir, range);
}

}  // namespace jvl::io
