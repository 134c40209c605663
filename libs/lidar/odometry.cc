#include "lidar/odometry.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "core/check.h"
#include "core/timer.h"

namespace jvl::lidar {
namespace {

// Candidates looked at per sampling list, as a multiple of s (the lists are only partially
// sorted; sampling stops at s accepted points).
constexpr size_t kListLengthFactor = 20;

// Constant velocity within the scan: a point taken at fraction s of the period was seen from
// cur_from_sensor(s) = Exp(s Log(prev_from_cur)).
void Deskew(const Rigid3d& prev_from_cur, PreprocessedScan* scan) {
  const Vector6d xi = LogSE3(prev_from_cur);
  for (size_t i = 0; i < scan->points.size(); ++i) {
    scan->points[i] = ExpSE3(static_cast<double>(scan->time_fraction[i]) * xi) * scan->points[i];
  }
}

}  // namespace

void OdometryOptions::Check() const {
  preprocess.Check();
  surface.Check();
  registration.Check();
  JVL_CHECK(scan_map_size >= 1, "--scan-map-size must be >= 1, got " << scan_map_size);
  JVL_CHECK(samples_per_list >= 1, "--samples-per-list must be >= 1, got " << samples_per_list);
  JVL_CHECK(initial_search_scale >= 1,
            "--initial-search-scale must be >= 1, got " << initial_search_scale);
}

const char* ToString(FrameStatus status) {
  switch (status) {
    case FrameStatus::kOk:
      return "ok";
    case FrameStatus::kFirstFrame:
      return "first-frame";
    case FrameStatus::kDegenerate:
      return "degenerate";
    case FrameStatus::kMotionModel:
      return "motion-model";
  }
  return "unknown";
}

Odometry::Odometry(const Rigid3d& cam0_from_velo, const OdometryOptions& options, int threads)
    : cam0_from_velo_(cam0_from_velo),
      options_(options),
      threads_(std::max(1, threads)),
      model_(options.registration.search_radius) {
  options_.Check();
}

Rigid3d Odometry::PredictMotion() const {
  if (frames_.size() < 2) return Rigid3d();
  const Rigid3d& a = frames_[frames_.size() - 2].world_from_cam;
  const Rigid3d& b = frames_.back().world_from_cam;
  return a.Inverse() * b;
}

RegistrationResult Odometry::Register(const ScanSurface& surface, const Rigid3d& predicted,
                                      const RegistrationOptions& options, int per_list,
                                      int* samples) const {
  // IMLS-SLAM sampling: s points per list with a model neighbour within r at the prediction.
  const auto lists = SamplingLists(surface, kListLengthFactor * static_cast<size_t>(per_list));
  const double r = options.search_radius;
  const std::vector<int> picked = SelectSamples(lists, surface.size(), per_list, [&](int i) {
    return model_.HasNeighbor(predicted * surface.points[i], r);
  });
  std::vector<Eigen::Vector3d> points;
  std::vector<double> planarity;
  points.reserve(picked.size());
  for (const int i : picked) {
    points.push_back(surface.points[i]);
    planarity.push_back(surface.planarity[i]);
  }
  *samples = static_cast<int>(points.size());
  return RegisterScan(points, model_, predicted, options, threads_, &planarity);
}

RegistrationResult Odometry::Track(const ScanSurface& surface, const Rigid3d& predicted,
                                   int* samples) const {
  const int s = options_.samples_per_list;
  Rigid3d start = predicted;
  if (frames_.size() == 1 && options_.initial_search_scale > 1) {
    // No velocity yet: a coarse registration with wider neighbourhoods seeds the normal one,
    // on a quarter of the samples (the wide neighbourhoods make each query ~20x dearer).
    RegistrationOptions coarse = options_.registration;
    const double k = options_.initial_search_scale;
    coarse.search_radius *= k;
    coarse.kernel_h *= k;
    coarse.max_distance *= k;
    coarse.robust_scale *= k;
    const RegistrationResult first =
        Register(surface, predicted, coarse, std::max(1, s / 4), samples);
    if (first.ok) start = first.world_from_scan;
  }
  RegistrationResult reg = Register(surface, start, options_.registration, s, samples);
  if (reg.degenerate && start.translation() != predicted.translation()) {
    // Along unobservable directions the motion model, not the coarse pass, must be kept.
    reg = Register(surface, predicted, options_.registration, s, samples);
  }
  return reg;
}

void Odometry::UpdateModel(int64_t frame, const ScanSurface& surface,
                           const Rigid3d& world_from_cam) {
  std::vector<Eigen::Vector3d> points, normals;
  points.reserve(surface.size());
  normals.reserve(surface.size());
  const Eigen::Quaterniond& q = world_from_cam.rotation();
  for (size_t i = 0; i < surface.size(); ++i) {
    if (!surface.valid[i]) continue;
    points.push_back(world_from_cam * surface.points[i]);
    normals.push_back(q * surface.normals[i]);
  }
  if (points.empty()) return;
  model_.AddScan(frame, points, normals);
  while (model_.num_scans() > static_cast<size_t>(options_.scan_map_size)) {
    model_.RemoveScan(model_.scan_ids().front());
  }
}

OdometryFrame Odometry::ProcessScan(const PointCloud& velo_scan, int64_t frame,
                                    int64_t non_finite_dropped) {
  const Timer timer;
  OdometryFrame out;
  out.frame = frame;
  FrameDiagnostics& d = out.diagnostics;
  PreprocessedScan pre = PreprocessScan(velo_scan, cam0_from_velo_, options_.preprocess, threads_);
  d.non_finite_points = non_finite_dropped + pre.counts.non_finite;
  if (pre.counts.non_finite > 0) {
    spdlog::warn("frame {}: dropped {} non-finite points", frame, pre.counts.non_finite);
  }
  d.points_after_filter = static_cast<int64_t>(pre.points.size());
  d.preprocess_ms = timer.ElapsedMs();
  const Rigid3d motion = PredictMotion();
  if (options_.deskew && frames_.size() >= 2) Deskew(motion, &pre);
  const ScanSurface surface = ComputeSurface(pre.points, options_.surface, threads_);
  d.surface_ms = timer.ElapsedMs() - d.preprocess_ms;

  if (frames_.empty()) {
    d.status = FrameStatus::kFirstFrame;
    out.world_from_cam = Rigid3d();
  } else {
    const RegistrationResult reg =
        Track(surface, frames_.back().world_from_cam * motion, &d.samples);
    out.world_from_cam = reg.world_from_scan;
    d.iterations = reg.iterations;
    d.residual = reg.residual;
    d.correspondences = reg.correspondences;
    d.converged = reg.converged;
    d.min_eigenvalue = reg.min_eigenvalue;
    if (!reg.ok) {
      d.status = FrameStatus::kMotionModel;
      d.degenerate = true;
      spdlog::warn(
          "frame {}: {} points after filtering, {} correspondences: using the "
          "constant-velocity motion model",
          frame, d.points_after_filter, reg.correspondences);
    } else if (reg.degenerate) {
      d.status = FrameStatus::kDegenerate;
      d.degenerate = true;
      spdlog::warn(
          "frame {}: degenerate geometry ({} unobservable directions, min eigenvalue "
          "{:.2e}): motion model kept along them",
          frame, reg.degenerate_directions, reg.min_eigenvalue);
    }
  }
  d.register_ms = timer.ElapsedMs() - d.preprocess_ms - d.surface_ms;
  UpdateModel(frame, surface, out.world_from_cam);
  d.time_ms = timer.ElapsedMs();
  frames_.push_back(out);
  return out;
}

}  // namespace jvl::lidar
