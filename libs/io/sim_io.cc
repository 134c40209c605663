#include "io/sim_io.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/check.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/kitti_text.h"
#include "io/oxford.h"
#include "io/trajectory_io.h"

namespace jvl::io {
namespace {

std::string FormatDouble(double v, const char* fmt) {
  if (!std::isfinite(v)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

}  // namespace

SimLayout ParseSimLayout(const std::string& name) {
  if (name == "kitti") return SimLayout::kKitti;
  if (name == "kitti360") return SimLayout::kKitti360;
  if (name == "oxford") return SimLayout::kOxford;
  JVL_THROW("--layout: unknown layout '" << name << "' (kitti, kitti360, oxford)");
}

int64_t SequenceLayout::OxfordTime(int64_t frame) const {
  JVL_CHECK(frame >= 0 && frame < static_cast<int64_t>(times.size()),
            "Oxford layout: no timestamp for frame " << frame);
  return kOxfordSimEpochUs + std::llround(1e6 * times[static_cast<size_t>(frame)]);
}
std::string SequenceLayout::Drive() const {
  if (layout == SimLayout::kOxford) return "sim-oxford-" + sequence;
  return "sim_drive_00" + sequence + "_sync";
}
std::string SequenceLayout::SequenceDir() const {
  if (layout == SimLayout::kKitti360) return root + "/data_3d_raw/" + Drive();
  if (layout == SimLayout::kOxford) return root + "/" + Drive();
  return root + "/sequences/" + sequence;
}
std::string SequenceLayout::ScanPath(int64_t f) const {
  if (layout == SimLayout::kOxford)
    return SequenceDir() + "/velodyne_left/" + std::to_string(OxfordTime(f)) + ".bin";
  if (layout == SimLayout::kKitti360)
    return SequenceDir() + "/velodyne_points/data/" + ZeroPaddedName(f, 10, ".bin");
  return SequenceDir() + "/velodyne/" + ZeroPaddedName(f, 6, ".bin");
}
std::string SequenceLayout::ImagePath(int64_t f, int camera) const {
  JVL_CHECK(camera >= 0 && camera < 4, "camera " << camera << " is not a camera (0..3)");
  JVL_CHECK(camera == 0 || layout == SimLayout::kKitti,
            "the " << (layout == SimLayout::kOxford ? "Oxford" : "KITTI-360")
                   << " layout is written with camera 0 only, not camera " << camera);
  if (layout == SimLayout::kOxford)
    return SequenceDir() + "/stereo/centre/" + std::to_string(OxfordTime(f)) + ".png";
  if (layout == SimLayout::kKitti360) {
    return root + "/data_2d_raw/" + Drive() + "/image_00/data_rect/" +
           ZeroPaddedName(f, 10, ".png");
  }
  return SequenceDir() + "/image_" + std::to_string(camera) + "/" + ZeroPaddedName(f, 6, ".png");
}
std::string SequenceLayout::PosesPath() const {
  if (layout == SimLayout::kOxford) return SequenceDir() + "/gps/ins.csv";
  if (layout == SimLayout::kKitti360) return root + "/data_poses/" + Drive() + "/cam0_to_world.txt";
  return root + "/poses/" + sequence + ".txt";
}
std::string SequenceLayout::SimDir() const { return SequenceDir() + "/sim"; }

namespace {

// " m00 m01 ... m23" of a rigid transform, full precision.
std::string Format3x4(const Rigid3d& t) {
  const Eigen::Matrix<double, 3, 4> m = t.Matrix3x4();
  std::string out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out += " " + FormatDouble(m(r, c), "%.17g");
  return out;
}

// KITTI raw / KITTI-360 timestamp of `seconds` after 2013-01-01 00:00:00 (within one day).
std::string Kitti360Timestamp(double seconds) {
  JVL_CHECK(seconds >= 0 && seconds < 86400,
            "KITTI-360 timestamps: " << seconds << " s is not within a day");
  const auto ns = static_cast<int64_t>(std::llround(seconds * 1e9));
  const int64_t s = ns / 1000000000, frac = ns % 1000000000;
  char buf[64];
  std::snprintf(buf, sizeof(buf), "2013-01-01 %02lld:%02lld:%02lld.%09lld",
                static_cast<long long>(s / 3600), static_cast<long long>(s / 60 % 60),
                static_cast<long long>(s % 60), static_cast<long long>(frac));
  return buf;
}

void WriteKitti360Metadata(const SequenceLayout& layout, const Calibration& calib,
                           const Trajectory& gt) {
  const std::string calib_dir = layout.root + "/calibration";
  const std::string image_dir = layout.root + "/data_2d_raw/" + layout.Drive() + "/image_00";
  const std::string poses_dir = layout.root + "/data_poses/" + layout.Drive();
  for (const std::string& d :
       {calib_dir, layout.SequenceDir() + "/velodyne_points", image_dir, poses_dir})
    CreateDirectories(d);
  auto row = [](const Eigen::Matrix<double, 3, 4>& m) {
    std::string out;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out += " " + FormatDouble(m(r, c), "%.12e");
    return out;
  };
  std::ostringstream persp;
  persp << "P_rect_00:" << row(calib.P[0]) << "\n"
        << "R_rect_00: 1 0 0 0 1 0 0 0 1\n"
        << "S_rect_00: " << calib.image_width << " " << calib.image_height << "\n"
        << "P_rect_01:" << row(calib.P[1]) << "\n"
        << "R_rect_01: 1 0 0 0 1 0 0 0 1\n"
        << "S_rect_01: " << calib.image_width << " " << calib.image_height << "\n";
  WriteTextFileAtomic(calib_dir + "/perspective.txt", persp.str());
  // The unrectified camera is the rectified one (R_rect_00 = identity); the IMU/GPS "pose"
  // frame is put at the Velodyne.
  const Rigid3d velo_from_cam0 = calib.cam0_from_velo.Inverse();
  WriteTextFileAtomic(calib_dir + "/calib_cam_to_velo.txt",
                      Format3x4(velo_from_cam0).substr(1) + "\n");
  WriteTextFileAtomic(calib_dir + "/calib_cam_to_pose.txt",
                      "image_00:" + Format3x4(velo_from_cam0) + "\n");
  std::string stamps, cam_poses, imu_poses;
  for (size_t i = 0; i < gt.size(); ++i) {
    stamps +=
        Kitti360Timestamp(gt.timestamps.empty() ? 0.1 * gt.frames[i] : gt.timestamps[i]) + "\n";
    const Rigid3d& w = gt.world_from_cam[i];
    cam_poses += std::to_string(gt.frames[i]) + Format3x4(w) + " 0 0 0 1\n";
    imu_poses += std::to_string(gt.frames[i]) + Format3x4(w * velo_from_cam0.Inverse()) + "\n";
  }
  JVL_CHECK(gt.frames.front() == 0, "KITTI-360 layout: the ground truth must start at frame 0");
  WriteTextFileAtomic(layout.SequenceDir() + "/velodyne_points/timestamps.txt", stamps);
  WriteTextFileAtomic(image_dir + "/timestamps.txt", stamps);
  WriteTextFileAtomic(layout.PosesPath(), cam_poses);
  WriteTextFileAtomic(poses_dir + "/poses.txt", imu_poses);
}

// x y z roll pitch yaw of a rigid transform (the SDK's convention, io/oxford.h), as text.
std::vector<std::string> FormatXyzRpy(const Rigid3d& t) {
  std::vector<std::string> out;
  for (double v : OxfordXyzRpy(t)) out.push_back(FormatDouble(v, "%.17g"));
  return out;
}

std::string JoinSpaced(const std::vector<std::string>& values) {
  std::string out;
  for (const auto& v : values) out += (out.empty() ? "" : " ") + v;
  return out;
}

void WriteOxfordMetadata(const SequenceLayout& layout, const Calibration& calib,
                         const Trajectory& gt) {
  JVL_CHECK(layout.times.size() == gt.size() && gt.frames.front() == 0,
            "Oxford layout: every frame's time from frame 0 is needed");
  const std::string dir = layout.SequenceDir();
  for (const std::string& d : {dir + "/stereo/centre", dir + "/velodyne_left", dir + "/gps",
                               layout.root + "/models", layout.root + "/extrinsics"})
    CreateDirectories(d);
  // The vehicle frame is camera 0's base frame: x forward, y right, z down.
  Eigen::Matrix3d vehicle_from_optical;
  vehicle_from_optical << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  const PinholeCamera cam = calib.Camera(0);
  std::string model = FormatDouble(cam.fx, "%.17g") + " " + FormatDouble(cam.fy, "%.17g") + " " +
                      FormatDouble(cam.cx, "%.17g") + " " + FormatDouble(cam.cy, "%.17g") + "\n";
  model += "0 0 1 0\n1 0 0 0\n0 1 0 0\n0 0 0 1\n";  // G_camera_image = vehicle_from_optical
  WriteTextFileAtomic(layout.root + "/models/stereo_narrow_left.txt", model);
  const int w = calib.image_width, h = calib.image_height;
  JVL_CHECK(w > 0 && h > 0, "Oxford layout: the image size is needed");
  std::string lut(16 * static_cast<size_t>(w) * h, '\0');
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const double u = c, v = r;
      const size_t i = static_cast<size_t>(r) * w + c;
      std::memcpy(lut.data() + 8 * i, &u, 8);
      std::memcpy(lut.data() + 8 * (static_cast<size_t>(w) * h + i), &v, 8);
    }
  }
  WriteTextFileAtomic(layout.root + "/models/stereo_narrow_left_distortion_lut.bin", lut);
  const Rigid3d vehicle_from_cam0(vehicle_from_optical, Eigen::Vector3d::Zero());
  WriteTextFileAtomic(layout.root + "/extrinsics/velodyne_left.txt",
                      JoinSpaced(FormatXyzRpy(vehicle_from_cam0 * calib.cam0_from_velo)) + "\n");
  WriteTextFileAtomic(layout.root + "/extrinsics/ins.txt", "0 0 0 0 0 0\n");
  WriteTextFileAtomic(layout.root + "/extrinsics/stereo.txt", "0 0 0 0 0 0\n");
  std::string stamps;
  std::string ins =
      "timestamp,ins_status,latitude,longitude,altitude,northing,easting,down,utm_zone,"
      "velocity_north,velocity_east,velocity_down,roll,pitch,yaw\n";
  const Rigid3d cam0_from_vehicle = vehicle_from_cam0.Inverse();
  for (size_t i = 0; i < gt.size(); ++i) {
    const int64_t t = layout.OxfordTime(gt.frames[i]);
    stamps += std::to_string(t) + " 1\n";
    // The INS at the vehicle origin, in a north-east-down world that is the vehicle frame of
    // frame 0 (level poses stay far from the Euler angles' singularity at pitch +-90 deg):
    // P_ins = vehicle_from_cam0 * world_from_cam0 * cam0_from_vehicle.
    const Rigid3d p = vehicle_from_cam0 * gt.world_from_cam[i] * cam0_from_vehicle;
    const std::vector<std::string> v = FormatXyzRpy(p);
    ins += std::to_string(t) + ",INS_SOLUTION_GOOD,0,0,0," + v[0] + "," + v[1] + "," + v[2] +
           ",30U,0,0,0," + v[3] + "," + v[4] + "," + v[5] + "\n";
  }
  WriteTextFileAtomic(dir + "/stereo.timestamps", stamps);
  WriteTextFileAtomic(dir + "/velodyne_left.timestamps", stamps);
  WriteTextFileAtomic(layout.PosesPath(), ins);
}

}  // namespace

void WriteSequenceScan(const SequenceLayout& layout, int64_t frame, const PointCloud& cloud) {
  if (layout.layout != SimLayout::kOxford) {
    WriteVelodyneBin(layout.ScanPath(frame), cloud);
    return;
  }
  const size_t n = cloud.size();
  std::vector<float> v(4 * n);
  for (size_t i = 0; i < n; ++i) {
    v[i] = static_cast<float>(cloud.points[i].x());
    v[n + i] = static_cast<float>(cloud.points[i].y());
    v[2 * n + i] = static_cast<float>(cloud.points[i].z());
    v[3 * n + i] = cloud.intensity.empty() ? 0.0f : 255.0f * cloud.intensity[i];
  }
  std::string bytes(16 * n, '\0');
  std::memcpy(bytes.data(), v.data(), bytes.size());
  WriteTextFileAtomic(layout.ScanPath(frame), bytes);
}

void WriteSequenceMetadata(const SequenceLayout& layout, const Calibration& calib,
                           const Trajectory& gt) {
  gt.Check("ground truth");
  if (layout.layout == SimLayout::kOxford) {
    WriteOxfordMetadata(layout, calib, gt);
    return;
  }
  if (layout.layout == SimLayout::kKitti360) {
    WriteKitti360Metadata(layout, calib, gt);
    return;
  }
  CreateDirectories(layout.SequenceDir());
  WriteKittiCalibration(layout.SequenceDir() + "/calib.txt", calib);
  WriteKittiTimes(layout.SequenceDir() + "/times.txt", gt.timestamps);
  WriteTrajectoryKitti(layout.PosesPath(), gt);
}

std::string FormatGtVpsCsv(const std::vector<GtVpRow>& rows) {
  std::ostringstream os;
  os << "frame,kind,group,dx,dy,dz,u,v,in_image,buildings\n";
  for (const GtVpRow& r : rows) {
    os << r.frame << ',' << r.kind << ',' << r.group << ',' << FormatDouble(r.direction.x(), "%.9f")
       << ',' << FormatDouble(r.direction.y(), "%.9f") << ','
       << FormatDouble(r.direction.z(), "%.9f") << ',' << FormatDouble(r.uv.x(), "%.4f") << ','
       << FormatDouble(r.uv.y(), "%.4f") << ',' << (r.in_image ? 1 : 0) << ',' << r.buildings
       << '\n';
  }
  return os.str();
}

void WriteGtVpsCsv(const std::string& path, const std::vector<GtVpRow>& rows) {
  WriteTextFileAtomic(path, FormatGtVpsCsv(rows));
}

std::vector<GtVpRow> ReadGtVpsCsv(const std::string& path) {
  std::istringstream in(ReadTextFile(path));
  std::string line;
  std::getline(in, line);
  JVL_CHECK(line.rfind("frame,kind,group", 0) == 0, path << ": not a ground-truth VP CSV");
  std::vector<GtVpRow> rows;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    JVL_CHECK(f.size() == 10, path << ":" << line_no << ": expected 10 fields, got " << f.size());
    auto num = [](const std::string& s) {
      return s == "nan" ? std::numeric_limits<double>::quiet_NaN() : std::stod(s);
    };
    GtVpRow r;
    try {
      r.frame = std::stoll(f[0]);
      r.kind = f[1];
      r.group = std::stoi(f[2]);
      r.direction = Eigen::Vector3d(num(f[3]), num(f[4]), num(f[5]));
      r.uv = Eigen::Vector2d(num(f[6]), num(f[7]));
      r.in_image = f[8] == "1";
      r.buildings = std::stoi(f[9]);
    } catch (const std::exception&) {
      JVL_THROW(path << ":" << line_no << ": malformed number");
    }
    rows.push_back(r);
  }
  return rows;
}

void WriteGtVpsJson(const std::string& path, const PinholeCamera& camera,
                    const std::vector<int64_t>& frames, const std::vector<GtVpRow>& rows,
                    const Provenance& provenance) {
  nlohmann::json body;
  body["camera"] = {camera.fx, camera.fy, camera.cx, camera.cy, camera.width, camera.height};
  body["frames"] = frames;
  nlohmann::json vps = nlohmann::json::array();
  for (const GtVpRow& r : rows) {
    nlohmann::json uv = nlohmann::json::array();
    if (std::isfinite(r.uv.x())) {
      uv = {r.uv.x(), r.uv.y()};
    } else {
      uv = nullptr;
    }
    vps.push_back({{"frame", r.frame},
                   {"kind", r.kind},
                   {"group", r.group},
                   {"direction", {r.direction.x(), r.direction.y(), r.direction.z()}},
                   {"uv", uv},
                   {"in_image", r.in_image},
                   {"buildings", r.buildings}});
  }
  body["vps"] = vps;
  WriteJsonArtifact(path, "sim_vps", 1, body, provenance);
}

void WriteSceneJson(const std::string& path, const nlohmann::json& scene,
                    const Provenance& provenance) {
  WriteJsonArtifact(path, "sim_scene", 1, scene, provenance);
}

}  // namespace jvl::io
