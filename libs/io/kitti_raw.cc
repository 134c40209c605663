#include "io/kitti_raw.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/check.h"
#include "core/hash.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/kitti_text.h"

namespace fs = std::filesystem;

namespace jvl::io {

OxtsPacket ParseOxtsPacket(const std::string& text, const std::string& name) {
  const auto tokens = SplitWhitespace(text);
  JVL_CHECK(tokens.size() >= 6,
            name << ": OXTS packet has " << tokens.size()
                 << " values, expected 30 (at least lat lon alt roll pitch yaw)");
  double v[6];
  for (int i = 0; i < 6; ++i) {
    const auto d = ParseDouble(tokens[i]);
    JVL_CHECK(d && std::isfinite(*d), name << ": bad OXTS value '" << tokens[i] << "'");
    v[i] = *d;
  }
  return {v[0], v[1], v[2], v[3], v[4], v[5]};
}

std::vector<Rigid3d> OxtsToImuPoses(const std::vector<OxtsPacket>& packets) {
  std::vector<Rigid3d> poses;
  if (packets.empty()) return poses;
  constexpr double kEarthRadius = 6378137.0;
  const double scale = std::cos(packets.front().lat * M_PI / 180.0);
  Rigid3d first_inv;
  for (size_t i = 0; i < packets.size(); ++i) {
    const OxtsPacket& p = packets[i];
    const Eigen::Vector3d t(
        scale * p.lon * M_PI * kEarthRadius / 180.0,
        scale * kEarthRadius * std::log(std::tan((90.0 + p.lat) * M_PI / 360.0)), p.alt);
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(p.pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(p.roll, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    const Rigid3d world_from_imu(r, t);
    if (i == 0) first_inv = world_from_imu.Inverse();
    poses.push_back(first_inv * world_from_imu);
  }
  return poses;
}

namespace {

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's civil-date algorithm).
int64_t DaysFromCivil(int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<int64_t>(doe) - 719468;
}

constexpr const char* kCalibHint = "KITTI raw keeps calib_*.txt one folder above the drive";

class KittiRawDataset : public Dataset {
 public:
  KittiRawDataset(const std::string& dir, const FrameRange& range) {
    format_ = DatasetFormat::kKittiRaw;
    scans_motion_compensated_ = false;  // the raw readme: points must be untwisted
    SetLidarElevationError(/*scene_path=*/"", /*kitti_hdl64e=*/true);  // the odometry scans' sensor
    root_ = dir;
    const fs::path p = fs::path(dir);
    const fs::path drive = p.filename().empty() ? p.parent_path() : p;
    const fs::path date_dir = drive.parent_path();

    // Calibration: P_rect_0X and R_rect_00 from cam_to_cam, velo_to_cam (unrectified cam0).
    const std::string c2c = (date_dir / "calib_cam_to_cam.txt").string();
    const std::string v2c = (date_dir / "calib_velo_to_cam.txt").string();
    const std::string i2v = (date_dir / "calib_imu_to_velo.txt").string();
    key_files_ = {c2c, v2c, i2v};
    const auto cam = ReadKeyValues(c2c, kCalibHint);
    const Rigid3d rect_from_cam0 =
        ReadRectification(cam, c2c, 4, 0, &calibration_, &image_size_source_);
    const auto velo = ReadKeyValues(v2c, kCalibHint);
    const Rigid3d cam0_from_velo_unrect =
        RigidFromRT(RequireValues(velo, "R", 9, v2c), RequireValues(velo, "T", 3, v2c), v2c);
    calibration_.cam0_from_velo = rect_from_cam0 * cam0_from_velo_unrect;

    scans_ = ListNumberedFiles((drive / "velodyne_points" / "data").string(), ".bin");
    const auto images = ListNumberedFiles((drive / "image_00" / "data").string(), ".png");
    const std::vector<int64_t> all = DatasetFrames(FrameIds(scans_), FrameIds(images), dir);
    SelectFrames(all, range, dir, &frames_);

    // Timestamps of the LiDAR (or camera) stream, relative to the first line.
    const std::string stamps =
        (drive / (scans_.empty() ? "image_00" : "velodyne_points") / "timestamps.txt").string();
    if (FileExists(stamps)) {
      timestamps_ = RelativeKittiRawTimes(stamps, all.back(), frames_);
    } else {
      spdlog::warn("{}: no timestamps.txt, assuming 10 Hz", dir);
      for (int64_t f : frames_) timestamps_.push_back(0.1 * f);
    }

    // Ground truth from OXTS, as world_from_cam0 with frame 0's cam0 as the world.
    const auto oxts = ListNumberedFiles((drive / "oxts" / "data").string(), ".txt");
    if (!oxts.empty()) {
      JVL_CHECK(oxts.rbegin()->first >= all.back(),
                dir << ": oxts/data has " << oxts.size() << " packets but the drive has frame "
                    << all.back() << " (OXTS and scans must match)");
      std::vector<OxtsPacket> packets;
      std::vector<int64_t> ids;
      for (const auto& [id, path] : oxts) {
        packets.push_back(ParseOxtsPacket(ReadTextFile(path), path));
        ids.push_back(id);
        ground_truth_files_.push_back(path);
      }
      const auto imu0_from_imu = OxtsToImuPoses(packets);
      const auto imu = ReadKeyValues(i2v, kCalibHint);
      const Rigid3d velo_from_imu =
          RigidFromRT(RequireValues(imu, "R", 9, i2v), RequireValues(imu, "T", 3, i2v), i2v);
      const Rigid3d cam0_from_imu = calibration_.cam0_from_velo * velo_from_imu;
      const Rigid3d imu_from_cam0 = cam0_from_imu.Inverse();
      Trajectory gt;
      for (size_t i = 0; i < frames_.size(); ++i) {
        const auto it = std::lower_bound(ids.begin(), ids.end(), frames_[i]);
        JVL_CHECK(it != ids.end() && *it == frames_[i],
                  dir << ": no OXTS packet for frame " << frames_[i]);
        const Rigid3d& pose = imu0_from_imu[static_cast<size_t>(it - ids.begin())];
        gt.Append(frames_[i], cam0_from_imu * pose * imu_from_cam0, timestamps_[i]);
      }
      ground_truth_ = gt;
    }
    Fnv1a64 hash;
    for (const auto& f : key_files_) {
      const std::string text = ReadTextFile(f);
      hash.Update(text.data(), text.size());
    }
    id_ = "kitti-raw:" + drive.filename().string() + ":" + hash.Hex().substr(0, 8);
  }

  PointCloud LoadScan(int64_t frame, size_t* dropped) const override {
    return LoadScanChecked(ScanPath(frame), frame, dropped);
  }
  cv::Mat LoadImage(int64_t frame, int camera) const override {
    return LoadImageChecked(ImagePath(frame, camera), frame, camera, calibration_,
                            image_size_source_);
  }
  std::string ScanPath(int64_t frame) const override {
    return (fs::path(root_) / "velodyne_points" / "data" / ZeroPaddedName(frame, 10, ".bin"))
        .string();
  }
  std::string ImagePath(int64_t frame, int camera) const override {
    return (fs::path(root_) / ("image_0" + std::to_string(camera)) / "data" /
            ZeroPaddedName(frame, 10, ".png"))
        .string();
  }
  std::vector<std::string> KeyFiles() const override { return key_files_; }

 private:
  std::map<int64_t, std::string> scans_;
  std::vector<std::string> key_files_;
};

}  // namespace

KittiRawTime ParseKittiRawTime(const std::string& text, const std::string& name) {
  const std::string s(Trim(text));
  int y = 0, mo = 0, d = 0, h = 0, mi = 0;
  char frac[32] = {0};
  int sec = 0;
  const int n =
      std::sscanf(s.c_str(), "%4d-%2d-%2d %2d:%2d:%2d.%31[0-9]", &y, &mo, &d, &h, &mi, &sec, frac);
  JVL_CHECK(n >= 6 && mo >= 1 && mo <= 12 && d >= 1 && d <= 31,
            name << ": bad timestamp '" << s << "' (expected YYYY-MM-DD HH:MM:SS.fffffffff)");
  const int64_t days = DaysFromCivil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d));
  KittiRawTime t;
  t.seconds = days * 86400 + h * 3600 + mi * 60 + sec;
  if (n == 7) t.fraction = *ParseDouble(std::string("0.") + frac);
  return t;
}

double ParseKittiRawTimestamp(const std::string& text, const std::string& name) {
  const KittiRawTime t = ParseKittiRawTime(text, name);
  return static_cast<double>(t.seconds) + t.fraction;
}

std::vector<double> RelativeKittiRawTimes(const std::string& path, int64_t last_frame,
                                          const std::vector<int64_t>& frames) {
  const auto lines = ReadLines(path);
  JVL_CHECK(static_cast<int64_t>(lines.size()) > last_frame,
            path << ": " << lines.size() << " timestamps but the drive has frame " << last_frame);
  const KittiRawTime t0 = ParseKittiRawTime(lines.front(), path);
  std::vector<double> times;
  for (int64_t f : frames) {
    const KittiRawTime t = ParseKittiRawTime(lines[static_cast<size_t>(f)], path);
    times.push_back(static_cast<double>(t.seconds - t0.seconds) + (t.fraction - t0.fraction));
  }
  return times;
}

std::unique_ptr<Dataset> OpenKittiRawDataset(const std::string& dir, const FrameRange& range) {
  return std::make_unique<KittiRawDataset>(dir, range);
}

}  // namespace jvl::io
