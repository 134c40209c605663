#include "io/kitti360.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>

#include "core/check.h"
#include "core/hash.h"
#include "io/files.h"
#include "io/kitti_raw.h"
#include "io/kitti_text.h"

namespace fs = std::filesystem;

namespace jvl::io {

std::optional<Kitti360Location> LocateKitti360(const std::string& dir) {
  fs::path p(dir);
  if (p.filename().empty()) p = p.parent_path();
  const std::string parent = p.parent_path().filename().string();
  if (parent != "data_3d_raw" && parent != "data_2d_raw" && parent != "data_poses") {
    return std::nullopt;
  }
  const fs::path root = p.parent_path().parent_path();
  if (!FileExists((root / "calibration" / "perspective.txt").string())) return std::nullopt;
  return Kitti360Location{root.string(), p.filename().string()};
}

std::map<int64_t, Rigid3d> ReadKitti360Poses(const std::string& path) {
  std::map<int64_t, Rigid3d> poses;
  const auto lines = ReadLines(path);
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto tokens = SplitWhitespace(lines[i]);
    const std::string where = path + ", line " + std::to_string(i + 1);
    JVL_CHECK(tokens.size() == 13 || tokens.size() == 17,
              where << ": " << tokens.size()
                    << " values, expected a frame number and 12 (3 x 4) or 16 (4 x 4)");
    const auto frame = ParseInt(tokens[0]);
    JVL_CHECK(frame && *frame >= 0, where << ": bad frame number '" << tokens[0] << "'");
    std::vector<double> m;
    for (size_t k = 1; k < tokens.size(); ++k) {
      const auto v = ParseDouble(tokens[k]);
      JVL_CHECK(v && std::isfinite(*v), where << ": bad value '" << tokens[k] << "'");
      m.push_back(*v);
    }
    if (m.size() == 16) {
      JVL_CHECK(m[12] == 0 && m[13] == 0 && m[14] == 0 && m[15] == 1,
                where << ": the last row of the 4 x 4 matrix is not 0 0 0 1");
      m.resize(12);
    }
    JVL_CHECK(poses.count(*frame) == 0, where << ": frame " << *frame << " appears twice");
    JVL_CHECK(poses.empty() || *frame > poses.rbegin()->first,
              where << ": frame " << *frame << " is not after frame " << poses.rbegin()->first);
    poses.emplace(*frame, RigidFrom3x4(m, where));
  }
  JVL_CHECK(!poses.empty(), path << ": no poses");
  return poses;
}

namespace {

constexpr const char* kCalibHint = "KITTI-360 keeps it in ROOT/calibration";

// Frame ranges "a-b, c, ..." of the ids in `all` missing from `have`, at most `max_ranges`.
std::string MissingRanges(const std::vector<int64_t>& all, const std::map<int64_t, Rigid3d>& have,
                          size_t* missing) {
  std::string out;
  size_t ranges = 0;
  *missing = 0;
  for (size_t i = 0; i < all.size();) {
    if (have.count(all[i])) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < all.size() && all[j + 1] == all[j] + 1 && !have.count(all[j + 1])) ++j;
    *missing += j - i + 1;
    if (++ranges <= 5) {
      out += (out.empty() ? "" : ", ") + std::to_string(all[i]);
      if (j > i) out += "-" + std::to_string(all[j]);
    }
    i = j + 1;
  }
  if (ranges > 5) out += ", ...";
  return out;
}

class Kitti360Dataset : public Dataset {
 public:
  Kitti360Dataset(const std::string& dir, const FrameRange& range) {
    format_ = DatasetFormat::kKitti360;
    const auto where = LocateKitti360(dir);
    JVL_CHECK(where, dir << ": not a KITTI-360 drive folder (expected ROOT/data_3d_raw/DRIVE, "
                            "ROOT/data_2d_raw/DRIVE or ROOT/data_poses/DRIVE with "
                            "ROOT/calibration/perspective.txt)");
    const fs::path root(where->root);
    drive_ = where->drive;
    root_ = dir;
    velo_dir_ = root / "data_3d_raw" / drive_ / "velodyne_points";
    // The raw Velodyne sweeps, as in KITTI raw (the odometry benchmark's scans are the ones
    // that were compensated): --deskew auto de-skews them. A drive written by sim_sequence says
    // in its sim/scene.json whether the LiDAR moved during the sweep.
    const std::string scene = (root / "data_3d_raw" / drive_ / "sim" / "scene.json").string();
    scans_motion_compensated_ = FileExists(scene) && !SimulatedWithMotionDistortion(scene);
    SetLidarElevationError(scene, /*kitti_hdl64e=*/false);
    image_root_ = root / "data_2d_raw" / drive_;

    // Calibration: rectified P of cameras 0 and 1 (the perspective pair), the rectified image
    // size, and the Velodyne in the rectified camera-0 frame.
    const std::string persp = (root / "calibration" / "perspective.txt").string();
    const std::string c2v = (root / "calibration" / "calib_cam_to_velo.txt").string();
    const std::string c2p = (root / "calibration" / "calib_cam_to_pose.txt").string();
    key_files_ = {persp, c2v};
    const auto cam = ReadKeyValues(persp, kCalibHint);
    const Rigid3d rect_from_cam0 =
        ReadRectification(cam, persp, 1, 1, &calibration_, &image_size_source_);
    JVL_CHECK(calibration_.P[0](0, 0) > 0 && calibration_.P[0](1, 1) > 0,
              persp << ": P_rect_00 has no positive focal length");
    JVL_CHECK(FileExists(c2v), c2v << ": calibration file not found (" << kCalibHint << ")");
    const Rigid3d velo_from_cam0 = RigidFrom3x4(ReadNumberFile(c2v), c2v);
    calibration_.cam0_from_velo = rect_from_cam0 * velo_from_cam0.Inverse();

    scans_ = ListNumberedFiles((velo_dir_ / "data").string(), ".bin");
    const auto images =
        ListNumberedFiles((image_root_ / "image_00" / "data_rect").string(), ".png");
    JVL_CHECK(!scans_.empty() || !images.empty(),
              dir << ": drive " << drive_ << " has neither scans (" << (velo_dir_ / "data").string()
                  << ") nor images (" << (image_root_ / "image_00" / "data_rect").string() << ")");
    const std::vector<int64_t> all = DatasetFrames(FrameIds(scans_), FrameIds(images), dir);
    SelectFrames(all, range, dir, &frames_);

    // Timestamps of the LiDAR (or camera) stream, relative to the first line.
    const std::string stamps =
        ((scans_.empty() ? image_root_ / "image_00" : velo_dir_) / "timestamps.txt").string();
    if (FileExists(stamps)) {
      key_files_.push_back(stamps);
      timestamps_ = RelativeKittiRawTimes(stamps, all.back(), frames_);
    } else {
      spdlog::warn("{}: no timestamps.txt, assuming 10 Hz", dir);
      for (int64_t f : frames_) timestamps_.push_back(0.1 * f);
    }

    // Ground truth: rectified camera 0 in the world, relative to the drive's first posed frame.
    const fs::path poses_dir = root / "data_poses" / drive_;
    const std::string cam_poses = (poses_dir / "cam0_to_world.txt").string();
    const std::string imu_poses = (poses_dir / "poses.txt").string();
    std::map<int64_t, Rigid3d> world_from_cam0;
    if (FileExists(cam_poses)) {
      world_from_cam0 = ReadKitti360Poses(cam_poses);
      ground_truth_files_.push_back(cam_poses);
    } else if (FileExists(imu_poses)) {
      const auto kv = ReadKeyValues(c2p, kCalibHint);
      const Rigid3d pose_from_cam0 = RigidFrom3x4(RequireValues(kv, "image_00", 12, c2p), c2p);
      const Rigid3d cam0_from_rect = rect_from_cam0.Inverse();
      for (const auto& [frame, world_from_pose] : ReadKitti360Poses(imu_poses)) {
        world_from_cam0.emplace(frame, world_from_pose * pose_from_cam0 * cam0_from_rect);
      }
      ground_truth_files_.push_back(imu_poses);
      key_files_.push_back(c2p);
    }
    if (!world_from_cam0.empty()) {
      const Rigid3d first_inv = world_from_cam0.begin()->second.Inverse();
      Trajectory gt;
      for (size_t i = 0; i < frames_.size(); ++i) {
        const auto it = world_from_cam0.find(frames_[i]);
        if (it != world_from_cam0.end())
          gt.Append(frames_[i], first_inv * it->second, timestamps_[i]);
      }
      size_t missing = 0;
      const std::string ranges = MissingRanges(frames_, world_from_cam0, &missing);
      if (missing > 0) {
        spdlog::warn(
            "{}: {} of {} selected frames have no ground-truth pose (frames {}; KITTI-360 "
            "leaves out frames where the car stands still); evaluate matches by frame",
            ground_truth_files_.front(), missing, frames_.size(), ranges);
      }
      if (!gt.empty()) ground_truth_ = gt;
    }
    Fnv1a64 hash;
    for (const auto& f : key_files_) {
      const std::string text = ReadTextFile(f);
      hash.Update(text.data(), text.size());
    }
    id_ = "kitti360:" + drive_ + ":" + hash.Hex().substr(0, 8);
  }

  PointCloud LoadScan(int64_t frame, size_t* dropped) const override {
    return LoadScanChecked(ScanPath(frame), frame, dropped);
  }
  cv::Mat LoadImage(int64_t frame, int camera) const override {
    JVL_CHECK(camera == 0 || camera == 1,
              root_ << ": KITTI-360 camera " << camera
                    << " is a fisheye camera; the tools read the perspective cameras 0 and 1");
    return LoadImageChecked(ImagePath(frame, camera), frame, camera, calibration_,
                            image_size_source_);
  }
  std::string ScanPath(int64_t frame) const override {
    return (velo_dir_ / "data" / ZeroPaddedName(frame, 10, ".bin")).string();
  }
  std::string ImagePath(int64_t frame, int camera) const override {
    // Cameras 2 and 3 are the fisheyes (data_rgb); listed so that no tool ever writes there.
    const char* sub = camera < 2 ? "data_rect" : "data_rgb";
    return (image_root_ / ("image_0" + std::to_string(camera)) / sub /
            ZeroPaddedName(frame, 10, ".png"))
        .string();
  }
  std::vector<std::string> KeyFiles() const override { return key_files_; }

 private:
  std::string drive_;
  fs::path velo_dir_, image_root_;
  std::map<int64_t, std::string> scans_;
  std::vector<std::string> key_files_;
};

}  // namespace

std::unique_ptr<Dataset> OpenKitti360Dataset(const std::string& dir, const FrameRange& range) {
  return std::make_unique<Kitti360Dataset>(dir, range);
}

}  // namespace jvl::io
