#include "direction/vp_priors.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/check.h"
#include "core/statistics.h"
#include "geometry/angles.h"

namespace jvl::direction {

DirectionSelection SelectDirections(const Trajectory& keyframes,
                                    const std::vector<VpAssociation>& associations) {
  DirectionSelection out;
  for (const auto& a : associations) {
    const auto row = keyframes.IndexOf(a.frame);
    if (!row) {
      ++out.not_keyframe;
      continue;
    }
    // A VP at infinity has no finite pixel v for Eq. (6); it is skipped (docs/global_opt.md).
    if (!a.uv.allFinite()) {
      ++out.at_infinity;
      continue;
    }
    JVL_CHECK(a.direction_world.allFinite() && a.direction_world.norm() > 0.5,
              "direction prior of cluster " << a.cluster << " (frame " << a.frame
                                            << ") is not a unit vector");
    out.priors.push_back({static_cast<int64_t>(*row), a.uv, a.direction_world.normalized()});
    out.clusters.push_back(a.cluster);
  }
  return out;
}

DirectionRefit RefitDirections(const Trajectory& keyframes, const PinholeCamera& camera,
                               const DirectionSelection& selection, double outlier_deg,
                               int min_support) {
  JVL_CHECK(selection.clusters.size() == selection.priors.size(),
            "RefitDirections: " << selection.clusters.size() << " cluster ids for "
                                << selection.priors.size() << " priors");
  // World direction of every VP under the current rotation, oriented like the old d_w.
  std::map<int32_t, std::vector<size_t>> members;
  std::vector<Eigen::Vector3d> rays(selection.priors.size());
  for (size_t i = 0; i < selection.priors.size(); ++i) {
    const VpPrior& p = selection.priors[i];
    JVL_CHECK(p.keyframe >= 0 && static_cast<size_t>(p.keyframe) < keyframes.size(),
              "RefitDirections: keyframe row " << p.keyframe << " out of range");
    const Eigen::Vector3d cam_ray = camera.Unproject(p.vp).normalized();
    Eigen::Vector3d w = keyframes.world_from_cam[p.keyframe].rotation() * cam_ray;
    if (w.dot(p.direction_world) < 0) w = -w;
    rays[i] = w;
    members[selection.clusters[i]].push_back(i);
  }
  DirectionRefit out;
  out.selection.not_keyframe = selection.not_keyframe;
  out.selection.at_infinity = selection.at_infinity;
  for (const auto& [cluster, idx] : members) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (size_t i : idx) d += rays[i];
    d.normalize();
    // Robust mean: gate = max(outlier_deg, 3 sigma) with sigma from the median angle to the
    // current mean (2D Gaussian: median = 1.1774 sigma); iterate to a fixed point.
    std::vector<size_t> kept = idx;
    for (int it = 0; it < 20; ++it) {
      std::vector<double> angles;
      for (size_t i : kept) angles.push_back(AngleDeg(rays[i], d));
      const double gate = std::max(outlier_deg, 3.0 * UpperMedian(std::move(angles)) / 1.1774);
      std::vector<size_t> next;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (size_t i : idx)
        if (AngleDeg(rays[i], d) <= gate) {
          next.push_back(i);
          sum += rays[i];
        }
      if (next.empty()) {
        kept.clear();
        break;
      }
      const bool stable = next == kept;
      kept = std::move(next);
      d = sum.normalized();
      if (stable) break;
    }
    out.outliers += static_cast<int64_t>(idx.size() - kept.size());
    if (static_cast<int>(kept.size()) < min_support) {
      out.small_cluster_vps += static_cast<int64_t>(kept.size());
      continue;
    }
    out.directions[cluster] = d;
    const Eigen::Vector3d old = selection.priors[idx.front()].direction_world;
    out.change_deg[cluster] = std::acos(std::clamp(old.dot(d), -1.0, 1.0)) * 180.0 / M_PI;
    for (size_t i : kept) {
      VpPrior p = selection.priors[i];
      p.direction_world = d;
      out.selection.priors.push_back(p);
      out.selection.clusters.push_back(cluster);
    }
  }
  return out;
}

double MedianDirectionError(const Trajectory& keyframes, const PinholeCamera& camera,
                            const std::vector<VpPrior>& priors) {
  std::vector<double> e;
  e.reserve(priors.size());
  for (const VpPrior& p : priors) {
    Eigen::Vector3d d =
        keyframes.world_from_cam.at(static_cast<size_t>(p.keyframe)).rotation().inverse() *
        p.direction_world;
    if (d.z() < 0) d = -d;  // unoriented, as in the cost
    if (d.z() < 1e-6) continue;
    e.push_back((camera.Project(d) - p.vp).norm());
  }
  return UpperMedian(std::move(e));
}

}  // namespace jvl::direction
