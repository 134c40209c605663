// Point clouds as PLY files (binary little-endian or ASCII, "vertex" with float x y z), readable
// by CloudCompare, Open3D and MeshLab.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace jvl::io {

void WritePly(const std::string& path, const std::vector<Eigen::Vector3f>& points,
              bool binary = true);
// Reads what WritePly writes (x y z float vertices, binary_little_endian or ascii).
std::vector<Eigen::Vector3f> ReadPly(const std::string& path);

}  // namespace jvl::io
