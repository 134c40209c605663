#include "io/sim_io.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/check.h"
#include "io/files.h"
#include "io/kitti.h"
#include "io/trajectory_io.h"

namespace jvl::io {
namespace {

std::string Numbered(int64_t frame, const char* ext) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06lld%s", static_cast<long long>(frame), ext);
  return buf;
}

std::string FormatDouble(double v, const char* fmt) {
  if (!std::isfinite(v)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

}  // namespace

std::string KittiLayout::SequenceDir() const { return root + "/sequences/" + sequence; }
std::string KittiLayout::ScanPath(int64_t f) const {
  return SequenceDir() + "/velodyne/" + Numbered(f, ".bin");
}
std::string KittiLayout::ImagePath(int64_t f) const {
  return SequenceDir() + "/image_0/" + Numbered(f, ".png");
}
std::string KittiLayout::PosesPath() const { return root + "/poses/" + sequence + ".txt"; }
std::string KittiLayout::SimDir() const { return SequenceDir() + "/sim"; }

void WriteKittiSequenceMetadata(const KittiLayout& layout, const Calibration& calib,
                                const Trajectory& gt) {
  gt.Check("ground truth");
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
