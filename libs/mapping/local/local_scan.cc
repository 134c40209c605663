#include "mapping/local/local_scan.h"

#include <cmath>

#include "core/check.h"
#include "lidar/voxel_grid.h"

namespace jvl::mapping {
namespace {

KeyframeScan FromSurface(const lidar::ScanSurface& surface, int samples_per_list,
                         double stored_voxel) {
  KeyframeScan scan;
  scan.sampled = lidar::SampleSurface(surface, samples_per_list);
  scan.stored = lidar::StoreScan(scan.sampled, stored_voxel);
  return scan;
}

}  // namespace

void ScanOptions::Check() const {
  preprocess.Check();
  surface.Check();
  JVL_CHECK(std::isfinite(stored_voxel), "stored_voxel must be finite");
}

KeyframeScan PrepareKeyframeScan(const PointCloud& velo_scan, const Rigid3d& cam0_from_velo,
                                 const ScanOptions& options, int samples_per_list, int threads,
                                 const std::optional<Rigid3d>& sweep_motion,
                                 double scan_time_offset) {
  lidar::PreprocessedScan pre =
      lidar::PreprocessScan(velo_scan, cam0_from_velo, options.preprocess, threads);
  pre.time_offset = scan_time_offset;
  if (sweep_motion) lidar::DeskewScan(*sweep_motion, &pre);
  const lidar::ScanSurface surface = lidar::ComputeSurface(pre.points, options.surface, threads);
  KeyframeScan scan = FromSurface(surface, samples_per_list, options.stored_voxel);
  scan.raw_points = static_cast<int64_t>(velo_scan.points.size());
  return scan;
}

std::optional<Rigid3d> SweepMotion(const Trajectory& trajectory, int64_t frame) {
  const auto prev = trajectory.IndexOf(frame - 1);
  const auto cur = trajectory.IndexOf(frame);
  const auto next = trajectory.IndexOf(frame + 1);
  const auto between = [&](size_t a, size_t b) {
    return trajectory.world_from_cam[a].Inverse() * trajectory.world_from_cam[b];
  };
  if (prev && next) return ExpSE3(0.5 * LogSE3(between(*prev, *next)));
  if (prev && cur) return between(*prev, *cur);
  if (cur && next) return between(*cur, *next);
  return std::nullopt;
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
  KeyframeScan scan = FromSurface(surface, 0, stored_voxel);
  scan.raw_points = static_cast<int64_t>(points.size());
  return scan;
}

lidar::ImlsModel BuildScanModel(const std::vector<const KeyframeScan*>& scans,
                                const std::vector<int64_t>& rows,
                                const std::vector<Rigid3d>& world_from_cam, double cell_size) {
  JVL_CHECK(scans.size() == rows.size(),
            "scan model: " << scans.size() << " scans for " << rows.size() << " keyframes");
  lidar::ImlsModel model(cell_size);
  for (size_t k = 0; k < scans.size(); ++k) {
    lidar::AddScanToModel(scans[k]->sampled.points, scans[k]->sampled.normals,
                          world_from_cam.at(static_cast<size_t>(rows[k])), rows[k], &model);
  }
  return model;
}

std::vector<optim::ImlsCorrespondence> AssociateScan(int64_t n, const KeyframeScan& scan,
                                                     const Rigid3d& world_from_n,
                                                     const lidar::ImlsModel& model,
                                                     const std::vector<Rigid3d>& world_from_cam,
                                                     const lidar::AssociationOptions& options) {
  std::vector<optim::ImlsCorrespondence> out;
  const lidar::SampledScan& sampled = scan.sampled;
  // IMLS-SLAM sampling: s points per list that have a model neighbour at the current pose.
  for (const int i : lidar::SelectSamples(sampled, world_from_n, model, options)) {
    lidar::ImlsProjection proj;
    // Eq. (2) in the world frame and p_y = p_x - I(p_x) n_c.
    if (!lidar::ProjectPoint(model, world_from_n * sampled.points[i], options, &proj)) continue;
    if (proj.nearest_scan < 0 || proj.nearest_scan == n) continue;
    const Rigid3d c_from_world =
        world_from_cam.at(static_cast<size_t>(proj.nearest_scan)).Inverse();
    optim::ImlsCorrespondence l;
    l.n = n;
    l.c = proj.nearest_scan;
    l.p_x = sampled.points[i];
    // Step 4: ^c p_y = T_cw p_y and n_c in K_c's frame.
    l.c_p_y = c_from_world * proj.projection;
    l.c_normal = (c_from_world.rotation() * proj.normal).normalized();
    out.push_back(l);
  }
  return out;
}

}  // namespace jvl::mapping
