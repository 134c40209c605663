// Procedural surface appearance: grey-level albedo for the camera (lane markings, paving,
// facade floors and windows, foliage) and reflectance for the LiDAR.
#pragma once

#include <Eigen/Core>

#include "sim/raycaster.h"
#include "sim/scene.h"

namespace jvl::sim {

struct Surface {
  float albedo = 0.5f;       // Camera: diffuse grey level in [0, 1].
  float reflectance = 0.3f;  // LiDAR: intensity before the incidence term, [0, 1].
  bool glass = false;        // Windows: the LiDAR often gets no return.
  bool marking = false;      // Lane marking / crossing stripe on the road.
};

// Appearance of the surface hit at world point p. footprint (m) is the size of the sensor's
// sample on the surface (0: a point): noise textures finer than about two footprints average out
// within the sample and fade to their mean (band-limited textures, as a pixel integrates them).
Surface ShadeSurface(const Scene& scene, const Hit& hit, const Eigen::Vector3d& p,
                     double footprint = 0.0);

}  // namespace jvl::sim
