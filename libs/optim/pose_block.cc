#include "optim/pose_block.h"

#include <ceres/product_manifold.h>

namespace jvl::optim {

std::unique_ptr<ceres::Manifold> MakePoseManifold() {
  using PoseManifold =
      ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;
  return std::make_unique<PoseManifold>(ceres::EigenQuaternionManifold(),
                                        ceres::EuclideanManifold<3>());
}

}  // namespace jvl::optim
