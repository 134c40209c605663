// Top view of the prior trajectory with the frames of each direction cluster in its own colour
// and the cluster's direction drawn as an arrow at its centroid (the paper's figure of direction
// priors). Rendering only; the tool writes the image.
#pragma once

#include <opencv2/core.hpp>

#include "direction/direction_cluster.h"
#include "geometry/trajectory.h"

namespace jvl::direction {

struct TopViewOptions {
  int size_px = 1000;  // Longer side of the image.
  int margin_px = 40;
  double arrow_m = 0;  // Arrow length in metres (0: 8 % of the trajectory extent).
};

// BGR 8-bit image. Axes: ground_e1 to the right, ground_e2 up (KITTI: x right, z up).
cv::Mat RenderTopView(const Trajectory& prior, const DirectionClusterResult& result,
                      const TopViewOptions& options = {});

}  // namespace jvl::direction
