// The ground plane of the prior's world frame and motion along it (Alg. 2 works on ground-plane
// projections: the forward direction fd_i, the slope of cluster centres, 2D positions).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "geometry/trajectory.h"

namespace jvl::direction {

// Orthonormal, right-handed (e1 x e2 = up): e1 spans with e2 the ground plane.
struct GroundFrame {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
  Eigen::Vector2d Project(const Eigen::Vector3d& p) const { return {p.dot(e1), p.dot(e2)}; }
};

// up: the given vector, or (if zero) minus the y axis of the first prior camera (KITTI cam0 has
// y down; with the first pose at identity this is world -y and the ground is the x-z plane).
// e1 is the first camera's x axis projected onto the ground (falls back to another axis when
// parallel to up), e2 = up x e1: for KITTI e1 = x (right), e2 = z (forward).
GroundFrame MakeGroundFrame(const Trajectory& prior, const Eigen::Vector3d& up);

// Unit ground-plane motion direction fd_i per prior pose (Alg. 2 line 3): t(j) - t(k) with j the
// first pose ahead at least baseline/2 from pose i and k the last pose behind at least baseline/2
// (one side only near the ends). Where the prior does not move that far, the ground projection
// of the camera's optical axis is used.
std::vector<Eigen::Vector2d> ForwardDirections(const Trajectory& prior, const GroundFrame& ground,
                                               double baseline);

// Slope of a direction's ground projection as a heading in [0, 180) deg (sign-free, Alg. 2 l. 13).
double SlopeDeg(const GroundFrame& ground, const Eigen::Vector3d& direction);

}  // namespace jvl::direction
