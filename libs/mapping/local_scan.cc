#include "mapping/local_scan.h"

#include <cmath>

#include "core/check.h"
#include "lidar/voxel_grid.h"

namespace jvl::mapping {
namespace {

// Keeps the valid rows of a surface and computes the sampling lists over them.
KeyframeScan FromValidSurface(const lidar::ScanSurface& surface, size_t max_list_length,
                              double stored_voxel) {
  lidar::ScanSurface kept;
  for (size_t i = 0; i < surface.size(); ++i) {
    if (!surface.valid[i]) continue;
    kept.points.push_back(surface.points[i]);
    kept.normals.push_back(surface.normals[i]);
    kept.planarity.push_back(surface.planarity[i]);
    kept.valid.push_back(1);
  }
  KeyframeScan scan;
  scan.lists = lidar::SamplingLists(kept, max_list_length);
  for (const size_t i : lidar::VoxelDownsample(kept.points, stored_voxel)) {
    scan.stored_points.push_back(kept.points[i]);
    scan.stored_normals.push_back(kept.normals[i]);
  }
  scan.points = std::move(kept.points);
  scan.normals = std::move(kept.normals);
  scan.planarity = std::move(kept.planarity);
  return scan;
}

}  // namespace

void ScanOptions::Check() const {
  preprocess.Check();
  surface.Check();
  JVL_CHECK(std::isfinite(stored_voxel), "--scan-voxel must be finite");
}

void AssociationOptions::Check() const {
  JVL_CHECK(samples_per_list >= 1, "--samples-per-list must be >= 1, got " << samples_per_list);
  JVL_CHECK(kernel_h > 0 && search_radius > 0 && max_distance > 0,
            "--imls-h, --imls-radius and --imls-max-distance must be positive (got "
                << kernel_h << ", " << search_radius << ", " << max_distance << ")");
}

KeyframeScan PrepareKeyframeScan(const PointCloud& velo_scan, const Rigid3d& cam0_from_velo,
                                 const ScanOptions& options, size_t max_list_length, int threads) {
  const lidar::PreprocessedScan pre =
      lidar::PreprocessScan(velo_scan, cam0_from_velo, options.preprocess, threads);
  const lidar::ScanSurface surface = lidar::ComputeSurface(pre.points, options.surface, threads);
  KeyframeScan scan = FromValidSurface(surface, max_list_length, options.stored_voxel);
  scan.raw_points = static_cast<int64_t>(velo_scan.points.size());
  return scan;
}

KeyframeScan KeyframeScanFromSurface(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3d>& normals,
                                     double stored_voxel) {
  JVL_CHECK(points.size() == normals.size(),
            "scan has " << points.size() << " points but " << normals.size() << " normals");
  lidar::ScanSurface surface;
  surface.points = points;
  for (const Eigen::Vector3d& n : normals) surface.normals.push_back(n.normalized());
  surface.planarity.assign(points.size(), 1.0);
  surface.valid.assign(points.size(), 1);
  KeyframeScan scan = FromValidSurface(surface, 0, stored_voxel);
  scan.raw_points = static_cast<int64_t>(points.size());
  return scan;
}

lidar::ImlsModel BuildScanModel(const std::vector<const KeyframeScan*>& scans,
                                const std::vector<int64_t>& rows,
                                const std::vector<Rigid3d>& world_from_cam, double cell_size) {
  JVL_CHECK(scans.size() == rows.size(),
            "scan model: " << scans.size() << " scans for " << rows.size() << " keyframes");
  lidar::ImlsModel model(cell_size);
  std::vector<Eigen::Vector3d> points, normals;
  for (size_t k = 0; k < scans.size(); ++k) {
    const Rigid3d& pose = world_from_cam.at(static_cast<size_t>(rows[k]));
    points.clear();
    normals.clear();
    for (size_t i = 0; i < scans[k]->points.size(); ++i) {
      points.push_back(pose * scans[k]->points[i]);
      normals.push_back(pose.rotation() * scans[k]->normals[i]);
    }
    if (!points.empty()) model.AddScan(rows[k], points, normals);
  }
  return model;
}

std::vector<optim::ImlsCorrespondence> AssociateScan(int64_t n, const KeyframeScan& scan,
                                                     const Rigid3d& world_from_n,
                                                     const lidar::ImlsModel& model,
                                                     const std::vector<Rigid3d>& world_from_cam,
                                                     const AssociationOptions& options) {
  std::vector<optim::ImlsCorrespondence> out;
  if (model.size() == 0 || scan.points.empty()) return out;
  const double r = options.search_radius;
  // IMLS-SLAM sampling: s points per list that have a model neighbour at the current pose.
  const std::vector<int> picked = lidar::SelectSamples(
      scan.lists, scan.points.size(), options.samples_per_list,
      [&](int i) { return model.HasNeighbor(world_from_n * scan.points[i], r); });
  for (const int i : picked) {
    lidar::ImlsProjection proj;
    // Eq. (2) in the world frame and p_y = p_x - I(p_x) n_c.
    if (!model.Project(world_from_n * scan.points[i], options.kernel_h, r, &proj)) continue;
    if (!(std::abs(proj.distance) <= options.max_distance)) continue;
    if (proj.nearest_scan < 0 || proj.nearest_scan == n) continue;
    const Rigid3d c_from_world =
        world_from_cam.at(static_cast<size_t>(proj.nearest_scan)).Inverse();
    optim::ImlsCorrespondence l;
    l.n = n;
    l.c = proj.nearest_scan;
    l.p_x = scan.points[i];
    // Step 4: ^c p_y = T_cw p_y and n_c in K_c's frame.
    l.c_p_y = c_from_world * proj.projection;
    l.c_normal = (c_from_world.rotation() * proj.normal).normalized();
    out.push_back(l);
  }
  return out;
}

}  // namespace jvl::mapping
