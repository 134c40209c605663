// Keyframe pose parameter blocks for Ceres.
//
// A pose block is world_from_cam stored as 7 doubles [qx qy qz qw tx ty tz] (Rigid3d::ToArray),
// so the quaternion part maps onto ceres::EigenQuaternionManifold ([x y z w], Plus = Exp(delta) *
// q, a perturbation in the world frame) and the translation onto EuclideanManifold<3>. The tangent
// space is [omega (3); t (3)]. Ceres 2.1 (Debian) provides Manifolds, so no LocalParameterization.
#pragma once

#include <ceres/manifold.h>

#include <array>
#include <memory>

#include "geometry/rigid3.h"

namespace jvl::optim {

constexpr int kPoseBlockSize = 7;
constexpr int kPoseTangentSize = 6;
using PoseBlock = std::array<double, kPoseBlockSize>;

// ProductManifold(EigenQuaternionManifold, EuclideanManifold<3>) for one pose block.
std::unique_ptr<ceres::Manifold> MakePoseManifold();

inline PoseBlock ToPoseBlock(const Rigid3d& world_from_cam) { return world_from_cam.ToArray(); }
inline Rigid3d FromPoseBlock(const PoseBlock& block) { return Rigid3d::FromArray(block.data()); }

}  // namespace jvl::optim
