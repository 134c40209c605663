// Triangle mesh of a laid-out scene: terrain grid, kerbs, boxes, prisms and irregular blobs.
#pragma once

#include "sim/random.h"
#include "sim/scene.h"

namespace jvl::sim {

// Fills scene.mesh from the object lists (deterministic given rng's state).
void BuildSceneMesh(Scene& scene, Rng& rng);

// A box from z0 to z1 over a footprint centred at c with yaw and horizontal size (sx, sy).
// Walls get texture frames (u along the wall, v up from ground_z), the top and bottom (x, y).
void AddBox(Mesh& mesh, const Eigen::Vector2d& c, double yaw, double sx, double sy, double z0,
            double z1, double ground_z, Material wall, Material top, int32_t object, float albedo);

}  // namespace jvl::sim
