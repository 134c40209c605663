#include "io/odometry_io.h"

#include <cmath>

#include "core/check.h"
#include "io/trajectory_io.h"

namespace jvl::io {
namespace {

template <typename T>
void CheckLength(const std::vector<T>& v, size_t n, const char* name, const std::string& where) {
  JVL_CHECK(v.size() == n,
            where << ": diagnostics/" << name << " has " << v.size() << " entries, expected " << n);
}

void CheckDiagnostics(const OdometryDiagnostics& d, size_t n, const std::string& where) {
  CheckLength(d.iterations, n, "iterations", where);
  CheckLength(d.residual, n, "residual", where);
  CheckLength(d.correspondences, n, "correspondences", where);
  CheckLength(d.time_ms, n, "time_ms", where);
  CheckLength(d.degenerate, n, "degenerate", where);
  CheckLength(d.points_after_filter, n, "points_after_filter", where);
  CheckLength(d.status, n, "status", where);
  CheckLength(d.non_finite_points, n, "non_finite_points", where);
  CheckLength(d.min_eigenvalue, n, "min_eigenvalue", where);
}

}  // namespace

void WriteOdometryArtifact(const std::string& path, const OdometryArtifact& artifact,
                           const Provenance& provenance) {
  artifact.trajectory.Check(path.c_str());
  const OdometryDiagnostics& d = artifact.diagnostics;
  CheckDiagnostics(d, artifact.trajectory.size(), path);
  H5Writer writer(path, kOdometrySchema, kOdometrySchemaVersion);
  WriteTrajectoryGroup(writer, "trajectory", artifact.trajectory);
  writer.WriteArray("diagnostics/iterations", d.iterations);
  writer.WriteArray("diagnostics/residual", d.residual);
  writer.WriteArray("diagnostics/correspondences", d.correspondences);
  writer.WriteArray("diagnostics/time_ms", d.time_ms);
  writer.WriteArray("diagnostics/degenerate", d.degenerate);
  writer.WriteArray("diagnostics/points_after_filter", d.points_after_filter);
  writer.WriteArray("diagnostics/status", d.status);
  writer.WriteArray("diagnostics/non_finite_points", d.non_finite_points);
  writer.WriteArray("diagnostics/min_eigenvalue", d.min_eigenvalue);
  writer.Commit(provenance);
}

OdometryArtifact ReadOdometryArtifact(const std::string& path) {
  H5Reader reader(path, kOdometrySchema, kOdometrySchemaVersion);
  OdometryArtifact a;
  a.trajectory = ReadTrajectoryGroup(reader, "trajectory");
  OdometryDiagnostics& d = a.diagnostics;
  d.iterations = reader.ReadArray<int32_t>("diagnostics/iterations");
  d.residual = reader.ReadArray<double>("diagnostics/residual");
  d.correspondences = reader.ReadArray<int32_t>("diagnostics/correspondences");
  d.time_ms = reader.ReadArray<double>("diagnostics/time_ms");
  d.degenerate = reader.ReadArray<uint8_t>("diagnostics/degenerate");
  d.points_after_filter = reader.ReadArray<int64_t>("diagnostics/points_after_filter");
  d.status = reader.ReadArray<int32_t>("diagnostics/status");
  d.non_finite_points = reader.ReadArray<int64_t>("diagnostics/non_finite_points");
  d.min_eigenvalue = reader.ReadArray<double>("diagnostics/min_eigenvalue");
  CheckDiagnostics(d, a.trajectory.size(), path);
  return a;
}

std::vector<double> ReadOdometryConditioning(const std::string& path) {
  if (path.size() < 3 || path.compare(path.size() - 3, 3, ".h5") != 0) return {};
  {
    const H5Reader reader(path, "", 0);
    if (reader.schema() != kOdometrySchema) return {};
  }
  const OdometryArtifact a = ReadOdometryArtifact(path);
  std::vector<double> out(a.trajectory.size(), 0.0);
  for (size_t k = 0; k < out.size(); ++k) {
    const int32_t status = a.diagnostics.status[k];
    const bool registered = status == 0 || status == 2;
    const double v = a.diagnostics.min_eigenvalue[k];
    out[k] = registered && std::isfinite(v) && v > 0 ? v : 0.0;
  }
  return out;
}

}  // namespace jvl::io
