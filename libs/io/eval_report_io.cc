#include "io/eval_report_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/check.h"
#include "core/strings.h"

namespace jvl::io {

namespace {

bool HasSuffix(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Column count of the first data line (0 if none).
size_t FirstLineColumns(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const std::string_view body = Trim(line);
    if (body.empty() || body.front() == '#') continue;
    return SplitWhitespace(body, /*comma=*/true).size();
  }
  return 0;
}

}  // namespace

PoseMatrices ParsePoseMatricesKitti(std::istream& in, const std::string& name) {
  PoseMatrices m;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view body = Trim(line);
    if (body.empty() || body.front() == '#') continue;
    const auto tokens = SplitWhitespace(body, /*comma=*/true);
    JVL_CHECK(tokens.size() == 12 || tokens.size() == 13,
              name << ":" << line_no << ": " << tokens.size()
                   << " columns; expected 12 (KITTI) or 13 (frame + KITTI)");
    double v[13];
    for (size_t i = 0; i < tokens.size(); ++i) {
      const auto d = ParseDouble(tokens[i]);
      JVL_CHECK(d && std::isfinite(*d),
                name << ":" << line_no << ": bad number '" << tokens[i] << "' in column " << i + 1);
      v[i] = *d;
    }
    const size_t off = tokens.size() - 12;
    int64_t frame = static_cast<int64_t>(m.frames.size());
    if (off == 1) {
      JVL_CHECK(v[0] >= 0 && v[0] < 1e15 && v[0] == std::floor(v[0]),
                name << ":" << line_no << ": frame index '" << tokens[0] << "' is not an integer");
      frame = static_cast<int64_t>(v[0]);
    }
    JVL_CHECK(m.frames.empty() || frame > m.frames.back(),
              name << ":" << line_no << ": frame " << frame << " does not increase");
    Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) pose(r, c) = v[off + 4 * r + c];
    const double det = pose.topLeftCorner<3, 3>().determinant();
    JVL_CHECK(std::abs(det - 1.0) < 1e-2,
              name << ":" << line_no << ": rotation part is not a rotation (det " << det << ")");
    m.frames.push_back(frame);
    m.poses.push_back(pose);
  }
  JVL_CHECK(!m.frames.empty(), name << ": no poses found");
  return m;
}

PoseMatrices ReadPoseMatrices(const std::string& path, TrajectoryFormat format) {
  JVL_CHECK(FileExists(path), path << ": file not found");
  bool kitti_text = format == TrajectoryFormat::kKitti || format == TrajectoryFormat::kKittiIndexed;
  std::string text;
  if (format == TrajectoryFormat::kAuto && !HasSuffix(path, ".h5")) {
    text = ReadTextFile(path);
    const size_t cols = FirstLineColumns(text);
    kitti_text = cols == 12 || cols == 13;
  }
  if (kitti_text) {
    if (text.empty()) text = ReadTextFile(path);
    std::istringstream in(text);
    return ParsePoseMatricesKitti(in, path);
  }
  const Trajectory t = ReadTrajectory(path, format);
  PoseMatrices m;
  m.frames = t.frames;
  m.timestamps = t.timestamps;
  for (const Rigid3d& pose : t.world_from_cam) m.poses.push_back(pose.Matrix4());
  return m;
}

std::vector<std::string> ListTrajectoryFiles(const std::string& dir) {
  namespace fs = std::filesystem;
  JVL_CHECK(IsDirectory(dir), dir << ": not a folder");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && (HasSuffix(name, ".txt") || HasSuffix(name, ".h5"))) {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

void WriteMetricsReport(const std::string& path, const nlohmann::json& body,
                        const Provenance& provenance) {
  WriteJsonArtifact(path, kMetricsSchema, kMetricsSchemaVersion, body, provenance);
}

nlohmann::json ReadMetricsReport(const std::string& path) {
  return ReadJsonArtifact(path, kMetricsSchema, kMetricsSchemaVersion);
}

}  // namespace jvl::io
