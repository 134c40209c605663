#include "cli_options.h"

#include "app/option_group.h"
#include "io/dataset.h"

namespace jvl::tools {

void AddLidarOdomFlags(app::Tool& tool, lidar::OdometryOptions* options, std::string* deskew,
                       std::string* vertical_correction) {
  lidar::OdometryOptions& o = *options;
  app::OptionGroup model(tool, "Model and sampling");
  model.Add("--scan-map-size", o.scan_map_size, "N: scans kept in the model (paper's N)");
  model.Add("--samples-per-list", o.association.samples_per_list,
            "s: points per IMLS-SLAM sampling list (x9)");
  model.Add("--initial-search-scale", o.initial_search_scale,
            "Second scan (no velocity yet): coarse pass with neighbourhoods x this (1 = off)");
  model
      .Add("--deskew", *deskew,
           "Constant-velocity de-skewing of each scan: auto (when the dataset's scans are not "
           "motion-compensated: KITTI raw, sim_sequence --motion-distortion; KITTI odometry scans "
           "are compensated), on or off")
      ->check(CLI::IsMember({"auto", "on", "off"}));

  app::OptionGroup pre(tool, "Preprocessing");
  auto& p = o.preprocess;
  pre.Add("--min-range", p.min_range, "Drop points closer than this (m)");
  pre.Add("--max-range", p.max_range, "Drop points further than this (m, 0 = no limit)");
  pre.Add("--vertical-correction", "vertical_correction_deg", *vertical_correction,
          io::kVerticalCorrectionHelp);
  pre.Add("--voxel-size", p.voxel_size, "Voxel downsampling of each scan (m, 0 = off)");
  pre.Add("--outlier-radius", p.outlier_radius, "RadiusOutlierRemoval radius (m, 0 = off)");
  pre.Add("--outlier-min-neighbors", p.outlier_min_neighbors,
          "RadiusOutlierRemoval: minimum neighbours within the radius");
  pre.Add("--outlier-method", p.outlier_method,
          "grid (hashed grid, same result) or pcl (pcl::RadiusOutlierRemoval)");
  pre.Add("--ground-distance", p.ground_distance, "Ground plane inlier distance (m)");
  pre.Add("--ground-max-angle", "ground_max_angle_deg", p.ground_max_angle_deg,
          "Ground normal vs vertical, max (deg)");
  pre.Add("--ground-iterations", "ground_max_iterations", p.ground_max_iterations,
          "Ground RANSAC iterations");
  pre.Add("--ground-samples", "ground_max_samples", p.ground_max_samples,
          "Points the ground RANSAC runs on");
  pre.Flag("--remove-small-objects,!--keep-small-objects", p.remove_small_objects,
           "Drop clusters with a small bounding box (cars, pedestrians), as IMLS-SLAM does; off by "
           "default: kept, they make the odometry more accurate (docs/lidar_odom.md)");
  pre.Add("--cluster-cell", p.cluster_cell, "Small-object clustering cell (m)");
  pre.Add("--small-object-horizontal", p.small_object_horizontal,
          "Clusters smaller than this along x and z (m) ...");
  pre.Add("--small-object-height", p.small_object_height, "... and along y (m) are removed");

  app::OptionGroup surf(tool, "Normals");
  surf.Add("--normal-neighbors", o.surface.normal_neighbors, "k nearest points of the local PCA");
  surf.Add("--normal-radius", o.surface.normal_radius, "Max neighbour distance of the PCA (m)");
  surf.Add("--min-normal-neighbors", o.surface.min_normal_neighbors,
           "Fewer neighbours: point has no normal and is not used");

  app::OptionGroup reg(tool, "Registration");
  auto& r = o.registration;
  reg.Add("--max-iterations", r.max_iterations, "Iteration cap");
  reg.Add("--imls-h", "kernel_h", o.association.kernel_h, "IMLS kernel width h of Eq. (2) (m)");
  reg.Add("--imls-radius", "search_radius", o.association.search_radius,
          "IMLS neighbourhood radius r (m)");
  reg.Add("--imls-max-distance,--max-distance", "max_distance", o.association.max_distance,
          "Reject correspondences with |I(x)| above (m)");
  reg.Add("--robust-scale", r.robust_scale, "Cauchy loss scale on I(x) (m)");
  reg.Add("--convergence-translation", r.convergence_translation,
          "Stop when the update is below this (m) ...");
  reg.Add("--convergence-rotation", r.convergence_rotation, "... and below this (rad)");
  reg.Add("--min-correspondences", r.min_correspondences,
          "Fewer: keep the motion-model pose and flag the frame");
  reg.Add("--degeneracy-threshold", r.degeneracy_threshold,
          "Normalised eigenvalue below which a direction is unobservable");
}

}  // namespace jvl::tools
