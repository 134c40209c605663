#include "io/oxford.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "core/hash.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/kitti_text.h"

namespace fs = std::filesystem;

namespace jvl::io {

Rigid3d OxfordSe3(double x, double y, double z, double roll, double pitch, double yaw) {
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  return Rigid3d(r, Eigen::Vector3d(x, y, z));
}

std::array<double, 6> OxfordXyzRpy(const Rigid3d& t) {
  const Eigen::Matrix3d r = t.RotationMatrix();
  return {t.translation().x(),
          t.translation().y(),
          t.translation().z(),
          std::atan2(r(2, 1), r(2, 2)),
          std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0))),
          std::atan2(r(1, 0), r(0, 0))};
}

std::vector<int64_t> ReadOxfordTimestamps(const std::string& path) {
  std::vector<int64_t> times;
  const auto lines = ReadLines(path);
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto tokens = SplitWhitespace(lines[i]);
    const auto t = tokens.empty() ? std::nullopt : ParseInt(tokens[0]);
    JVL_CHECK(t && *t > 0, path << ", line " << i + 1 << ": bad timestamp '" << lines[i]
                                << "' (expected '<microseconds> <chunk>')");
    JVL_CHECK(times.empty() || *t > times.back(),
              path << ", line " << i + 1 << ": timestamp " << *t << " is not after the previous");
    times.push_back(*t);
  }
  JVL_CHECK(!times.empty(), path << ": no timestamps");
  return times;
}

int64_t NearestTime(const std::vector<int64_t>& times, int64_t t) {
  if (times.empty()) return -1;
  const auto it = std::lower_bound(times.begin(), times.end(), t);
  if (it == times.begin()) return 0;
  if (it == times.end()) return static_cast<int64_t>(times.size()) - 1;
  const auto after = it - times.begin();
  return (*it - t) < (t - *(it - 1)) ? after : after - 1;
}

PointCloud ReadOxfordVelodyneBin(const std::string& path) {
  JVL_CHECK(FileExists(path), path << ": scan file not found");
  const std::string bytes = ReadTextFile(path);
  JVL_CHECK(bytes.size() % 16 == 0, path << ": " << bytes.size()
                                         << " bytes is not a whole number of points (4 float32 "
                                            "each, stored as x..., y..., z..., intensity...)");
  const size_t n = bytes.size() / 16;
  std::vector<float> v(4 * n);
  std::memcpy(v.data(), bytes.data(), bytes.size());
  PointCloud cloud;
  cloud.points.reserve(n);
  cloud.intensity.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    cloud.points.emplace_back(v[i], v[n + i], v[2 * n + i]);
    cloud.intensity.push_back(v[3 * n + i] / 255.0f);
  }
  return cloud;
}

bool IsOxfordTraversal(const std::string& dir) {
  const fs::path p(dir);
  return FileExists((p / "stereo.timestamps").string()) &&
         FileExists((p / "velodyne_left.timestamps").string());
}

namespace {

Rigid3d ReadExtrinsic(const std::string& path) {
  JVL_CHECK(FileExists(path), path << ": extrinsics file not found");
  const auto v = ReadNumberFile(path);
  JVL_CHECK(v.size() == 6, path << ": " << v.size() << " numbers, expected x y z roll pitch yaw");
  return OxfordSe3(v[0], v[1], v[2], v[3], v[4], v[5]);
}

// x forward, y left, z up (the tools' LiDAR axes) from the vehicle's x forward, y right, z down.
const Eigen::Matrix3d kFluFromFrd = Eigen::Vector3d(1, -1, -1).asDiagonal();

class OxfordDataset : public Dataset {
 public:
  OxfordDataset(const std::string& dir, const FrameRange& range) {
    format_ = DatasetFormat::kOxford;
    root_ = dir;
    const fs::path p(dir);
    // The SDK: the scans are not motion-compensated. A traversal written by sim_sequence says
    // in its sim/scene.json whether the LiDAR moved during the sweep.
    const std::string scene = (p / "sim" / "scene.json").string();
    scans_motion_compensated_ = FileExists(scene) && !SimulatedWithMotionDistortion(scene);
    JVL_CHECK(IsOxfordTraversal(dir), dir << ": not an Oxford RobotCar traversal (expected "
                                             "stereo.timestamps and velodyne_left.timestamps)");
    const std::string cam_stamps = (p / "stereo.timestamps").string();
    const std::string velo_stamps = (p / "velodyne_left.timestamps").string();
    camera_times_ = ReadOxfordTimestamps(cam_stamps);
    velo_times_ = ReadOxfordTimestamps(velo_stamps);
    key_files_ = {cam_stamps, velo_stamps};

    // The SDK's extrinsics/ and models/: in the traversal or one or two folders above.
    fs::path sdk;
    for (const fs::path& base : {p, p.parent_path(), p.parent_path().parent_path()}) {
      if (FileExists((base / "extrinsics" / "velodyne_left.txt").string()) &&
          FileExists((base / "models" / "stereo_narrow_left.txt").string())) {
        sdk = base;
        break;
      }
    }
    JVL_CHECK(!sdk.empty(), dir << ": the RobotCar SDK's extrinsics/velodyne_left.txt and "
                                   "models/stereo_narrow_left.txt were found neither in the "
                                   "traversal nor one or two folders above it (copy or link them)");
    const std::string velo_ext = (sdk / "extrinsics" / "velodyne_left.txt").string();
    const std::string model = (sdk / "models" / "stereo_narrow_left.txt").string();
    const std::string lut = (sdk / "models" / "stereo_narrow_left_distortion_lut.bin").string();
    key_files_.push_back(velo_ext);
    key_files_.push_back(model);

    // Camera: line 1 fx fy cx cy, then G_camera_image (optical frame -> camera base frame,
    // x forward, y right, z down). The stereo camera is the vehicle frame (stereo.txt is zero).
    const auto m = ReadNumberFile(model);
    JVL_CHECK(m.size() == 20,
              model << ": " << m.size() << " numbers, expected fx fy cx cy and a 4 x 4 matrix");
    JVL_CHECK(m[0] > 0 && m[1] > 0, model << ": focal lengths must be positive");
    calibration_.P[0] << m[0], 0, m[2], 0, 0, m[1], m[3], 0, 0, 0, 1, 0;
    Eigen::Matrix<double, 3, 4> g;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) g(r, c) = m[4 + 4 * r + c];
    const Rigid3d vehicle_from_cam0 = RigidFromRT(
        {g(0, 0), g(0, 1), g(0, 2), g(1, 0), g(1, 1), g(1, 2), g(2, 0), g(2, 1), g(2, 2)},
        {g(0, 3), g(1, 3), g(2, 3)}, model);
    // LiDAR: the points are turned to x forward, y left, z up at the sensor's origin.
    const Rigid3d vehicle_from_lidar = ReadExtrinsic(velo_ext);
    flu_from_lidar_ = kFluFromFrd * vehicle_from_lidar.RotationMatrix();
    const Rigid3d vehicle_from_velo(Eigen::Matrix3d(kFluFromFrd.transpose()),
                                    vehicle_from_lidar.translation());
    calibration_.cam0_from_velo = vehicle_from_cam0.Inverse() * vehicle_from_velo;

    const std::vector<int64_t> all = [&] {
      std::vector<int64_t> ids(camera_times_.size());
      for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int64_t>(i);
      return ids;
    }();
    SelectFrames(all, range, dir, &frames_);
    for (int64_t f : frames_)
      timestamps_.push_back(1e-6 * static_cast<double>(camera_times_[f] - camera_times_[0]));

    // Image size from the first image, and the undistortion table of that size.
    const std::string first = ImagePath(frames_.front(), 0);
    const cv::Mat raw = ReadImage(first, true);
    JVL_CHECK(raw.cols >= kMinImageSide && raw.rows >= kMinImageSide,
              first << ": image is " << raw.cols << "x" << raw.rows << ", too small");
    calibration_.image_width = raw.cols;
    calibration_.image_height = raw.rows;
    image_size_source_ = first + ", the first image";
    const size_t pixels = static_cast<size_t>(raw.cols) * raw.rows;
    JVL_CHECK(FileExists(lut),
              lut << ": undistortion table not found (the RobotCar SDK's models/)");
    JVL_CHECK(FileSize(lut) == static_cast<int64_t>(16 * pixels),
              lut << ": " << FileSize(lut) << " bytes, expected " << 16 * pixels << " for "
                  << raw.cols << "x" << raw.rows << " images (float64 u then v per pixel)");
    const std::string table = ReadTextFile(lut);
    std::vector<double> uv(2 * pixels);
    std::memcpy(uv.data(), table.data(), table.size());
    map_u_.create(raw.rows, raw.cols, CV_32FC1);
    map_v_.create(raw.rows, raw.cols, CV_32FC1);
    for (size_t i = 0; i < pixels; ++i) {
      JVL_CHECK(std::isfinite(uv[i]) && std::isfinite(uv[pixels + i]),
                lut << ": non-finite entry " << i);
      map_u_.at<float>(static_cast<int>(i / raw.cols), static_cast<int>(i % raw.cols)) =
          static_cast<float>(uv[i]);
      map_v_.at<float>(static_cast<int>(i / raw.cols), static_cast<int>(i % raw.cols)) =
          static_cast<float>(uv[pixels + i]);
    }
    key_files_.push_back(lut);

    ReadGroundTruth(p / "gps" / "ins.csv", sdk / "extrinsics" / "ins.txt", vehicle_from_cam0);

    size_t unpaired = 0;
    for (int64_t f : frames_) unpaired += PairedSweep(f) < 0 ? 1 : 0;
    if (unpaired > 0) {
      spdlog::warn("{}: {} of {} frames have no LiDAR sweep within {:.0f} ms of their image", dir,
                   unpaired, frames_.size(), 1e3 * kOxfordMaxPairGapS);
    }
    Fnv1a64 hash;
    for (const auto& f : key_files_) {
      if (f == lut) continue;
      const std::string text = ReadTextFile(f);
      hash.Update(text.data(), text.size());
    }
    id_ = "oxford:" + fs::path(dir).lexically_normal().filename().string() + ":" +
          hash.Hex().substr(0, 8);
  }

  PointCloud LoadScan(int64_t frame, size_t* dropped) const override {
    const int64_t k = PairedSweep(frame);
    JVL_CHECK(k >= 0, root_ << ": frame " << frame << " has no LiDAR sweep within "
                            << 1e3 * kOxfordMaxPairGapS << " ms of its image");
    const std::string path = SweepPath(k);
    PointCloud raw = ReadOxfordVelodyneBin(path);
    PointCloud cloud;
    size_t bad = 0;
    for (size_t i = 0; i < raw.size(); ++i) {
      const Eigen::Vector3d q = flu_from_lidar_ * raw.points[i];
      if (!q.allFinite() || q.norm() > kMaxScanRange) {
        ++bad;
        continue;
      }
      cloud.points.push_back(q);
      cloud.intensity.push_back(raw.intensity[i]);
    }
    if (bad > 0) spdlog::warn("{}: dropped {} invalid points (frame {})", path, bad, frame);
    if (cloud.empty()) spdlog::warn("{}: empty scan (frame {})", path, frame);
    if (dropped) *dropped = bad;
    return cloud;
  }
  cv::Mat LoadImage(int64_t frame, int camera) const override {
    JVL_CHECK(camera == 0, root_ << ": camera " << camera
                                 << " is not read; camera 0 is the stereo rig's centre camera");
    const std::string path = ImagePath(frame, 0);
    const cv::Mat raw = LoadImageChecked(path, frame, camera, calibration_, image_size_source_);
    cv::Mat grey, undistorted;
    cv::cvtColor(raw, grey, cv::COLOR_BayerGR2GRAY);  // the SDK's "gbrg" pattern
    cv::remap(grey, undistorted, map_u_, map_v_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
    return undistorted;
  }
  std::string ScanPath(int64_t frame) const override {
    const int64_t k = PairedSweep(frame);
    return k >= 0 ? SweepPath(k) : (fs::path(root_) / "velodyne_left" / "unpaired.bin").string();
  }
  std::string ImagePath(int64_t frame, int camera) const override {
    static const char* kDirs[4] = {"stereo/centre", "stereo/left", "stereo/right", "mono_left"};
    JVL_CHECK(frame >= 0 && frame < static_cast<int64_t>(camera_times_.size()),
              root_ << ": no frame " << frame);
    return (fs::path(root_) / kDirs[std::clamp(camera, 0, 3)] /
            (std::to_string(camera_times_[static_cast<size_t>(frame)]) + ".png"))
        .string();
  }
  std::vector<std::string> KeyFiles() const override { return key_files_; }

 private:
  std::string SweepPath(int64_t k) const {
    return (fs::path(root_) / "velodyne_left" /
            (std::to_string(velo_times_[static_cast<size_t>(k)]) + ".bin"))
        .string();
  }
  int64_t PairedSweep(int64_t frame) const {
    const int64_t t = camera_times_[static_cast<size_t>(frame)];
    const int64_t k = NearestTime(velo_times_, t);
    if (k < 0 || std::abs(velo_times_[static_cast<size_t>(k)] - t) > 1e6 * kOxfordMaxPairGapS)
      return -1;
    return k;
  }

  // gps/ins.csv: timestamp, ins_status, latitude, longitude, altitude, northing, easting, down,
  // utm_zone, velocity_north, velocity_east, velocity_down, roll, pitch, yaw.
  void ReadGroundTruth(const fs::path& ins_csv, const fs::path& ins_ext,
                       const Rigid3d& vehicle_from_cam0) {
    if (!FileExists(ins_csv.string())) return;
    const auto lines = ReadLines(ins_csv.string());
    std::vector<int64_t> times;
    std::vector<Rigid3d> ned_from_ins;
    for (size_t i = 1; i < lines.size(); ++i) {  // line 1 is the header
      const std::string where = ins_csv.string() + ", line " + std::to_string(i + 1);
      std::vector<std::string> cols;
      size_t start = 0;
      for (size_t c = 0; c <= lines[i].size(); ++c) {
        if (c == lines[i].size() || lines[i][c] == ',') {
          cols.emplace_back(Trim(std::string_view(lines[i]).substr(start, c - start)));
          start = c + 1;
        }
      }
      JVL_CHECK(cols.size() == 15, where << ": " << cols.size() << " columns, expected 15");
      const auto t = ParseInt(cols[0]);
      JVL_CHECK(t, where << ": bad timestamp '" << cols[0] << "'");
      double v[6];
      const int idx[6] = {5, 6, 7, 12, 13, 14};
      for (int k = 0; k < 6; ++k) {
        const auto d = ParseDouble(cols[idx[k]]);
        JVL_CHECK(d && std::isfinite(*d), where << ": bad value '" << cols[idx[k]] << "'");
        v[k] = *d;
      }
      JVL_CHECK(times.empty() || *t > times.back(), where << ": timestamp not increasing");
      times.push_back(*t);
      ned_from_ins.push_back(OxfordSe3(v[0], v[1], v[2], v[3], v[4], v[5]));
    }
    if (times.size() < 2) return;
    const Rigid3d ins_from_cam0 = ReadExtrinsic(ins_ext.string()).Inverse() * vehicle_from_cam0;
    ground_truth_files_.push_back(ins_csv.string());
    key_files_.push_back(ins_ext.string());
    Trajectory gt;
    std::optional<Rigid3d> first_inv;
    size_t outside = 0;
    for (size_t i = 0; i < frames_.size(); ++i) {
      const int64_t t = camera_times_[static_cast<size_t>(frames_[i])];
      if (t < times.front() || t > times.back()) {
        ++outside;
        continue;
      }
      const size_t hi = std::min<size_t>(
          std::upper_bound(times.begin(), times.end(), t) - times.begin(), times.size() - 1);
      const size_t lo = hi - 1;
      const double f = std::clamp(
          static_cast<double>(t - times[lo]) / static_cast<double>(times[hi] - times[lo]), 0.0,
          1.0);
      const Rigid3d world_from_cam0 =
          InterpolateDecoupled(ned_from_ins[lo], ned_from_ins[hi], f) * ins_from_cam0;
      if (!first_inv) first_inv = world_from_cam0.Inverse();
      gt.Append(frames_[i], *first_inv * world_from_cam0, timestamps_[i]);
    }
    if (outside > 0) {
      spdlog::warn("{}: {} of {} frames lie outside the INS record; they have no ground truth",
                   ins_csv.string(), outside, frames_.size());
    }
    if (!gt.empty()) ground_truth_ = gt;
  }

  std::vector<int64_t> camera_times_, velo_times_;
  Eigen::Matrix3d flu_from_lidar_ = Eigen::Matrix3d::Identity();
  cv::Mat map_u_, map_v_;
  std::vector<std::string> key_files_;
};

}  // namespace

std::unique_ptr<Dataset> OpenOxfordDataset(const std::string& dir, const FrameRange& range) {
  return std::make_unique<OxfordDataset>(dir, range);
}

}  // namespace jvl::io
