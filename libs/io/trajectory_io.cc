#include "io/trajectory_io.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/check.h"
#include "core/strings.h"
#include "io/global_io.h"
#include "io/local_io.h"
#include "io/odometry_io.h"
#include "io/visual_io.h"

namespace jvl::io {

TrajectoryFormat ParseTrajectoryFormat(const std::string& name) {
  if (name == "auto") return TrajectoryFormat::kAuto;
  if (name == "h5") return TrajectoryFormat::kH5;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "kitti-indexed") return TrajectoryFormat::kKittiIndexed;
  if (name == "tum") return TrajectoryFormat::kTum;
  JVL_THROW("unknown trajectory format '" << name << "' (auto, h5, kitti, kitti-indexed, tum)");
}

std::string ToString(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kAuto: return "auto";
    case TrajectoryFormat::kH5: return "h5";
    case TrajectoryFormat::kKitti: return "kitti";
    case TrajectoryFormat::kKittiIndexed: return "kitti-indexed";
    case TrajectoryFormat::kTum: return "tum";
  }
  return "?";
}

namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The one rule of every trajectory reader for rotations that are not exactly unit quaternions
// or orthonormal matrices: a deviation up to kSilentDeviation (the rounding of text written
// with 7+ significant digits; KITTI's ground truth deviates by up to 1.5e-7) is removed
// without a word; up to kMaxDeviation (text with few digits, e.g. 4 decimals) it is removed
// with one warning per file; beyond, the file is rejected naming the line or frame.
constexpr double kSilentDeviation = 1e-6;
constexpr double kMaxDeviation = 1e-2;

class RotationRule {
 public:
  explicit RotationRule(std::string file) : file_(std::move(file)) {}
  ~RotationRule() {
    if (count_ > 0) {
      spdlog::warn(
          "{}: {} rotation(s) not unit to {} (largest deviation {:.2g}); normalised "
          "(docs/robustness.md)",
          file_, count_, kSilentDeviation, largest_);
    }
  }
  // `deviation`: |norm - 1| of a quaternion, or max |R^T R - I| of a matrix.
  void Check(double deviation, const std::string& where, const std::string& what) {
    JVL_CHECK(std::isfinite(deviation) && deviation <= kMaxDeviation,
              where << ": " << what << " (deviation " << deviation << " > " << kMaxDeviation
                    << ")");
    if (deviation > kSilentDeviation) {
      ++count_;
      largest_ = std::max(largest_, deviation);
    }
  }

 private:
  std::string file_;
  int64_t count_ = 0;
  double largest_ = 0;
};

double OrthonormalityDeviation(const Eigen::Matrix3d& r) {
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
}

// Schema versions whose "trajectory" group this reader understands.
void CheckTrajectorySchema(const H5Reader& reader) {
  static const std::map<std::string, int> kKnown = {
      {"trajectory", 1},
      {"odometry", kOdometrySchemaVersion},
      {"global", kGlobalSchemaVersion},
      {"local", kLocalSchemaVersion},
      {"visual", kVisualSchemaVersion}};
  const auto it = kKnown.find(reader.schema());
  if (it == kKnown.end()) return;  // another artifact: "holds no trajectory" below if so
  JVL_CHECK(reader.schema_version() == it->second,
            reader.path() << ": expected schema '" << it->first << "' version " << it->second
                          << ", found '" << reader.schema() << "' version "
                          << reader.schema_version());
}

}  // namespace

Trajectory ReadTrajectoryText(std::istream& in, TrajectoryFormat format, const std::string& name) {
  Trajectory t;
  RotationRule rotations(name);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view body = Trim(line);
    if (body.empty() || body.front() == '#') continue;
    const auto tokens = SplitWhitespace(body, /*comma=*/true);
    if (format == TrajectoryFormat::kAuto) {
      if (tokens.size() == 12) format = TrajectoryFormat::kKitti;
      else if (tokens.size() == 13) format = TrajectoryFormat::kKittiIndexed;
      else if (tokens.size() == 8) format = TrajectoryFormat::kTum;
      else
        JVL_THROW(name << ":" << line_no << ": " << tokens.size()
                       << " columns; expected 12 (KITTI), 13 (frame + KITTI) or 8 (TUM)");
    }
    const size_t expected = format == TrajectoryFormat::kKitti          ? 12
                            : format == TrajectoryFormat::kKittiIndexed ? 13
                                                                        : 8;
    JVL_CHECK(tokens.size() == expected, name << ":" << line_no << ": " << tokens.size()
                                              << " columns, expected " << expected << " ("
                                              << ToString(format) << ")");
    std::vector<double> v(tokens.size());
    for (size_t i = 0; i < tokens.size(); ++i) {
      const auto d = ParseDouble(tokens[i]);
      JVL_CHECK(d && std::isfinite(*d), name << ":" << line_no << ": bad number '" << tokens[i]
                                             << "' in column " << i + 1);
      v[i] = *d;
    }
    if (format == TrajectoryFormat::kTum) {
      const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      rotations.Check(std::abs(q.norm() - 1.0), name + ":" + std::to_string(line_no),
                      "quaternion is not unit (norm " + FormatDouble(q.norm()) + ")");
      JVL_CHECK(t.empty() || v[0] > t.timestamps.back(),
                name << ":" << line_no << ": timestamp " << tokens[0]
                     << " does not increase (previous " << FormatDouble(t.timestamps.back())
                     << ")");
      t.Append(static_cast<int64_t>(t.size()),
               Rigid3d(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3])), v[0]);
      continue;
    }
    const size_t off = format == TrajectoryFormat::kKittiIndexed ? 1 : 0;
    int64_t frame = static_cast<int64_t>(t.size());
    if (off == 1) {
      JVL_CHECK(v[0] >= 0 && v[0] < 1e15 && v[0] == std::floor(v[0]),
                name << ":" << line_no << ": frame index '" << tokens[0] << "' is not an integer");
      frame = static_cast<int64_t>(v[0]);
    }
    Eigen::Matrix<double, 3, 4> m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) m(r, c) = v[off + 4 * r + c];
    const double det = m.leftCols<3>().determinant();
    JVL_CHECK(det > 0, name << ":" << line_no << ": rotation part is not a rotation (det "
                            << det << ")");
    rotations.Check(std::max(OrthonormalityDeviation(m.leftCols<3>()), std::abs(det - 1.0)),
                    name + ":" + std::to_string(line_no),
                    "rotation part is not a rotation (det " + FormatDouble(det) + ")");
    JVL_CHECK(t.empty() || frame > t.frames.back(),
              name << ":" << line_no << ": frame " << frame << " does not increase");
    t.Append(frame, Rigid3d::FromMatrix(m));
  }
  JVL_CHECK(!t.empty(), name << ": no poses found");
  return t;
}

Trajectory ReadTrajectory(const std::string& path, TrajectoryFormat format) {
  JVL_CHECK(FileExists(path), path << ": trajectory file not found");
  if (format == TrajectoryFormat::kH5 || (format == TrajectoryFormat::kAuto && EndsWith(path, ".h5"))) {
    H5Reader reader(path, "", 0);
    CheckTrajectorySchema(reader);
    JVL_CHECK(reader.Has("trajectory/frames"),
              path << ": artifact '" << reader.schema() << "' holds no trajectory");
    return ReadTrajectoryGroup(reader, "trajectory");
  }
  std::ifstream in(path);
  JVL_CHECK(in.good(), path << ": cannot open");
  Trajectory t = ReadTrajectoryText(in, format, path);
  t.Check(path.c_str());
  return t;
}

std::string FormatTrajectoryKitti(const Trajectory& t, bool with_index) {
  std::string out;
  for (size_t i = 0; i < t.size(); ++i) {
    const auto m = t.world_from_cam[i].Matrix3x4();
    if (with_index) out += std::to_string(t.frames[i]) + " ";
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        out += FormatDouble(m(r, c));
        out += (r == 2 && c == 3) ? '\n' : ' ';
      }
  }
  return out;
}

std::string FormatTrajectoryTum(const Trajectory& t) {
  std::string out;
  for (size_t i = 0; i < t.size(); ++i) {
    const double stamp = t.has_timestamps() ? t.timestamps[i] : static_cast<double>(t.frames[i]);
    const auto a = t.world_from_cam[i].ToArray();
    out += FormatDouble(stamp);
    for (int k : {4, 5, 6, 0, 1, 2, 3}) out += " " + FormatDouble(a[k]);
    out += '\n';
  }
  return out;
}

void WriteTrajectoryKitti(const std::string& path, const Trajectory& t, bool force_index) {
  bool contiguous = true;
  for (size_t i = 0; i < t.size(); ++i) contiguous &= t.frames[i] == static_cast<int64_t>(i);
  WriteTextFileAtomic(path, FormatTrajectoryKitti(t, force_index || !contiguous));
}

void WriteTrajectoryTum(const std::string& path, const Trajectory& t) {
  WriteTextFileAtomic(path, FormatTrajectoryTum(t));
}

void WriteTrajectoryGroup(H5Writer& writer, const std::string& group, const Trajectory& t) {
  t.Check(group.c_str());
  std::vector<double> poses;
  poses.reserve(7 * t.size());
  for (const auto& p : t.world_from_cam) {
    const auto a = p.ToArray();
    poses.insert(poses.end(), a.begin(), a.end());
  }
  writer.WriteArray(group + "/frames", t.frames);
  writer.WriteArray(group + "/poses", poses, {static_cast<int64_t>(t.size()), 7});
  if (t.has_timestamps()) writer.WriteArray(group + "/timestamps", t.timestamps);
}

Trajectory ReadTrajectoryGroup(const H5Reader& reader, const std::string& group) {
  Trajectory t;
  t.frames = reader.ReadArray<int64_t>(group + "/frames");
  const auto poses = reader.ReadArray<double>(group + "/poses", 7);
  JVL_CHECK(poses.size() == 7 * t.frames.size(),
            reader.path() << ": " << group << " has " << t.frames.size() << " frames but "
                          << poses.size() / 7 << " poses");
  RotationRule rotations(reader.path());
  for (size_t i = 0; i < t.frames.size(); ++i) {
    for (int k = 0; k < 7; ++k) {
      JVL_CHECK(std::isfinite(poses[7 * i + k]), reader.path() << ": " << group << " pose of frame "
                                                               << t.frames[i] << " is not finite");
    }
    const double* a = &poses[7 * i];
    const double norm = Eigen::Vector4d(a[0], a[1], a[2], a[3]).norm();
    rotations.Check(std::abs(norm - 1.0),
                    reader.path() + ": " + group + " frame " + std::to_string(t.frames[i]),
                    "quaternion is not unit (norm " + FormatDouble(norm) + ")");
    const Rigid3d pose = Rigid3d::FromArray(a);  // Rigid3d normalises its quaternion
    t.world_from_cam.push_back(pose);
  }
  if (reader.Has(group + "/timestamps")) t.timestamps = reader.ReadArray<double>(group + "/timestamps");
  t.Check((reader.path() + ":" + group).c_str());
  return t;
}

void WriteTrajectoryArtifact(const std::string& path, const Trajectory& t,
                             const Provenance& provenance) {
  H5Writer writer(path, "trajectory", 1);
  WriteTrajectoryGroup(writer, "trajectory", t);
  writer.Commit(provenance);
}

}  // namespace jvl::io
