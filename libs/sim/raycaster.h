// Ray casting against the static scene mesh (a BVH of its own, the same bytes on every CPU) and
// against moving boxes (analytic slab test), combined into the nearest hit.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <vector>

#include "sim/scene.h"

namespace jvl::sim {

struct Hit {
  double t = std::numeric_limits<double>::infinity();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // Unit, facing the ray origin.
  int32_t face = -1;                                 // Face of the static mesh, or -1.
  int32_t triangle = -1;                             // Triangle of the static mesh, or -1.
  int32_t dynamic = -1;                              // Index of the moving box hit, or -1.
  bool valid() const { return face >= 0 || dynamic >= 0; }
};

class RayCaster {
 public:
  // Builds the BVH (single-threaded, so that the structure is the same on every run).
  explicit RayCaster(const Mesh& mesh);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // Nearest static hit along o + t d (d unit) with t in (t_min, t_max); an exact tie goes to the
  // lower triangle index. Thread-safe. hint: a triangle likely hit (the neighbouring ray's), tried
  // first to prune the search; it changes the time taken, never the answer.
  Hit Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max,
                int32_t hint = -1) const;
  // Up to eight rays with a common origin (camera rows), each hinted by the one before it (the
  // first by `hint`).
  void Intersect8(const Eigen::Vector3d& o, const Eigen::Vector3d* d, int count, double t_min,
                  double t_max, Hit* hits, int32_t hint = -1) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Nearest hit among oriented boxes (moving cars); updates `hit` if closer.
void IntersectBoxes(const std::vector<Box>& boxes, const Eigen::Vector3d& o,
                    const Eigen::Vector3d& d, Hit* hit);

}  // namespace jvl::sim
