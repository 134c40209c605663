#include "io/kitti_text.h"

#include <cmath>
#include <cstdio>
#include <fstream>

#include "core/check.h"
#include "core/strings.h"

namespace jvl::io {

std::map<std::string, std::vector<double>> ReadKeyValues(const std::string& path,
                                                         const std::string& hint) {
  std::ifstream in(path);
  JVL_CHECK(in.good(), path << ": calibration file not found" << (hint.empty() ? "" : " (") << hint
                            << (hint.empty() ? "" : ")"));
  std::map<std::string, std::vector<double>> out;
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key(Trim(std::string_view(line).substr(0, colon)));
    std::vector<double> values;
    bool numeric = true;
    for (auto tok : SplitWhitespace(std::string_view(line).substr(colon + 1))) {
      const auto v = ParseDouble(tok);
      if (!v) {
        numeric = false;
        break;
      }
      values.push_back(*v);
    }
    if (numeric) out[key] = values;
  }
  return out;
}

const std::vector<double>& RequireValues(const std::map<std::string, std::vector<double>>& kv,
                                         const std::string& key, size_t n,
                                         const std::string& path) {
  const auto it = kv.find(key);
  JVL_CHECK(it != kv.end() && it->second.size() == n,
            path << ": missing or malformed '" << key << "' (" << n << " numbers expected)");
  return it->second;
}

Rigid3d RigidFromRT(const std::vector<double>& r, const std::vector<double>& t,
                    const std::string& path) {
  Eigen::Matrix<double, 3, 4> m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = r[i];
  m.col(3) = Eigen::Vector3d(t[0], t[1], t[2]);
  JVL_CHECK(m.allFinite(), path << ": not a rigid transform (a value is not finite)");
  const double deviation = Rigid3d::RotationDeviation(m.leftCols<3>());
  JVL_CHECK(deviation < 1e-2,
            path << ": not a rigid transform (rotation part off by " << deviation << ")");
  return Rigid3d::FromMatrix(m);
}

Rigid3d RigidFrom3x4(const std::vector<double>& m, const std::string& path) {
  JVL_CHECK(m.size() == 12, path << ": " << m.size() << " numbers, expected a 3 x 4 matrix (12)");
  return RigidFromRT({m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]}, {m[3], m[7], m[11]},
                     path);
}

std::vector<std::string> ReadLines(const std::string& path) {
  std::ifstream in(path);
  JVL_CHECK(in.good(), path << ": not found");
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (!Trim(line).empty()) lines.push_back(line);
  }
  return lines;
}

std::vector<double> ReadNumberFile(const std::string& path) {
  std::vector<double> values;
  for (const auto& line : ReadLines(path)) {
    for (auto tok : SplitWhitespace(line)) {
      const auto v = ParseDouble(tok);
      JVL_CHECK(v && std::isfinite(*v), path << ": bad value '" << tok << "'");
      values.push_back(*v);
    }
  }
  return values;
}

std::string ZeroPaddedName(int64_t frame, int digits, const char* ext) {
  char name[48];
  std::snprintf(name, sizeof(name), "%0*lld%s", digits, static_cast<long long>(frame), ext);
  return name;
}

Rigid3d ReadRectification(const std::map<std::string, std::vector<double>>& kv,
                          const std::string& path, int required, int optional, Calibration* calib,
                          std::string* size_source) {
  for (int i = 0; i < required + optional; ++i) {
    const std::string key = "P_rect_0" + std::to_string(i);
    if (i >= required && !kv.count(key)) continue;
    const auto& v = RequireValues(kv, key, 12, path);
    for (int k = 0; k < 12; ++k) {
      JVL_CHECK(std::isfinite(v[k]), path << ": " << key << " has a non-finite value");
      calib->P[i](k / 4, k % 4) = v[k];
    }
  }
  const Rigid3d rect_from_cam0 =
      RigidFromRT(RequireValues(kv, "R_rect_00", 9, path), {0, 0, 0}, path);
  const auto& size = RequireValues(kv, "S_rect_00", 2, path);
  JVL_CHECK(size[0] >= 1 && size[0] <= 1e5 && size[1] >= 1 && size[1] <= 1e5,
            path << ": S_rect_00 is not an image size");
  calib->image_width = static_cast<int>(size[0]);
  calib->image_height = static_cast<int>(size[1]);
  *size_source = path + ", S_rect_00";
  return rect_from_cam0;
}

}  // namespace jvl::io
