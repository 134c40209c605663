// IMLS association (paper Sec. 4.2 steps 2-4 and Eq. 2, IMLS-SLAM Sec. V): the one place where
// a scan is sampled and its points are projected onto the implicit surface of a model of other
// scans. The odometry (Sec. 4.1), the local mapping (Sec. 4.2) and the global traversal
// (Sec. 4.3) all associate through it:
//
//   SampledScan scan = SampleSurface(surface, options.samples_per_list);   // once per scan
//   ImlsModel model(options.search_radius);
//   AddScanToModel(other.points, other.normals, world_from_other, other_id, &model);
//   for (int i : SelectSamples(scan, world_from_scan, model, options)) {
//     ImlsProjection p;
//     if (ProjectPoint(model, world_from_scan * scan.points[i], options, &p)) ...  // Eq. (2)
//   }
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "geometry/rigid3.h"
#include "lidar/imls.h"
#include "lidar/surface.h"

namespace jvl::lidar {

struct AssociationOptions {
  int samples_per_list = 100;  // s of IMLS-SLAM: up to 9 s sampled points per scan.
  double kernel_h = 0.3;       // m, h of W_i in Eq. (2).
  double search_radius = 0.6;  // m, r: model neighbours of Eq. (2) (and the sampling test).
  double max_distance = 0.5;   // m, |I(x)| above this: no correspondence.
  // Throws naming the field (samples_per_list, kernel_h, ...); tools name their flags.
  void Check() const;
};

// The sampling lists hold this many candidates per point to take (they are sorted by the
// IMLS-SLAM values; sampling stops at samples_per_list accepted points, rarely further down).
inline constexpr size_t kListLengthFactor = 20;

// A scan prepared for association, in its own frame: the points that have a normal, their unit
// normals and planarity a2D, and the nine IMLS-SLAM sampling lists over them.
struct SampledScan {
  std::vector<Eigen::Vector3d> points, normals;
  std::vector<double> planarity;
  std::array<std::vector<int>, 9> lists;
  size_t size() const { return points.size(); }
};

// A scan kept for later association (the "scans" of the local artifact, read by the global
// optimisation and the map export): a voxel-downsampled copy of a scan's points that have a
// normal, in the scan's frame, in single precision as stored.
struct StoredScan {
  std::vector<Eigen::Vector3f> points, normals;  // unit normals
  size_t size() const { return points.size(); }
};

// The points of `scan` (its model points) thinned to one per voxel of `voxel` m (<= 0: all).
StoredScan StoreScan(const SampledScan& scan, double voxel);

// The valid points of `surface` and lists of kListLengthFactor * samples_per_list entries
// (samples_per_list <= 0: whole lists).
SampledScan SampleSurface(const ScanSurface& surface, int samples_per_list);

// Adds the points of a scan (its frame; normals shorter than 0.5 mark points without one and
// are skipped) placed at world_from_scan to `model` as scan `id`. Nothing is added for a scan
// without points.
void AddScanToModel(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Eigen::Vector3d>& normals, const Rigid3d& world_from_scan,
                    int64_t id, ImlsModel* model);
void AddScanToModel(const std::vector<Eigen::Vector3f>& points,
                    const std::vector<Eigen::Vector3f>& normals, const Rigid3d& world_from_scan,
                    int64_t id, ImlsModel* model);

// IMLS-SLAM sampling: up to samples_per_list points of each list (a point only once) that have
// a model point within search_radius when the scan is placed at world_from_scan. Indices into
// scan.points, in selection order.
std::vector<int> SelectSamples(const SampledScan& scan, const Rigid3d& world_from_scan,
                               const ImlsModel& model, const AssociationOptions& options);

// Eq. (2) at the world point x and its projection y = x - I(x) n_c: false when no model point
// is within search_radius or |I(x)| > max_distance.
bool ProjectPoint(const ImlsModel& model, const Eigen::Vector3d& x,
                  const AssociationOptions& options, ImlsProjection* out);

}  // namespace jvl::lidar
