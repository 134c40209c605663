// The LiDAR side of local mapping (paper Sec. 4.2 steps 2-4): each keyframe's scan is prepared
// once (preprocessing, normals, the nine IMLS-SLAM sampling lists), the scan model S_model is
// built from the scans of K_start..K_{n-1} placed with their current poses, and the sampled points
// of K_n are projected onto its IMLS surface (Eq. 2) to give the correspondences of Eq. (3).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "geometry/point_cloud.h"
#include "geometry/rigid3.h"
#include "geometry/trajectory.h"
#include "lidar/association.h"
#include "lidar/imls.h"
#include "lidar/preprocess.h"
#include "lidar/surface.h"
#include "optim/joint_problem.h"

namespace jvl::mapping {

struct ScanOptions {
  lidar::PreprocessOptions preprocess;
  lidar::SurfaceOptions surface;
  // Voxel (m) of the copy kept for the artifact's "scans" group (global optimisation and the
  // PLY map read it instead of the dataset). <= 0 keeps every model point.
  double stored_voxel = 0.4;
  void Check() const;
};

// One keyframe's scan in its own cam0 frame, prepared once and reused by every optimisation the
// keyframe takes part in: the sampled surface the association works on, and the copy stored in
// the artifact.
struct KeyframeScan {
  lidar::SampledScan sampled;
  lidar::StoredScan stored;  // voxel-downsampled (ScanOptions::stored_voxel)
  int64_t raw_points = 0;    // input scan size
};

// Preprocessing (supplement 1.1), normals and sampling lists (IMLS-SLAM Sec. V) of a velodyne
// scan, for samples_per_list points per list. With `sweep_motion` (the motion over one scan
// period, prev_from_cur in cam0) the points are de-skewed first (lidar::DeskewScan), and moved
// to the frame time if the scan was taken `scan_time_offset` frame periods after it
// (io::Dataset::ScanTimeOffsetInFrames).
KeyframeScan PrepareKeyframeScan(const PointCloud& velo_scan, const Rigid3d& cam0_from_velo,
                                 const ScanOptions& options, int samples_per_list, int threads,
                                 const std::optional<Rigid3d>& sweep_motion = std::nullopt,
                                 double scan_time_offset = 0);

// The motion over one frame period at `frame` from a trajectory (constant velocity, centred:
// half the motion from frame - 1 to frame + 1, or the one-sided motion at the ends); nullopt
// when the trajectory has neither neighbour.
std::optional<Rigid3d> SweepMotion(const Trajectory& trajectory, int64_t frame);

// Builds a KeyframeScan from points that already have normals (synthetic scans, tests): the
// planarity is taken as 1 and the sampling lists are computed as for a real scan (whole lists).
KeyframeScan KeyframeScanFromSurface(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3d>& normals,
                                     double stored_voxel);

// Step 2: S_model, the scans of `rows` (keyframe rows) placed with world_from_cam[row]; every
// model point remembers its keyframe row (the scan id).
lidar::ImlsModel BuildScanModel(const std::vector<const KeyframeScan*>& scans,
                                const std::vector<int64_t>& rows,
                                const std::vector<Rigid3d>& world_from_cam, double cell_size);

// Steps 3-4: samples the scan of keyframe row n (placed at world_from_n) with the nine-value
// sampling, projects each sample onto the IMLS surface of `model` and returns the
// correspondences (n, c, p_x in n's frame, c_p_y and n_c in c's frame), c = keyframe of the
// nearest model point. world_from_cam holds the current poses of the model's keyframes.
std::vector<optim::ImlsCorrespondence> AssociateScan(int64_t n, const KeyframeScan& scan,
                                                     const Rigid3d& world_from_n,
                                                     const lidar::ImlsModel& model,
                                                     const std::vector<Rigid3d>& world_from_cam,
                                                     const lidar::AssociationOptions& options);

}  // namespace jvl::mapping
