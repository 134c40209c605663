#include "io/oxford.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

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

PointCloud ReadOxfordVelodynePng(const std::string& path, std::vector<int64_t>* times) {
  JVL_CHECK(FileExists(path), path << ": scan file not found");
  cv::Mat raw;
  try {
    raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    raw.release();
  }
  JVL_CHECK(!raw.empty(), path << ": not a readable PNG image (a raw Velodyne sweep)");
  JVL_CHECK(raw.type() == CV_8UC1, path
                                       << ": a raw Velodyne sweep is an 8-bit grey image, this one "
                                       << "has " << raw.channels() << " channel(s) of "
                                       << 8 * raw.elemSize1() << " bits");
  JVL_CHECK(raw.rows == kOxfordRawSweepRows,
            path << ": " << raw.rows << " rows, expected " << kOxfordRawSweepRows
                 << " (32 intensities, 64 range bytes, 2 azimuth bytes, 8 time bytes)");
  const int n = raw.cols;
  const auto byte = [&](int row, int col) {
    return static_cast<uint32_t>(raw.at<uint8_t>(row, col));
  };
  const auto u16 = [&](int row, int col) { return byte(row, col) | (byte(row + 1, col) << 8); };
  constexpr double kPi = 3.14159265358979323846;
  std::vector<double> sin_azimuth(n), cos_azimuth(n);
  for (int c = 0; c < n; ++c) {
    const double azimuth = u16(96, c) * (2.0 * kPi) / 36000.0;  // 1/100 degree
    sin_azimuth[c] = std::sin(azimuth);
    cos_azimuth[c] = std::cos(azimuth);
  }
  std::vector<int64_t> column_times;
  if (times) {
    column_times.resize(n);
    for (int c = 0; c < n; ++c) {
      uint64_t t = 0;
      for (int b = 0; b < 8; ++b) t |= static_cast<uint64_t>(byte(98 + b, c)) << (8 * b);
      column_times[c] = static_cast<int64_t>(t);
    }
    times->clear();
  }
  PointCloud cloud;
  for (int k = 0; k < 32; ++k) {
    const double cos_elevation = std::cos(kHdl32eElevations[k]);
    const double sin_elevation = std::sin(kHdl32eElevations[k]);
    for (int c = 0; c < n; ++c) {
      const double range = u16(32 + 2 * k, c) * kHdl32eRangeResolution;
      if (!(range > kHdl32eMinimumRange)) continue;
      const double xy = cos_elevation * range;
      cloud.points.emplace_back(sin_azimuth[c] * xy, -cos_azimuth[c] * xy,
                                sin_elevation * range - kHdl32eBaseToFireHeight);
      cloud.intensity.push_back(static_cast<float>(byte(k, c)) / 255.0f);
      if (times) times->push_back(column_times[c]);
    }
  }
  return cloud;
}

OxfordLidar ParseOxfordLidar(const std::string& name) {
  if (name == "default" || name == "left") return OxfordLidar::kLeft;
  if (name == "right") return OxfordLidar::kRight;
  if (name == "both") return OxfordLidar::kBoth;
  JVL_THROW("--lidar: expected default, left, right or both, got '" << name << "'");
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

// The comma-separated fields of a CSV line, trimmed.
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> cols;
  size_t start = 0;
  for (size_t c = 0; c <= line.size(); ++c) {
    if (c == line.size() || line[c] == ',') {
      cols.emplace_back(Trim(std::string_view(line).substr(start, c - start)));
      start = c + 1;
    }
  }
  return cols;
}

// x forward, y left, z up (the tools' LiDAR axes) from the vehicle's x forward, y right, z down.
const Eigen::Matrix3d kFluFromFrd = Eigen::Vector3d(1, -1, -1).asDiagonal();

// One Velodyne: its sweeps' times and how its points reach the tools' axes.
struct Velodyne {
  std::string name;            // velodyne_left or velodyne_right
  std::vector<int64_t> times;  // <name>.timestamps
  Eigen::Matrix3d flu_from_lidar =
      Eigen::Matrix3d::Identity();  // sensor axes -> x forward, y left, z up at the sensor
  Rigid3d vehicle_from_velo;        // that turned frame in the vehicle frame
};

class OxfordDataset : public Dataset {
 public:
  OxfordDataset(const std::string& dir, const DatasetOptions& options, const FrameRange& range) {
    format_ = DatasetFormat::kOxford;
    root_ = dir;
    const OxfordLidar lidar = ParseOxfordLidar(options.lidar);
    const std::string& gt_source = options.ground_truth;
    JVL_CHECK(gt_source == "default" || gt_source == "ins" || gt_source == "radar",
              "--gt-source: expected default, ins or radar, got '" << gt_source << "'");
    const fs::path p(dir);
    // The SDK: the scans are not motion-compensated. A traversal written by sim_sequence says
    // in its sim/scene.json whether the LiDAR moved during the sweep.
    const std::string scene = (p / "sim" / "scene.json").string();
    scans_motion_compensated_ = FileExists(scene) && !SimulatedWithMotionDistortion(scene);
    SetLidarElevationError(scene, /*kitti_hdl64e=*/false);
    JVL_CHECK(IsOxfordTraversal(dir), dir << ": not an Oxford RobotCar traversal (expected "
                                             "stereo.timestamps and velodyne_left.timestamps)");
    const std::string cam_stamps = (p / "stereo.timestamps").string();
    primary_.name = lidar == OxfordLidar::kRight ? "velodyne_right" : "velodyne_left";
    const std::string velo_stamps = (p / (primary_.name + ".timestamps")).string();
    JVL_CHECK(FileExists(velo_stamps),
              "--lidar " << options.lidar << ": " << velo_stamps << ": not found");
    camera_times_ = ReadOxfordTimestamps(cam_stamps);
    primary_.times = ReadOxfordTimestamps(velo_stamps);
    key_files_ = {cam_stamps, velo_stamps};

    // The SDK's extrinsics/ and models/: in the traversal or one or two folders above.
    fs::path sdk;
    for (const fs::path& base : {p, p.parent_path(), p.parent_path().parent_path()}) {
      if (FileExists((base / "extrinsics" / (primary_.name + ".txt")).string()) &&
          FileExists((base / "models" / "stereo_narrow_left.txt").string())) {
        sdk = base;
        break;
      }
    }
    JVL_CHECK(!sdk.empty(), dir << ": the RobotCar SDK's extrinsics/" << primary_.name
                                << ".txt and models/stereo_narrow_left.txt were found neither in "
                                   "the traversal nor one or two folders above it (copy or link "
                                   "them)");
    const std::string velo_ext = (sdk / "extrinsics" / (primary_.name + ".txt")).string();
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
    SetExtrinsic(velo_ext, &primary_);
    calibration_.cam0_from_velo = vehicle_from_cam0.Inverse() * primary_.vehicle_from_velo;

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

    if (lidar == OxfordLidar::kBoth) {
      // The right Velodyne, merged into the left one's frame (its sweep nearest the left's).
      Velodyne right;
      right.name = "velodyne_right";
      const std::string right_stamps = (p / "velodyne_right.timestamps").string();
      const std::string right_ext = (sdk / "extrinsics" / "velodyne_right.txt").string();
      JVL_CHECK(FileExists(right_stamps), "--lidar both: " << right_stamps << ": not found");
      right.times = ReadOxfordTimestamps(right_stamps);
      SetExtrinsic(right_ext, &right);
      primary_from_secondary_ = primary_.vehicle_from_velo.Inverse() * right.vehicle_from_velo;
      secondary_ = std::move(right);
      key_files_.push_back(right_stamps);
      key_files_.push_back(right_ext);
    }

    ReadGroundTruth(p, sdk, vehicle_from_cam0, gt_source);

    size_t unpaired = 0;
    for (int64_t f : frames_) {
      const int64_t k = PairedSweep(f);
      unpaired += k < 0 ? 1 : 0;
      scan_time_offsets_.push_back(
          k < 0 ? 0.0
                : 1e-6 * static_cast<double>(primary_.times[static_cast<size_t>(k)] -
                                             camera_times_[static_cast<size_t>(f)]));
    }
    if (unpaired > 0) {
      spdlog::warn("{}: {} of {} frames have no LiDAR sweep within {:.0f} ms of their image", dir,
                   unpaired, frames_.size(), 1e3 * kOxfordMaxPairGapS);
    }
    if (secondary_) {
      size_t alone = 0;
      for (int64_t f : frames_) {
        const int64_t k = PairedSweep(f);
        alone += k >= 0 && SecondarySweep(k) < 0 ? 1 : 0;
      }
      if (alone > 0) {
        spdlog::warn(
            "{}: {} of {} frames have no right Velodyne sweep within {:.0f} ms of their left one; "
            "their scans are the left sweep alone",
            dir, alone, frames_.size(), 1e3 * kOxfordMaxPairGapS);
      }
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
    PointCloud cloud;
    size_t bad = 0;
    AppendSweep(primary_, k, nullptr, frame, &cloud, &bad);
    if (secondary_) {
      const int64_t j = SecondarySweep(k);
      if (j >= 0) AppendSweep(*secondary_, j, &primary_from_secondary_, frame, &cloud, &bad);
    }
    if (cloud.empty()) spdlog::warn("{}: empty scan (frame {})", SweepPath(primary_, k), frame);
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
    return k >= 0 ? SweepPath(primary_, k)
                  : (fs::path(root_) / primary_.name / "unpaired.bin").string();
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
  static void SetExtrinsic(const std::string& path, Velodyne* v) {
    const Rigid3d vehicle_from_lidar = ReadExtrinsic(path);
    v->flu_from_lidar = kFluFromFrd * vehicle_from_lidar.RotationMatrix();
    v->vehicle_from_velo =
        Rigid3d(Eigen::Matrix3d(kFluFromFrd.transpose()), vehicle_from_lidar.translation());
  }
  // The sweep's .bin when present (the SDK's build_pointcloud reads it first), else its raw .png.
  std::string SweepPath(const Velodyne& v, int64_t k) const {
    const fs::path base =
        fs::path(root_) / v.name / std::to_string(v.times[static_cast<size_t>(k)]);
    const std::string bin = base.string() + ".bin";
    const std::string png = base.string() + ".png";
    return !FileExists(bin) && FileExists(png) ? png : bin;
  }
  // Sweep k of `v` in the tools' axes at v's origin, moved by `to_primary` if given.
  void AppendSweep(const Velodyne& v, int64_t k, const Rigid3d* to_primary, int64_t frame,
                   PointCloud* cloud, size_t* bad_total) const {
    const std::string path = SweepPath(v, k);
    JVL_CHECK(FileExists(path), path << ": scan file not found (nor a raw .png sweep)");
    const PointCloud raw = fs::path(path).extension() == ".png" ? ReadOxfordVelodynePng(path)
                                                                : ReadOxfordVelodyneBin(path);
    size_t bad = 0;
    for (size_t i = 0; i < raw.size(); ++i) {
      Eigen::Vector3d q = v.flu_from_lidar * raw.points[i];
      if (to_primary) q = *to_primary * q;
      if (!q.allFinite() || q.norm() > kMaxScanRange) {
        ++bad;
        continue;
      }
      cloud->points.push_back(q);
      cloud->intensity.push_back(raw.intensity[i]);
    }
    if (bad > 0) spdlog::warn("{}: dropped {} invalid points (frame {})", path, bad, frame);
    *bad_total += bad;
  }
  int64_t PairedSweep(int64_t frame) const {
    const int64_t t = camera_times_[static_cast<size_t>(frame)];
    const int64_t k = NearestTime(primary_.times, t);
    if (k < 0 || std::abs(primary_.times[static_cast<size_t>(k)] - t) > 1e6 * kOxfordMaxPairGapS)
      return -1;
    return k;
  }
  // The right sweep nearest in time to left sweep k (-1 if none within kOxfordMaxPairGapS).
  int64_t SecondarySweep(int64_t k) const {
    const int64_t t = primary_.times[static_cast<size_t>(k)];
    const int64_t j = NearestTime(secondary_->times, t);
    if (j < 0 || std::abs(secondary_->times[static_cast<size_t>(j)] - t) > 1e6 * kOxfordMaxPairGapS)
      return -1;
    return j;
  }

  // --gt-source: default (gps/ins.csv if present, else gt/radar_odometry.csv if present), ins
  // or radar (the file must be present).
  void ReadGroundTruth(const fs::path& dir, const fs::path& sdk, const Rigid3d& vehicle_from_cam0,
                       const std::string& source) {
    const fs::path ins_csv = dir / "gps" / "ins.csv";
    const fs::path radar_csv = dir / "gt" / "radar_odometry.csv";
    std::string use = source;
    if (use == "default") {
      use = FileExists(ins_csv.string()) ? "ins" : FileExists(radar_csv.string()) ? "radar" : "";
    } else {
      const fs::path& needed = use == "ins" ? ins_csv : radar_csv;
      JVL_CHECK(FileExists(needed.string()),
                "--gt-source " << use << ": " << needed.string() << ": not found");
    }
    if (use == "ins")
      ReadInsGroundTruth(ins_csv, sdk / "extrinsics" / "ins.txt", vehicle_from_cam0);
    if (use == "radar") {
      ReadRadarGroundTruth(radar_csv, sdk / "extrinsics" / "radar.txt", vehicle_from_cam0);
    }
  }

  // gps/ins.csv: timestamp, ins_status, latitude, longitude, altitude, northing, easting, down,
  // utm_zone, velocity_north, velocity_east, velocity_down, roll, pitch, yaw.
  void ReadInsGroundTruth(const fs::path& ins_csv, const fs::path& ins_ext,
                          const Rigid3d& vehicle_from_cam0) {
    const auto lines = ReadLines(ins_csv.string());
    std::vector<int64_t> times;
    std::vector<Rigid3d> ned_from_ins;
    for (size_t i = 1; i < lines.size(); ++i) {  // line 1 is the header
      const std::string where = ins_csv.string() + ", line " + std::to_string(i + 1);
      const std::vector<std::string> cols = SplitCsv(lines[i]);
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
    InterpolateGroundTruth(times, ned_from_ins, ins_from_cam0, ins_csv.string(), "INS record");
  }

  // gt/radar_odometry.csv (the Radar RobotCar dataset's documentation): source_timestamp,
  // destination_timestamp, x, y, z, roll, pitch, yaw, source_radar_timestamp,
  // destination_radar_timestamp. Each row is the pose of the radar at the source (later) time in
  // its frame at the destination (earlier) time, as the SDK's interpolate_vo_poses composes
  // relative poses (absolute(source) = absolute(previous) * row); the rows form one chain, each
  // destination being the previous row's source. The composed poses are at the rows' first two
  // timestamps (the radar timestamps are those of the scans the odometry was computed from).
  void ReadRadarGroundTruth(const fs::path& radar_csv, const fs::path& radar_ext,
                            const Rigid3d& vehicle_from_cam0) {
    const auto lines = ReadLines(radar_csv.string());
    std::vector<int64_t> times;
    std::vector<Rigid3d> first_from_radar;
    for (size_t i = 1; i < lines.size(); ++i) {  // line 1 is the header
      const std::string where = radar_csv.string() + ", line " + std::to_string(i + 1);
      const std::vector<std::string> cols = SplitCsv(lines[i]);
      JVL_CHECK(cols.size() == 10, where << ": " << cols.size() << " columns, expected 10");
      const auto source = ParseInt(cols[0]);
      const auto destination = ParseInt(cols[1]);
      JVL_CHECK(source && destination,
                where << ": bad timestamps '" << cols[0] << "', '" << cols[1] << "'");
      double v[6];
      for (int k = 0; k < 6; ++k) {
        const auto d = ParseDouble(cols[2 + k]);
        JVL_CHECK(d && std::isfinite(*d), where << ": bad value '" << cols[2 + k] << "'");
        v[k] = *d;
      }
      JVL_CHECK(*source > *destination,
                where << ": source_timestamp " << *source << " is not after destination_timestamp "
                      << *destination << " (a row is the later frame's pose in the earlier one)");
      if (times.empty()) {
        times.push_back(*destination);
        first_from_radar.push_back(Rigid3d());
      }
      JVL_CHECK(*destination == times.back(),
                where << ": destination_timestamp " << *destination
                      << " is not the previous row's source_timestamp " << times.back()
                      << " (the relative poses must form one chain)");
      times.push_back(*source);
      first_from_radar.push_back(first_from_radar.back() *
                                 OxfordSe3(v[0], v[1], v[2], v[3], v[4], v[5]));
    }
    JVL_CHECK(times.size() >= 2, radar_csv.string() << ": no relative poses");
    const Rigid3d radar_from_cam0 = ReadExtrinsic(radar_ext.string()).Inverse() * vehicle_from_cam0;
    ground_truth_files_.push_back(radar_csv.string());
    key_files_.push_back(radar_ext.string());
    InterpolateGroundTruth(times, first_from_radar, radar_from_cam0, radar_csv.string(),
                           "radar odometry");
  }

  // world_from_cam0 at the selected frames' image times from sensor poses at `times` (SLERP and
  // linear translation between the two around each), relative to the first frame that has one.
  void InterpolateGroundTruth(const std::vector<int64_t>& times,
                              const std::vector<Rigid3d>& world_from_sensor,
                              const Rigid3d& sensor_from_cam0, const std::string& source,
                              const char* record) {
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
          InterpolateDecoupled(world_from_sensor[lo], world_from_sensor[hi], f) * sensor_from_cam0;
      if (!first_inv) first_inv = world_from_cam0.Inverse();
      gt.Append(frames_[i], *first_inv * world_from_cam0, timestamps_[i]);
    }
    if (outside > 0) {
      spdlog::warn("{}: {} of {} frames lie outside the {}; they have no ground truth", source,
                   outside, frames_.size(), record);
    }
    if (!gt.empty()) ground_truth_ = gt;
  }

  std::vector<int64_t> camera_times_;
  Velodyne primary_;                   // the frames' LiDAR (left unless --lidar right)
  std::optional<Velodyne> secondary_;  // --lidar both: the right one
  Rigid3d primary_from_secondary_;
  cv::Mat map_u_, map_v_;
  std::vector<std::string> key_files_;
};

}  // namespace

std::unique_ptr<Dataset> OpenOxfordDataset(const std::string& dir, const FrameRange& range) {
  return std::make_unique<OxfordDataset>(dir, DatasetOptions(), range);
}

std::unique_ptr<Dataset> OpenOxfordDataset(const std::string& dir, const DatasetOptions& options,
                                           const FrameRange& range) {
  return std::make_unique<OxfordDataset>(dir, options, range);
}

}  // namespace jvl::io
