#include "eval/metrics.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "eval/pose_series.h"

namespace jvl::eval {

namespace {
constexpr double kRadToDeg = 180.0 / M_PI;
}  // namespace

ErrorStats ComputeStats(const std::vector<double>& values) {
  ErrorStats s;
  s.count = static_cast<int64_t>(values.size());
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  double sum = 0, sum_sq = 0;
  s.min = values.front();
  s.max = values.front();
  for (double v : values) {
    sum += v;
    sum_sq += v * v;
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0;  // Two-pass variance: no cancellation for large means.
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const size_t mid = sorted.size() / 2;
  s.median = sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  return s;
}

ErrorStats PoolStats(const std::vector<const std::vector<double>*>& parts) {
  std::vector<double> all;
  for (const auto* p : parts) all.insert(all.end(), p->begin(), p->end());
  return ComputeStats(all);
}

std::vector<double> TrajectoryDistances(const std::vector<Eigen::Matrix4d>& poses) {
  std::vector<double> dist(poses.size(), 0.0);
  for (size_t i = 1; i < poses.size(); ++i) {
    const double dx = poses[i - 1](0, 3) - poses[i](0, 3);
    const double dy = poses[i - 1](1, 3) - poses[i](1, 3);
    const double dz = poses[i - 1](2, 3) - poses[i](2, 3);
    dist[i] = dist[i - 1] + std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  return dist;
}

ApeResult ComputeApe(const PairedPoses& paired) {
  ApeResult r;
  for (size_t i = 0; i < paired.size(); ++i) {
    if (!paired.has_est[i]) continue;
    const Eigen::Vector3d d = paired.gt[i].block<3, 1>(0, 3) - paired.est[i].block<3, 1>(0, 3);
    r.frames.push_back(paired.frames[i]);
    r.translation_m.push_back(std::sqrt(d.x() * d.x() + d.y() * d.y() + d.z() * d.z()));
    const Eigen::Matrix4d error = paired.gt[i].inverse() * paired.est[i];
    r.rotation_deg.push_back(DevkitRotationAngle(error) * kRadToDeg);
  }
  r.translation_stats = ComputeStats(r.translation_m);
  r.rotation_stats = ComputeStats(r.rotation_deg);
  return r;
}

ApeComponents ComputeApeComponents(const PairedPoses& paired, const Eigen::Vector3d& up) {
  ApeComponents c;
  if (paired.size() == 0) return c;
  c.up = up.norm() > 0 ? up.normalized()
                       : Eigen::Vector3d(-paired.gt.front().block<3, 1>(0, 1).normalized());
  JVL_CHECK(c.up.allFinite(), "APE components: the up vector is not finite");
  const size_t n = paired.size();
  auto position = [&](size_t i) -> Eigen::Vector3d { return paired.gt[i].block<3, 1>(0, 3); };
  for (size_t i = 0; i < n; ++i) {
    if (!paired.has_est[i]) continue;
    // Direction of travel: from the last row >= 1 m behind to the first row >= 1 m ahead.
    size_t ahead = i, behind = i;
    while (ahead + 1 < n && (position(ahead) - position(i)).norm() < 1.0) ++ahead;
    while (behind > 0 && (position(behind) - position(i)).norm() < 1.0) --behind;
    Eigen::Vector3d travel = position(ahead) - position(behind);
    if (travel.norm() < 1.0) travel = paired.gt[i].block<3, 1>(0, 2);  // Standing: camera z.
    Eigen::Vector3d along = travel - travel.dot(c.up) * c.up;
    if (along.norm() < 1e-6 * travel.norm()) {
      ++c.skipped;
      continue;
    }
    along.normalize();
    const Eigen::Vector3d lateral = c.up.cross(along);
    const Eigen::Vector3d d = paired.est[i].block<3, 1>(0, 3) - position(i);
    const Eigen::Matrix3d error =
        paired.gt[i].block<3, 3>(0, 0).transpose() * paired.est[i].block<3, 3>(0, 0);
    const Eigen::AngleAxisd aa(error);
    const Eigen::Vector3d w = aa.angle() * kRadToDeg * aa.axis();
    c.frames.push_back(paired.frames[i]);
    c.along_m.push_back(d.dot(along));
    c.lateral_m.push_back(d.dot(lateral));
    c.vertical_m.push_back(d.dot(c.up));
    c.pitch_deg.push_back(w.x());
    c.yaw_deg.push_back(w.y());
    c.roll_deg.push_back(w.z());
  }
  static_cast<ApeComponentStats&>(c) = PoolApeComponents({&c});
  return c;
}

ApeComponentStats PoolApeComponents(const std::vector<const ApeComponents*>& parts) {
  auto pool = [&](std::vector<double> ApeComponents::*values) {
    std::vector<const std::vector<double>*> v;
    for (const ApeComponents* p : parts) v.push_back(&(p->*values));
    return PoolStats(v);
  };
  ApeComponentStats s;
  s.along = pool(&ApeComponents::along_m);
  s.lateral = pool(&ApeComponents::lateral_m);
  s.vertical = pool(&ApeComponents::vertical_m);
  s.pitch = pool(&ApeComponents::pitch_deg);
  s.yaw = pool(&ApeComponents::yaw_deg);
  s.roll = pool(&ApeComponents::roll_deg);
  return s;
}

RpeUnit ParseRpeUnit(const std::string& name) {
  if (name == "frames" || name == "f") return RpeUnit::kFrames;
  if (name == "m") return RpeUnit::kMetres;
  JVL_THROW("unknown RPE unit '" << name << "' (expected frames or m)");
}

std::string ToString(RpeUnit unit) { return unit == RpeUnit::kFrames ? "frames" : "m"; }

void RpeOptions::Check() const {
  JVL_CHECK(std::isfinite(delta) && delta > 0, "delta must be > 0 (got " << delta << ")");
  JVL_CHECK(unit != RpeUnit::kFrames || delta == std::floor(delta),
            "delta must be a whole number of frames (got " << delta << ")");
}

RpeResult ComputeRpe(const PairedPoses& paired, const std::vector<double>& gt_distances,
                     const RpeOptions& options) {
  options.Check();
  RpeResult r;
  for (size_t i = 0; i < paired.size(); ++i) {
    if (!paired.has_est[i]) continue;
    size_t j = paired.size();
    if (options.unit == RpeUnit::kFrames) {
      const int64_t target = paired.frames[i] + static_cast<int64_t>(options.delta);
      const auto it = std::lower_bound(paired.frames.begin() + i, paired.frames.end(), target);
      if (it != paired.frames.end() && *it == target) j = it - paired.frames.begin();
    } else {
      const auto it = std::upper_bound(gt_distances.begin() + i, gt_distances.end(),
                                       gt_distances[i] + options.delta);
      j = it - gt_distances.begin();
    }
    if (j >= paired.size() || !paired.has_est[j]) continue;
    const Eigen::Matrix4d gt_rel = paired.gt[i].inverse() * paired.gt[j];
    const Eigen::Matrix4d est_rel = paired.est[i].inverse() * paired.est[j];
    const Eigen::Matrix4d error = gt_rel.inverse() * est_rel;
    const double t = TranslationNorm(error);
    const double path = gt_distances[j] - gt_distances[i];
    r.first_frame.push_back(paired.frames[i]);
    r.last_frame.push_back(paired.frames[j]);
    r.translation_m.push_back(t);
    r.rotation_deg.push_back(DevkitRotationAngle(error) * kRadToDeg);
    if (path > 0) r.translation_percent.push_back(t / path * 100.0);
  }
  r.translation_stats = ComputeStats(r.translation_m);
  r.percent_stats = ComputeStats(r.translation_percent);
  r.rotation_stats = ComputeStats(r.rotation_deg);
  return r;
}

}  // namespace jvl::eval
