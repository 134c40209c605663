#include "lidar/association.h"

#include <cmath>

#include "core/check.h"
#include "lidar/voxel_grid.h"

namespace jvl::lidar {

namespace {

template <typename Vector>
void AddPoints(const std::vector<Vector>& points, const std::vector<Vector>& normals,
               const Rigid3d& world_from_scan, int64_t id, ImlsModel* model) {
  JVL_CHECK(points.size() == normals.size(),
            "scan " << id << ": " << points.size() << " points but " << normals.size()
                    << " normals");
  std::vector<Eigen::Vector3d> world_points, world_normals;
  world_points.reserve(points.size());
  world_normals.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (normals[i].squaredNorm() < 0.25) continue;  // no normal
    world_points.push_back(world_from_scan * points[i].template cast<double>());
    world_normals.push_back(world_from_scan.rotation() * normals[i].template cast<double>());
  }
  if (!world_points.empty()) model->AddScan(id, world_points, world_normals);
}

}  // namespace

void AssociationOptions::Check() const {
  JVL_CHECK(samples_per_list >= 1, "samples_per_list must be >= 1, got " << samples_per_list);
  JVL_CHECK(kernel_h > 0, "kernel_h must be > 0, got " << kernel_h);
  JVL_CHECK(search_radius > 0, "search_radius must be > 0, got " << search_radius);
  JVL_CHECK(max_distance > 0, "max_distance must be > 0, got " << max_distance);
}

SampledScan SampleSurface(const ScanSurface& surface, int samples_per_list) {
  ScanSurface kept;
  for (size_t i = 0; i < surface.size(); ++i) {
    if (!surface.valid[i]) continue;
    kept.points.push_back(surface.points[i]);
    kept.normals.push_back(surface.normals[i]);
    kept.planarity.push_back(surface.planarity[i]);
    kept.valid.push_back(1);
  }
  SampledScan scan;
  // The lists keep the order of the valid points, so they hold the same points as lists over
  // the whole surface (ties are broken by index).
  scan.lists = SamplingLists(
      kept, samples_per_list <= 0 ? 0 : kListLengthFactor * static_cast<size_t>(samples_per_list));
  scan.points = std::move(kept.points);
  scan.normals = std::move(kept.normals);
  scan.planarity = std::move(kept.planarity);
  return scan;
}

StoredScan StoreScan(const SampledScan& scan, double voxel) {
  StoredScan stored;
  for (const size_t i : VoxelDownsample(scan.points, voxel)) {
    stored.points.push_back(scan.points[i].cast<float>());
    stored.normals.push_back(scan.normals[i].cast<float>());
  }
  return stored;
}

void AddScanToModel(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Eigen::Vector3d>& normals, const Rigid3d& world_from_scan,
                    int64_t id, ImlsModel* model) {
  AddPoints(points, normals, world_from_scan, id, model);
}

void AddScanToModel(const std::vector<Eigen::Vector3f>& points,
                    const std::vector<Eigen::Vector3f>& normals, const Rigid3d& world_from_scan,
                    int64_t id, ImlsModel* model) {
  AddPoints(points, normals, world_from_scan, id, model);
}

std::vector<int> SelectSamples(const SampledScan& scan, const Rigid3d& world_from_scan,
                               const ImlsModel& model, const AssociationOptions& options) {
  if (model.size() == 0 || scan.points.empty()) return {};
  const double r = options.search_radius;
  return SelectSamples(scan.lists, scan.points.size(), options.samples_per_list, [&](int i) {
    return model.HasNeighbor(world_from_scan * scan.points[i], r);
  });
}

bool ProjectPoint(const ImlsModel& model, const Eigen::Vector3d& x,
                  const AssociationOptions& options, ImlsProjection* out) {
  ImlsProjection p;
  if (!model.Project(x, options.kernel_h, options.search_radius, &p)) return false;
  if (!(std::abs(p.distance) <= options.max_distance)) return false;  // also NaN
  *out = p;
  return true;
}

}  // namespace jvl::lidar
