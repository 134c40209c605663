#include "optim/correction.h"

#include <algorithm>

#include "core/check.h"
#include "core/statistics.h"

namespace jvl::optim {

std::vector<Rigid3d> DistributeCorrection(const std::vector<Rigid3d>& world_from_cam,
                                          const Rigid3d& corrected_world_from_cam_n,
                                          const std::vector<double>& positions) {
  const size_t count = world_from_cam.size();
  JVL_CHECK(count >= 2, "DistributeCorrection needs at least two keyframes (got " << count << ")");
  JVL_CHECK(
      positions.empty() || positions.size() == count,
      "DistributeCorrection: " << positions.size() << " positions for " << count << " keyframes");
  auto position = [&](size_t i) {
    return positions.empty() ? static_cast<double>(i) : positions[i];
  };
  const double span = position(count - 1) - position(0);
  JVL_CHECK(span > 0, "DistributeCorrection: keyframe positions must increase");
  // Line 1-3, in the paper's cam_from_world convention.
  const Rigid3d cam_from_world_n = world_from_cam.back().Inverse();
  const Rigid3d corrected_cam_from_world_n = corrected_world_from_cam_n.Inverse();
  const Rigid3d delta = corrected_cam_from_world_n * cam_from_world_n.Inverse();
  const Eigen::Vector3d delta_phi = LogSO3(delta.rotation());
  const Eigen::Vector3d delta_t = delta.translation();
  std::vector<Rigid3d> out(world_from_cam);
  for (size_t i = 1; i + 1 < count; ++i) {  // lines 4-11
    const double f = (position(i) - position(0)) / span;
    const Rigid3d delta_i(ExpSO3(f * delta_phi), f * delta_t);
    out[i] = (delta_i * world_from_cam[i].Inverse()).Inverse();
  }
  out.back() = corrected_world_from_cam_n;
  return out;
}

Rigid3d KeyframeCorrection(const Rigid3d& prior_world_from_cam,
                           const Rigid3d& optimized_world_from_cam) {
  return optimized_world_from_cam * prior_world_from_cam.Inverse();
}

Trajectory InterpolateFullRate(const Trajectory& prior,
                               const std::map<int64_t, Rigid3d>& optimized_keyframes,
                               double step_factor, int64_t* bridged) {
  prior.Check("prior trajectory");
  JVL_CHECK(!optimized_keyframes.empty(), "full-rate interpolation needs at least one keyframe");
  // Keyframes as (row in prior, correction), in frame order (the map is sorted by id).
  std::vector<size_t> rows;
  std::vector<Rigid3d> corrections;
  for (const auto& [frame, pose] : optimized_keyframes) {
    const auto row = prior.IndexOf(frame);
    JVL_CHECK(row.has_value(), "keyframe " << frame << " is not a frame of the prior trajectory");
    rows.push_back(*row);
    corrections.push_back(KeyframeCorrection(prior.world_from_cam[*row], pose));
  }
  auto time = [&](size_t row) {
    return prior.has_timestamps() ? prior.timestamps[row] : static_cast<double>(prior.frames[row]);
  };
  // Intervals where the prior's motion disagrees with the optimised one (a step inside).
  std::vector<uint8_t> bridge(rows.size(), 0);  // bridge[k]: interval rows[k-1] .. rows[k]
  if (step_factor > 0 && rows.size() >= 2) {
    std::vector<double> d(rows.size(), 0.0);
    for (size_t k = 1; k < rows.size(); ++k) {
      const Rigid3d& a = optimized_keyframes.at(prior.frames[rows[k - 1]]);
      const Rigid3d& b = optimized_keyframes.at(prior.frames[rows[k]]);
      const Rigid3d mismatch =
          (a.Inverse() * b).Inverse() *
          (prior.world_from_cam[rows[k - 1]].Inverse() * prior.world_from_cam[rows[k]]);
      d[k] = mismatch.translation().norm() / static_cast<double>(rows[k] - rows[k - 1]);
    }
    const double threshold = step_factor * Median(std::vector<double>(d.begin() + 1, d.end()));
    for (size_t k = 1; k < rows.size(); ++k)
      bridge[k] = rows[k] - rows[k - 1] >= 2 && d[k] > threshold ? 1 : 0;
  }
  if (bridged != nullptr) *bridged = std::count(bridge.begin(), bridge.end(), 1);
  Trajectory out = prior;
  size_t k = 0;  // first keyframe with rows[k] >= row
  for (size_t row = 0; row < prior.size(); ++row) {
    while (k < rows.size() && rows[k] < row) ++k;
    Rigid3d correction;
    if (k == 0) {
      correction = corrections.front();
    } else if (k == rows.size()) {
      correction = corrections.back();
    } else if (rows[k] == row) {
      correction = corrections[k];
    } else {
      const double t0 = time(rows[k - 1]);
      const double t1 = time(rows[k]);
      const double s = t1 > t0 ? std::clamp((time(row) - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
      if (bridge[k]) {
        out.world_from_cam[row] = Interpolate(optimized_keyframes.at(prior.frames[rows[k - 1]]),
                                              optimized_keyframes.at(prior.frames[rows[k]]), s);
        continue;
      }
      correction = Interpolate(corrections[k - 1], corrections[k], s);
    }
    out.world_from_cam[row] = correction * prior.world_from_cam[row];
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    out.world_from_cam[rows[i]] = optimized_keyframes.at(prior.frames[rows[i]]);
  }
  return out;
}

}  // namespace jvl::optim
