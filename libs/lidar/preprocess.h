// Scan preprocessing of the tracking odometry (paper supplement 1.1, IMLS-SLAM Sec. IV):
// points closer than 5 m are dropped, isolated points are removed with PCL's
// RadiusOutlierRemoval, the ground plane is found with PCL's SACSegmentation (kept, labelled),
// and small objects (clusters of non-ground points with a small bounding box: cars,
// pedestrians) are removed so that they do not enter the model.
//
// All steps work in the cam0 frame (the scan is moved there with calib Tr = cam0_from_velo),
// where y points down and x, z span the horizontal plane.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/point_cloud.h"
#include "geometry/rigid3.h"

namespace jvl::lidar {

struct PreprocessOptions {
  double min_range = 5.0;  // m, supplement 1.1.
  double max_range = 0.0;  // m, 0 = no limit.
  // KITTI HDL-64 intrinsic elevation error (degrees, e.g. 0.205); 0 = off.
  double vertical_correction_deg = 0.0;
  // Voxel downsampling (m) applied after the range cut; all later steps and the model use the
  // downsampled points. 0 = keep every point.
  double voxel_size = 0.4;
  // PCL RadiusOutlierRemoval: keep points with at least min_neighbors others within radius.
  double outlier_radius = 1.0;
  int outlier_min_neighbors = 2;
  // "grid": the same test answered from a hashed grid (several times faster, identical
  // result); "pcl": pcl::RadiusOutlierRemoval itself.
  std::string outlier_method = "grid";
  // PCL SACSegmentation (RANSAC, plane perpendicular to the cam0 y axis within max_angle).
  double ground_distance = 0.25;
  double ground_max_angle_deg = 15.0;
  int ground_max_iterations = 100;
  int ground_max_samples = 2000;  // RANSAC runs on an evenly strided subset of this size.
  // Small-object removal: clusters of non-ground points connected through cells of this size,
  // dropped when their bounding box is below all three extents (IMLS-SLAM: 14 x 14 x 4 m).
  bool remove_small_objects = true;
  double cluster_cell = 0.6;
  double small_object_horizontal = 14.0;  // m, along x and along z.
  double small_object_height = 4.0;       // m, along y.
  void Check() const;
};

struct PreprocessCounts {
  int64_t input = 0, non_finite = 0, after_range = 0, after_voxel = 0, after_outliers = 0;
  int64_t ground = 0, small_object_points = 0, small_object_clusters = 0, output = 0;
};

struct PreprocessedScan {
  std::vector<Eigen::Vector3d> points;  // cam0 frame.
  std::vector<uint8_t> is_ground;       // 1 for ground-plane inliers.
  // Acquisition time of each point as a fraction of the scan period relative to the frame
  // time, in [-0.5, 0.5], from the azimuth (used for de-skewing).
  std::vector<float> time_fraction;
  // The scan's time minus the frame's, in frame periods, added to every time fraction when
  // de-skewing: the points are then moved to the sensor pose at the frame time (a sweep taken
  // 20 ms after its image is moved back to the image). 0 when scan and frame are simultaneous.
  double time_offset = 0;
  bool ground_found = false;
  Eigen::Vector4d ground_plane = Eigen::Vector4d::Zero();  // n.p + d = 0, |n| = 1, cam0 frame.
  PreprocessCounts counts;
};

// The whole chain. Never throws on degenerate input: an empty result is valid data.
PreprocessedScan PreprocessScan(const PointCloud& velo_scan, const Rigid3d& cam0_from_velo,
                                const PreprocessOptions& options, int threads = 1);

// Constant-velocity de-skewing: `prev_from_cur` is the motion over one scan period in the scan's
// cam0 frame; a point taken at time fraction s (PreprocessedScan::time_fraction, plus the scan's
// time_offset) was seen from cur_from_sensor(s) = Exp(s Log(prev_from_cur)) and is moved there,
// so every point is in the frame-time pose. Raw scans (KITTI raw, sim_sequence --motion-distortion)
// need it; the KITTI odometry scans are compensated already
// (io::Dataset::scans_motion_compensated).
void DeskewScan(const Rigid3d& prev_from_cur, PreprocessedScan* scan);

// The single steps, exposed for tests and for the mapping stages. Each returns a keep mask or
// labels over `points` (cam0 frame unless stated otherwise).
// Raises each point's elevation by `angle_rad` (rotation about p x z_velo), velodyne frame.
void CorrectVerticalAngle(double angle_rad, std::vector<Eigen::Vector3d>* velo_points);
// Time fraction in [-0.5, 0.5] of a velodyne-frame point from its azimuth: the HDL-64 spins
// clockwise seen from above and KITTI stamps a scan when it faces forward (+x).
float AzimuthTimeFraction(const Eigen::Vector3d& velo_point);
// Keep mask of points with at least min_neighbors other points within radius.
std::vector<uint8_t> RadiusOutlierMask(const std::vector<Eigen::Vector3d>& points, double radius,
                                       int min_neighbors, const std::string& method = "grid",
                                       int threads = 1);
// Ground inliers (1) by RANSAC; *plane receives the plane; returns all zeros if none found.
std::vector<uint8_t> SegmentGround(const std::vector<Eigen::Vector3d>& points,
                                   const PreprocessOptions& options, Eigen::Vector4d* plane,
                                   bool* found);
// Keep mask: 0 for non-ground points in clusters with a small bounding box.
std::vector<uint8_t> SmallObjectMask(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<uint8_t>& is_ground,
                                     const PreprocessOptions& options, int64_t* clusters_removed);

}  // namespace jvl::lidar
