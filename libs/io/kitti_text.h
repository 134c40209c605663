// Plain-text pieces shared by the KITTI raw, KITTI-360 and Oxford readers: "key: numbers"
// calibration files, rectification, rigid transforms from their numbers, number and line lists,
// numbered file names.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "geometry/calibration.h"
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

// The numbers of a file holding only whitespace-separated numbers; throws naming it.
std::vector<double> ReadNumberFile(const std::string& path);

// "0000000042.bin": `frame` zero-padded to `digits`, then `ext`.
std::string ZeroPaddedName(int64_t frame, int digits, const char* ext);

// The rectification of a KITTI-style "key: numbers" calibration (`kv`, read from `path`):
// P_rect_00 .. P_rect_0(required-1) into calib->P (each present one of the next `optional`
// too), S_rect_00 as the image size (*size_source names it), and R_rect_00 returned as
// rect_from_cam0. Throws naming the file and key.
Rigid3d ReadRectification(const std::map<std::string, std::vector<double>>& kv,
                          const std::string& path, int required, int optional, Calibration* calib,
                          std::string* size_source);

}  // namespace jvl::io
