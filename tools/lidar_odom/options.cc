#include "options.h"

namespace jvl::lidar_odom {

void AddOdometryOptions(CLI::App& cli, lidar::OdometryOptions& o) {
  auto add = [&cli](const std::string& name, auto& value, const std::string& help,
                    const std::string& group) {
    cli.add_option(name, value, help)->capture_default_str()->group(group);
  };
  const std::string model = "Model and sampling";
  add("--scan-map-size", o.scan_map_size, "N: scans kept in the model (paper's N)", model);
  add("--samples-per-list", o.association.samples_per_list,
      "s: points per IMLS-SLAM sampling list (x9)", model);
  add("--initial-search-scale", o.initial_search_scale,
      "Second scan (no velocity yet): coarse pass with neighbourhoods x this (1 = off)", model);
  cli.add_flag("--deskew,!--no-deskew", o.deskew, "Constant-velocity de-skewing of each scan")
      ->capture_default_str()
      ->group(model);

  const std::string pre = "Preprocessing";
  auto& p = o.preprocess;
  add("--min-range", p.min_range, "Drop points closer than this (m)", pre);
  add("--max-range", p.max_range, "Drop points further than this (m, 0 = no limit)", pre);
  add("--vertical-correction", p.vertical_correction_deg,
      "Elevation correction (deg; KITTI HDL-64: 0.205; 0 = off)", pre);
  add("--voxel-size", p.voxel_size, "Voxel downsampling of each scan (m, 0 = off)", pre);
  add("--outlier-radius", p.outlier_radius, "RadiusOutlierRemoval radius (m, 0 = off)", pre);
  add("--outlier-min-neighbors", p.outlier_min_neighbors,
      "RadiusOutlierRemoval: minimum neighbours within the radius", pre);
  add("--outlier-method", p.outlier_method,
      "grid (hashed grid, same result) or pcl (pcl::RadiusOutlierRemoval)", pre);
  add("--ground-distance", p.ground_distance, "Ground plane inlier distance (m)", pre);
  add("--ground-max-angle", p.ground_max_angle_deg, "Ground normal vs vertical, max (deg)", pre);
  add("--ground-iterations", p.ground_max_iterations, "Ground RANSAC iterations", pre);
  add("--ground-samples", p.ground_max_samples, "Points the ground RANSAC runs on", pre);
  cli.add_flag("--remove-small-objects,!--keep-small-objects", p.remove_small_objects,
               "Drop clusters with a small bounding box (cars, pedestrians)")
      ->capture_default_str()
      ->group(pre);
  add("--cluster-cell", p.cluster_cell, "Small-object clustering cell (m)", pre);
  add("--small-object-horizontal", p.small_object_horizontal,
      "Clusters smaller than this along x and z (m) ...", pre);
  add("--small-object-height", p.small_object_height, "... and along y (m) are removed", pre);

  const std::string surf = "Normals";
  add("--normal-neighbors", o.surface.normal_neighbors, "k nearest points of the local PCA", surf);
  add("--normal-radius", o.surface.normal_radius, "Max neighbour distance of the PCA (m)", surf);
  add("--min-normal-neighbors", o.surface.min_normal_neighbors,
      "Fewer neighbours: point has no normal and is not used", surf);

  const std::string reg = "Registration";
  auto& r = o.registration;
  add("--max-iterations", r.max_iterations, "Iteration cap", reg);
  add("--imls-h", o.association.kernel_h, "IMLS kernel width h of Eq. (2) (m)", reg);
  add("--imls-radius", o.association.search_radius, "IMLS neighbourhood radius r (m)", reg);
  add("--imls-max-distance,--max-distance", o.association.max_distance,
      "Reject correspondences with |I(x)| above (m)", reg);
  add("--robust-scale", r.robust_scale, "Cauchy loss scale on I(x) (m)", reg);
  add("--convergence-translation", r.convergence_translation,
      "Stop when the update is below this (m) ...", reg);
  add("--convergence-rotation", r.convergence_rotation, "... and below this (rad)", reg);
  add("--min-correspondences", r.min_correspondences,
      "Fewer: keep the motion-model pose and flag the frame", reg);
  add("--degeneracy-threshold", r.degeneracy_threshold,
      "Normalised eigenvalue below which a direction is unobservable", reg);
}

}  // namespace jvl::lidar_odom
