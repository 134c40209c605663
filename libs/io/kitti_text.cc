#include "io/kitti_text.h"

#include <cmath>
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

}  // namespace jvl::io
