// Greyscale camera rendering by ray casting one ray per pixel centre: Lambertian shading of the
// procedural textures under a fixed sun, sky and distance haze, optics blur, exposure gain and
// Gaussian pixel noise.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "sim/raycaster.h"
#include "sim/scene.h"

namespace jvl::sim {

struct CameraOptions {
  double pixel_noise = 2.0;          // Standard deviation in grey levels.
  double exposure_variation = 0.12;  // Relative amplitude of the frame-to-frame gain change.
  double blur_sigma = 0.6;           // Pixels (lens / demosaicing softness).
  // Area integration: pixels at a surface boundary or where the centre-ray radiance bends by more
  // than supersample_contrast grey levels (second difference of neighbouring centre rays: a
  // texture edge) average supersample x supersample rays.
  int supersample = 2;
  double supersample_contrast = 8.0;
  double max_range = 400.0;                         // Beyond: sky.
  double haze_start = 90.0;                         // Distance haze begins (m).
  Eigen::Vector3d sun_direction{0.45, 0.35, 0.82};  // Map frame, towards the sun.
  void Check() const;
};

// Exposure gain of frame k: a smooth random-looking variation around 1.
double ExposureGain(int64_t frame, double variation, uint64_t seed);

// Renders the image seen by `camera` at world_from_cam (camera convention x right, y down,
// z forward). Pixel (i, j) is the ray through the pixel centre (i, j), as in OpenCV.
cv::Mat RenderImage(const Scene& scene, const RayCaster& caster, const PinholeCamera& camera,
                    const Rigid3d& world_from_cam, const std::vector<Box>& moving, double gain,
                    uint64_t noise_seed, const CameraOptions& options);

}  // namespace jvl::sim
