// Mean-shift mode seeking (Comaniciu and Meer 2002) with a truncated Gaussian kernel, used twice
// by the bi-level clustering of Algorithm 2 (supplement 1.4): on unit directions (points on the
// sphere, distance = angle) and on 2D ground positions (Euclidean distance).
//
// Deterministic: searches start in the order of the points (one per seed cell), neighbours are
// summed in a fixed order, and modes are merged in seed order; cluster k is the k-th new mode.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace jvl::direction {

struct MeanShiftOptions {
  // Gaussian kernel standard deviation: radians on the sphere, metres in the plane.
  double bandwidth = 0.05;
  // The kernel is cut at truncation * bandwidth (points farther away get weight 0).
  double truncation = 3.0;
  int max_iterations = 100;
  // Stop when a shift moves the estimate by less than tolerance * bandwidth.
  double tolerance = 1e-4;
  // Converged modes closer than merge_radius * bandwidth are one cluster.
  double merge_radius = 0.5;
  // Bin seeding: start one search per cell of seed_bin * bandwidth (0 = one per point). Points
  // share the label of their cell's search; this bounds the cost for dense clusters.
  double seed_bin = 0.25;
  void Check() const;
};

struct MeanShiftResult {
  std::vector<int> labels;  // Cluster of every input point, 0..modes.size()-1.
  // Mode of every cluster (unit vectors for the sphere version, zero-padded to 3D in the plane).
  std::vector<Eigen::Vector3d> modes;
  std::vector<int> sizes;    // Number of points per cluster.
  int total_iterations = 0;  // Sum over all points (diagnostic).
};

// Mean-shift on unit vectors: the kernel is exp(-c^2 / (2 h^2)) with c = 2 sin(theta / 2) the
// chord of the angle theta between two directions (von Mises-Fisher, kappa = 1/h^2); each step
// moves to the normalised weighted mean. Inputs are renormalised. Distances (support, merge,
// tolerance) are chords, equal to angles within 1 % below 20 deg.
MeanShiftResult MeanShiftSphere(const std::vector<Eigen::Vector3d>& directions,
                                const MeanShiftOptions& options);

// Mean-shift on 2D points with the Euclidean Gaussian kernel.
MeanShiftResult MeanShiftPlane(const std::vector<Eigen::Vector2d>& points,
                               const MeanShiftOptions& options);

}  // namespace jvl::direction
