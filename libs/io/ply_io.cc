#include "io/ply_io.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include "core/check.h"
#include "io/files.h"

namespace jvl::io {

void WritePly(const std::string& path, const std::vector<Eigen::Vector3f>& points, bool binary) {
  AtomicWrite(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    JVL_CHECK(out, "cannot write " << path);
    out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
        << "comment jvl accumulated map (world frame = first camera, metres)\n"
        << "element vertex " << points.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\nend_header\n";
    if (binary) {
      static_assert(sizeof(float) == 4, "PLY float is 4 bytes");
      const uint16_t probe = 1;
      JVL_CHECK(*reinterpret_cast<const uint8_t*>(&probe) == 1,
                "binary PLY writing assumes a little-endian host");
      for (const auto& p : points) out.write(reinterpret_cast<const char*>(p.data()), 12);
    } else {
      out.precision(9);
      for (const auto& p : points) out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    }
    JVL_CHECK(out.good(), "write failed: " << path);
  });
}

std::vector<Eigen::Vector3f> ReadPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  JVL_CHECK(in, "cannot open " << path);
  std::string line, format;
  size_t count = 0;
  int properties = 0;
  std::getline(in, line);
  JVL_CHECK(line == "ply", path << ": not a PLY file");
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "format") ls >> format;
    if (key == "element") {
      std::string name;
      ls >> name >> count;
      JVL_CHECK(name == "vertex", path << ": unsupported element '" << name << "'");
    }
    if (key == "property") ++properties;
  }
  JVL_CHECK(properties == 3, path << ": expected float x y z vertices only");
  std::vector<Eigen::Vector3f> points(count);
  if (format == "binary_little_endian") {
    for (auto& p : points) in.read(reinterpret_cast<char*>(p.data()), 12);
  } else {
    JVL_CHECK(format == "ascii", path << ": unsupported PLY format '" << format << "'");
    for (auto& p : points) in >> p.x() >> p.y() >> p.z();
  }
  JVL_CHECK(!in.fail(), path << ": truncated PLY (" << count << " vertices announced)");
  return points;
}

}  // namespace jvl::io
