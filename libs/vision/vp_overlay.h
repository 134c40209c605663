// Debug overlay of a VP result: segments coloured by their VP (grey when unassigned) and a
// marker per VP (a ring at its pixel, or an arrow at the border pointing towards it).
#pragma once

#include <opencv2/core.hpp>

#include "geometry/camera.h"
#include "vision/vanishing_points.h"

namespace jvl {

// Returns a BGR copy of `image` with the overlay drawn on it.
cv::Mat DrawVpOverlay(const cv::Mat& image, const PinholeCamera& camera, const VpResult& result);

}  // namespace jvl
