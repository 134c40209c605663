#include "direction/vp_priors.h"

#include <Eigen/Eigenvalues>
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

namespace {

// Robust mean of unit directions: the mean of those within max(outlier_deg, 3 sigma) of it, sigma
// from the median angle to the current mean (2D Gaussian: median = 1.1774 sigma), iterated to a
// fixed point from the plain mean. Returns the indices kept (increasing; empty if none) and the
// mean in *mean.
std::vector<size_t> RobustMeanDirection(const std::vector<Eigen::Vector3d>& directions,
                                        double outlier_deg, Eigen::Vector3d* mean) {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : directions) d += x;
  d.normalize();
  std::vector<size_t> kept(directions.size());
  for (size_t i = 0; i < kept.size(); ++i) kept[i] = i;
  for (int it = 0; it < 20; ++it) {
    std::vector<double> angles;
    for (size_t i : kept) angles.push_back(AngleDeg(directions[i], d));
    const double gate = std::max(outlier_deg, 3.0 * UpperMedian(std::move(angles)) / 1.1774);
    std::vector<size_t> next;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < directions.size(); ++i)
      if (AngleDeg(directions[i], d) <= gate) {
        next.push_back(i);
        sum += directions[i];
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
  *mean = d;
  return kept;
}

}  // namespace

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
    std::vector<Eigen::Vector3d> members_rays;
    for (size_t i : idx) members_rays.push_back(rays[i]);
    Eigen::Vector3d d;
    std::vector<size_t> kept;
    for (size_t k : RobustMeanDirection(members_rays, outlier_deg, &d)) kept.push_back(idx[k]);
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

namespace {

// v - pi(R_nw d_w) of every prior whose direction is not parallel to the image plane.
std::vector<Eigen::Vector2d> DirectionErrors(const Trajectory& keyframes,
                                             const PinholeCamera& camera,
                                             const std::vector<VpPrior>& priors) {
  std::vector<Eigen::Vector2d> e;
  e.reserve(priors.size());
  for (const VpPrior& p : priors) {
    Eigen::Vector3d d =
        keyframes.world_from_cam.at(static_cast<size_t>(p.keyframe)).rotation().inverse() *
        p.direction_world;
    if (d.z() < 0) d = -d;  // unoriented, as in the cost
    if (d.z() < 1e-6) continue;
    e.push_back(p.vp - camera.Project(d));
  }
  return e;
}

}  // namespace

double MedianDirectionError(const Trajectory& keyframes, const PinholeCamera& camera,
                            const std::vector<VpPrior>& priors) {
  std::vector<double> norms;
  for (const Eigen::Vector2d& e : DirectionErrors(keyframes, camera, priors))
    norms.push_back(e.norm());
  return UpperMedian(std::move(norms));
}

Eigen::Vector2d MedianAbsDirectionError(const Trajectory& keyframes, const PinholeCamera& camera,
                                        const std::vector<VpPrior>& priors) {
  std::vector<double> u, v;
  for (const Eigen::Vector2d& e : DirectionErrors(keyframes, camera, priors)) {
    u.push_back(std::abs(e.x()));
    v.push_back(std::abs(e.y()));
  }
  return {UpperMedian(std::move(u)), UpperMedian(std::move(v))};
}

double DirectionErrorCorrelation(const Trajectory& keyframes, const PinholeCamera& camera,
                                 const std::vector<VpPrior>& priors,
                                 const std::vector<int32_t>& clusters) {
  JVL_CHECK(priors.size() == clusters.size(),
            "DirectionErrorCorrelation: " << priors.size() << " priors, " << clusters.size()
                                          << " cluster ids");
  // Errors per cluster in keyframe order (directions parallel to the image plane skipped).
  std::map<int32_t, std::vector<std::pair<int64_t, Eigen::Vector2d>>> by_cluster;
  for (size_t i = 0; i < priors.size(); ++i) {
    const auto e = DirectionErrors(keyframes, camera, {priors[i]});
    if (!e.empty()) by_cluster[clusters[i]].emplace_back(priors[i].keyframe, e.front());
  }
  double var = 0, diff = 0;
  size_t count = 0;
  for (auto& [cluster, keyed] : by_cluster) {
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Eigen::Vector2d> e;
    for (const auto& k : keyed) e.push_back(k.second);
    if (e.size() < 2) continue;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& x : e) mean += x;
    mean /= static_cast<double>(e.size());
    for (const auto& x : e) var += (x - mean).squaredNorm();
    for (size_t i = 1; i < e.size(); ++i) diff += (e[i] - e[i - 1]).squaredNorm();
    count += e.size();
  }
  if (count < 3 || var <= 0) return 0.0;
  return std::clamp(1.0 - diff / (2.0 * var), 0.0, 0.9);
}

VerticalSelection SelectVertical(const Trajectory& keyframes, const std::vector<VpRay>& rays,
                                 const Eigen::Vector3d& up_world, double max_angle_deg,
                                 double outlier_deg, double min_sigma_deg) {
  JVL_CHECK(up_world.norm() > 0.5, "SelectVertical: up direction must be a unit vector");
  const Eigen::Vector3d up = up_world.normalized();
  std::map<int64_t, size_t> row_of;
  for (size_t r = 0; r < keyframes.size(); ++r) row_of[keyframes.frames[r]] = r;
  // Per keyframe row: the candidate ray and its world direction (oriented like up).
  std::map<size_t, std::pair<Eigen::Vector3d, Eigen::Vector3d>> best;
  for (const VpRay& v : rays) {
    const auto it = row_of.find(v.frame);
    if (it == row_of.end() || !v.ray.allFinite() || v.ray.norm() < 0.5) continue;
    const Eigen::Vector3d ray = v.ray.normalized();
    Eigen::Vector3d w = keyframes.world_from_cam[it->second].rotation() * ray;
    if (w.dot(up) < 0) w = -w;
    if (AngleDeg(w, up) > max_angle_deg) continue;
    const auto b = best.find(it->second);
    if (b == best.end() || w.dot(up) > b->second.second.dot(up)) best[it->second] = {ray, w};
  }
  VerticalSelection out;
  out.candidates = static_cast<int64_t>(best.size());
  if (best.empty()) return out;
  std::vector<size_t> rows;
  std::vector<Eigen::Vector3d> world;
  for (const auto& [row, rw] : best) {
    rows.push_back(row);
    world.push_back(rw.second);
  }
  Eigen::Vector3d d;
  std::vector<size_t> kept;
  for (size_t k : RobustMeanDirection(world, outlier_deg, &d)) kept.push_back(rows[k]);
  out.outliers = out.candidates - static_cast<int64_t>(kept.size());
  if (kept.empty()) return out;
  std::vector<double> angles;
  for (const size_t row : kept) {
    out.rows.push_back(static_cast<int64_t>(row));
    out.rays.push_back(best.at(row).first);
    angles.push_back(AngleDeg(best.at(row).second, d));
  }
  out.direction = d;
  // Errors in the tangent plane of d, in keyframe order (kept is sorted by row).
  const Eigen::Matrix<double, 3, 2> tangent = TangentBasis(d);
  std::vector<Eigen::Vector2d> e;
  for (const size_t row : kept) e.push_back(tangent.transpose() * best.at(row).second);
  for (const auto& x : e) out.errors_deg.push_back(x * kDegPerRad);
  if (e.size() >= 3) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero(), var = Eigen::Vector2d::Zero(),
                    diff = Eigen::Vector2d::Zero();
    for (const auto& x : e) mean += x;
    mean /= static_cast<double>(e.size());
    for (const auto& x : e) var += (x - mean).cwiseAbs2();
    var /= static_cast<double>(e.size());
    for (size_t i = 1; i < e.size(); ++i) diff += (e[i] - e[i - 1]).cwiseAbs2();
    diff /= static_cast<double>(e.size() - 1);
    double rho = 0;
    for (int k = 0; k < 2; ++k) rho += var[k] > 0 ? 0.5 * (1.0 - diff[k] / (2.0 * var[k])) : 0.0;
    out.rho = std::clamp(rho, 0.0, 0.9);
    out.inflation = std::sqrt((1.0 + out.rho) / (1.0 - out.rho));
  }
  out.sigma_deg = std::max(min_sigma_deg, UpperMedian(std::move(angles)) / 1.1774) * out.inflation;
  return out;
}

SlowError MeasureSlowError(const std::vector<int64_t>& frames,
                           const std::vector<Eigen::Vector2d>& errors_deg, int half_window) {
  JVL_CHECK(frames.size() == errors_deg.size(),
            "MeasureSlowError: " << frames.size() << " frames, " << errors_deg.size() << " errors");
  JVL_CHECK(half_window >= 0, "MeasureSlowError: half_window must be >= 0, got " << half_window);
  JVL_CHECK(std::is_sorted(frames.begin(), frames.end()),
            "MeasureSlowError: frames must be ascending");
  SlowError out;
  const size_t n = errors_deg.size();
  if (n < 3) return out;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& x : errors_deg) mean += x;
  mean /= static_cast<double>(n);
  Eigen::Matrix2d white = Eigen::Matrix2d::Zero();
  for (size_t i = 1; i < n; ++i) {
    const Eigen::Vector2d d = errors_deg[i] - errors_deg[i - 1];
    white += d * d.transpose();
  }
  white /= 2.0 * static_cast<double>(n - 1);
  out.white_deg = white.diagonal().cwiseSqrt();
  // Prefix sums over the de-meaned errors; the window of sample i holds the samples whose frame
  // is within half_window of frames[i].
  std::vector<Eigen::Vector2d> prefix(n + 1, Eigen::Vector2d::Zero());
  for (size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + (errors_deg[i] - mean);
  Eigen::Matrix2d slow = Eigen::Matrix2d::Zero();
  size_t lo = 0, hi = 0;
  for (size_t i = 0; i < n; ++i) {
    while (frames[lo] < frames[i] - half_window) ++lo;
    while (hi < n && frames[hi] <= frames[i] + half_window) ++hi;
    const double count = static_cast<double>(hi - lo);
    const Eigen::Vector2d m = (prefix[hi] - prefix[lo]) / count;
    slow += m * m.transpose() - white * (1.0 / count - 1.0 / static_cast<double>(n));
  }
  slow /= static_cast<double>(n);
  out.low_frequency_deg = slow.diagonal().cwiseMax(0.0).cwiseSqrt();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(slow);
  out.slow_deg = std::sqrt(std::max(0.0, eigen.eigenvalues().maxCoeff()));
  return out;
}

}  // namespace jvl::direction
