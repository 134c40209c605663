// Plain-text pieces shared by the KITTI raw and KITTI-360 readers: "key: numbers" calibration
// files, rigid transforms from their numbers, and line lists.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "geometry/rigid3.h"

namespace jvl::io {

// The "key: v1 v2 ..." lines of a calibration file whose values are all numbers. Throws naming
// the file (and `hint`, where such files live) if it cannot be read.
std::map<std::string, std::vector<double>> ReadKeyValues(const std::string& path,
                                                         const std::string& hint);

// kv[key], which must hold exactly n numbers; throws naming the file and key otherwise.
const std::vector<double>& RequireValues(const std::map<std::string, std::vector<double>>& kv,
                                         const std::string& key, size_t n, const std::string& path);

// The rigid transform [R | t] of a row-major 3 x 3 rotation and a translation; throws naming the
// file if R is not a rotation (within 1e-2) or a value is not finite.
Rigid3d RigidFromRT(const std::vector<double>& r, const std::vector<double>& t,
                    const std::string& path);
// The same from 12 row-major numbers of a 3 x 4 matrix.
Rigid3d RigidFrom3x4(const std::vector<double>& m, const std::string& path);

// The non-blank lines of a text file; throws naming it if it cannot be read.
std::vector<std::string> ReadLines(const std::string& path);

}  // namespace jvl::io
