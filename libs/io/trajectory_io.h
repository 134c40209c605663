// Trajectory files: the jvl HDF5 artifact (group "trajectory" in any artifact), KITTI text
// (12 numbers per line, or frame index + 12 numbers) and TUM text (t tx ty tz qx qy qz qw).
#pragma once

#include <iosfwd>
#include <string>

#include "geometry/trajectory.h"
#include "io/artifact.h"

namespace jvl::io {

enum class TrajectoryFormat { kAuto, kH5, kKitti, kKittiIndexed, kTum };

TrajectoryFormat ParseTrajectoryFormat(const std::string& name);  // auto|h5|kitti|kitti-indexed|tum
std::string ToString(TrajectoryFormat format);

// Reads any supported format. kAuto: ".h5" -> HDF5, otherwise the column count of the first
// data line (12 KITTI, 13 indexed KITTI, 8 TUM). KITTI 12-column lines get frames 0, 1, ...;
// TUM lines get frames 0, 1, ... and timestamps. Throws naming the file and line.
Trajectory ReadTrajectory(const std::string& path, TrajectoryFormat format = TrajectoryFormat::kAuto);
Trajectory ReadTrajectoryText(std::istream& in, TrajectoryFormat format, const std::string& name);

// KITTI text: 12 columns when frames are 0..N-1, otherwise "frame + 12" (or force with_index).
void WriteTrajectoryKitti(const std::string& path, const Trajectory& t, bool force_index = false);
void WriteTrajectoryTum(const std::string& path, const Trajectory& t);
std::string FormatTrajectoryKitti(const Trajectory& t, bool with_index);
std::string FormatTrajectoryTum(const Trajectory& t);

// Trajectory datasets inside an artifact: <group>/frames (N int64), <group>/poses (N x 7
// [qx qy qz qw tx ty tz]), optional <group>/timestamps (N).
void WriteTrajectoryGroup(H5Writer& writer, const std::string& group, const Trajectory& t);
Trajectory ReadTrajectoryGroup(const H5Reader& reader, const std::string& group);

// A stand-alone trajectory artifact (schema "trajectory", version 1).
void WriteTrajectoryArtifact(const std::string& path, const Trajectory& t,
                             const Provenance& provenance);

}  // namespace jvl::io
