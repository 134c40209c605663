#include "io/kitti.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/check.h"
#include "core/strings.h"
#include "io/files.h"

namespace jvl::io {

PointCloud ParseVelodyneBin(const std::string& bytes, const std::string& name, size_t* dropped,
                            size_t* out_of_range) {
  JVL_CHECK(bytes.size() % 16 == 0, name << ": size " << bytes.size()
                                         << " bytes is not a multiple of 16 (x, y, z, reflectance "
                                            "as float32): truncated or not a KITTI scan");
  const size_t n = bytes.size() / 16;
  PointCloud cloud;
  cloud.points.reserve(n);
  cloud.intensity.reserve(n);
  size_t bad = 0, far = 0;
  constexpr float kMaxRange2 = static_cast<float>(kMaxScanRange * kMaxScanRange);
  for (size_t i = 0; i < n; ++i) {
    float v[4];
    std::memcpy(v, bytes.data() + 16 * i, 16);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
      ++bad;
      continue;
    }
    // In double: a float square of 1e30 overflows to infinity (still "far", but say why).
    const double r2 = static_cast<double>(v[0]) * v[0] + static_cast<double>(v[1]) * v[1] +
                      static_cast<double>(v[2]) * v[2];
    if (r2 > kMaxRange2) {
      ++far;
      continue;
    }
    cloud.points.emplace_back(v[0], v[1], v[2]);
    cloud.intensity.push_back(std::isfinite(v[3]) ? v[3] : 0.0f);
  }
  if (dropped) *dropped = bad;
  if (out_of_range) *out_of_range = far;
  return cloud;
}

PointCloud ReadVelodyneBin(const std::string& path, size_t* dropped, size_t* out_of_range) {
  JVL_CHECK(FileExists(path), path << ": scan file not found");
  JVL_CHECK(!IsDirectory(path), path << ": is a folder, not a scan file");
  return ParseVelodyneBin(ReadTextFile(path), path, dropped, out_of_range);
}

void WriteVelodyneBin(const std::string& path, const PointCloud& cloud) {
  std::string bytes(16 * cloud.size(), '\0');
  for (size_t i = 0; i < cloud.size(); ++i) {
    const float v[4] = {static_cast<float>(cloud.points[i].x()),
                        static_cast<float>(cloud.points[i].y()),
                        static_cast<float>(cloud.points[i].z()),
                        cloud.intensity.empty() ? 0.0f : cloud.intensity[i]};
    std::memcpy(bytes.data() + 16 * i, v, 16);
  }
  WriteTextFileAtomic(path, bytes);
}

Calibration ParseKittiCalibration(std::istream& in, const std::string& name) {
  std::map<std::string, Eigen::Matrix<double, 3, 4>> entries;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view body = Trim(line);
    if (body.empty()) continue;
    const auto colon = body.find(':');
    JVL_CHECK(colon != std::string_view::npos,
              name << ":" << line_no << ": expected 'KEY: values', got '" << body << "'");
    const std::string key(Trim(body.substr(0, colon)));
    const auto tokens = SplitWhitespace(body.substr(colon + 1));
    const bool required =
        key == "Tr" || (key.size() == 2 && key[0] == 'P' && key[1] >= '0' && key[1] <= '3');
    JVL_CHECK(!required || tokens.size() == 12, name << ":" << line_no << ": " << key << " has "
                                                     << tokens.size() << " numbers, expected 12");
    if (tokens.size() != 12) continue;  // Other entries (e.g. S_rect sizes) are not 3x4.
    Eigen::Matrix<double, 3, 4> m;
    for (int i = 0; i < 12; ++i) {
      const auto v = ParseDouble(tokens[i]);
      JVL_CHECK(v && std::isfinite(*v),
                name << ":" << line_no << ": bad number '" << tokens[i] << "' in " << key);
      m(i / 4, i % 4) = *v;
    }
    entries[key] = m;
  }
  Calibration calib;
  for (int i = 0; i < 4; ++i) {
    const std::string key = "P" + std::to_string(i);
    JVL_CHECK(entries.count(key), name << ": missing " << key << " (3x4 projection matrix)");
    calib.P[i] = entries[key];
  }
  JVL_CHECK(entries.count("Tr"), name << ": missing Tr (velodyne to cam0, 3x4)");
  const double deviation = Rigid3d::RotationDeviation(entries["Tr"].leftCols<3>());
  JVL_CHECK(deviation < 1e-2,
            name << ": Tr is not a rigid transform (rotation part off by " << deviation << ")");
  calib.cam0_from_velo = Rigid3d::FromMatrix(entries["Tr"]);
  try {
    calib.Camera(0).Check();
  } catch (const Error& e) {
    JVL_THROW(name << ": P0: " << e.message());
  }
  return calib;
}

Calibration ReadKittiCalibration(const std::string& path) {
  std::ifstream in(path);
  JVL_CHECK(in.good(), path << ": calibration file not found");
  return ParseKittiCalibration(in, path);
}

namespace {
std::string FormatRow(const Eigen::Matrix<double, 3, 4>& m) {
  std::string out;
  for (int i = 0; i < 12; ++i) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.12e", m(i / 4, i % 4));
    out += (i ? " " : "") + std::string(buf);
  }
  return out;
}
}  // namespace

void WriteKittiCalibration(const std::string& path, const Calibration& calib) {
  std::string out;
  for (int i = 0; i < 4; ++i) out += "P" + std::to_string(i) + ": " + FormatRow(calib.P[i]) + "\n";
  out += "Tr: " + FormatRow(calib.cam0_from_velo.Matrix3x4()) + "\n";
  WriteTextFileAtomic(path, out);
}

std::vector<double> ParseKittiTimes(std::istream& in, const std::string& name) {
  std::vector<double> times;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto body = Trim(line);
    if (body.empty()) continue;
    const auto v = ParseDouble(body);
    JVL_CHECK(v && std::isfinite(*v), name << ":" << line_no << ": bad timestamp '" << body << "'");
    JVL_CHECK(times.empty() || *v > times.back(),
              name << ":" << line_no << ": timestamp " << body << " does not increase (previous "
                   << FormatDouble(times.back()) << ")");
    times.push_back(*v);
  }
  return times;
}

std::vector<double> ReadKittiTimes(const std::string& path) {
  std::ifstream in(path);
  JVL_CHECK(in.good(), path << ": times file not found");
  return ParseKittiTimes(in, path);
}

void WriteKittiTimes(const std::string& path, const std::vector<double>& times) {
  std::string out;
  for (double t : times) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.6e\n", t);
    out += buf;
  }
  WriteTextFileAtomic(path, out);
}

namespace {

// A PNG starts with its 8-byte signature and ends with the 12-byte IEND chunk. Checking both
// before decoding names a truncated file clearly, and keeps libpng from printing its own error.
constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr unsigned char kPngIend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};

bool LooksLikeCompletePng(const std::string& bytes) {
  return bytes.size() >= 20 && std::memcmp(bytes.data(), kPngSignature, 8) == 0 &&
         std::memcmp(bytes.data() + bytes.size() - 12, kPngIend, 12) == 0;
}

}  // namespace

cv::Mat ReadImage(const std::string& path, bool grayscale) {
  JVL_CHECK(FileExists(path), path << ": image not found");
  const std::string bytes = ReadTextFile(path);
  JVL_CHECK(!bytes.empty(), path << ": empty image file");
  JVL_CHECK(bytes.size() < (1u << 31), path << ": image file too large");
  const bool png = bytes.size() >= 4 && bytes.compare(1, 3, "PNG") == 0;
  JVL_CHECK(!png || LooksLikeCompletePng(bytes),
            path << ": truncated PNG (no IEND chunk at the end)");
  const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
  cv::Mat image;
  try {
    image = cv::imdecode(buffer, grayscale ? cv::IMREAD_GRAYSCALE : cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    image.release();  // OpenCV's own assertion text would not name the file.
  }
  JVL_CHECK(!image.empty(), path << ": image does not decode (damaged or not an image)");
  return image;
}

void WriteImage(const std::string& path, const cv::Mat& image) {
  // OpenCV picks the encoder from the extension, so keep it on the temporary name.
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? ".png" : path.substr(dot);
  AtomicWrite(path, [&](const std::string& tmp) {
    std::vector<uchar> buffer;
    JVL_CHECK(cv::imencode(ext, image, buffer), path << ": cannot encode image");
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(buffer.data()),
              static_cast<std::streamsize>(buffer.size()));
    JVL_CHECK(out.good(), tmp << ": write failed");
  });
}

}  // namespace jvl::io
