#include "lidar/odometry.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "core/check.h"
#include "core/timer.h"

namespace jvl::lidar {

void OdometryOptions::Check() const {
  preprocess.Check();
  surface.Check();
  association.Check();
  registration.Check();
  JVL_CHECK(scan_map_size >= 1, "scan_map_size must be >= 1, got " << scan_map_size);
  JVL_CHECK(initial_search_scale >= 1,
            "initial_search_scale must be >= 1, got " << initial_search_scale);
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
      model_(options.association.search_radius) {
  options_.Check();
}

Rigid3d Odometry::PredictMotion() const {
  if (frames_.size() < 2) return Rigid3d();
  const Rigid3d& a = frames_[frames_.size() - 2].world_from_cam;
  const Rigid3d& b = frames_.back().world_from_cam;
  return a.Inverse() * b;
}

RegistrationResult Odometry::Register(const ScanSurface& surface, const Rigid3d& predicted,
                                      const AssociationOptions& association,
                                      const RegistrationOptions& options, int* samples) const {
  return RegisterSurface(surface, model_, predicted, association, options, threads_, samples);
}

RegistrationResult Odometry::Track(const ScanSurface& surface, const Rigid3d& predicted,
                                   int* samples) const {
  Rigid3d start = predicted;
  if (frames_.size() == 1 && options_.initial_search_scale > 1) {
    // No velocity yet: a coarse registration with wider neighbourhoods seeds the normal one,
    // on a quarter of the samples (the wide neighbourhoods make each query ~20x dearer).
    AssociationOptions coarse = options_.association;
    RegistrationOptions coarse_registration = options_.registration;
    ScaleNeighbourhoods(options_.initial_search_scale, &coarse, &coarse_registration);
    coarse.samples_per_list = std::max(1, coarse.samples_per_list / 4);
    const RegistrationResult first =
        Register(surface, predicted, coarse, coarse_registration, samples);
    if (first.ok) start = first.world_from_scan;
  }
  RegistrationResult reg =
      Register(surface, start, options_.association, options_.registration, samples);
  if (reg.degenerate && start.translation() != predicted.translation()) {
    // Along unobservable directions the motion model, not the coarse pass, must be kept.
    reg = Register(surface, predicted, options_.association, options_.registration, samples);
  }
  return reg;
}

RegistrationResult Odometry::RedoFirstPair(const PreprocessedScan& second,
                                           const RegistrationResult& raw, ScanSurface* surface,
                                           int* samples) {
  const Rigid3d& world_from_first = frames_.front().world_from_cam;
  const Rigid3d motion = world_from_first.Inverse() * raw.world_from_scan;
  PreprocessedScan first = std::move(first_scan_);
  first_scan_ = PreprocessedScan();
  DeskewScan(motion, &first);
  const ScanSurface first_surface = ComputeSurface(first.points, options_.surface, threads_);
  model_.RemoveScan(frames_.front().frame);
  AddScanToModel(first_surface.points, first_surface.normals, world_from_first,
                 frames_.front().frame, &model_);
  PreprocessedScan deskewed = second;
  DeskewScan(motion, &deskewed);
  *surface = ComputeSurface(deskewed.points, options_.surface, threads_);
  const RegistrationResult reg = Track(*surface, raw.world_from_scan, samples);
  return reg.ok ? reg : raw;
}

void Odometry::UpdateModel(int64_t frame, const ScanSurface& surface,
                           const Rigid3d& world_from_cam) {
  // Points without a normal have a zero one and are left out.
  AddScanToModel(surface.points, surface.normals, world_from_cam, frame, &model_);
  while (model_.num_scans() > static_cast<size_t>(options_.scan_map_size)) {
    model_.RemoveScan(model_.scan_ids().front());
  }
}

OdometryFrame Odometry::ProcessScan(const PointCloud& velo_scan, int64_t frame,
                                    int64_t non_finite_dropped, double scan_time_offset) {
  const Timer timer;
  OdometryFrame out;
  out.frame = frame;
  FrameDiagnostics& d = out.diagnostics;
  PreprocessedScan pre = PreprocessScan(velo_scan, cam0_from_velo_, options_.preprocess, threads_);
  pre.time_offset = scan_time_offset;
  d.non_finite_points = non_finite_dropped + pre.counts.non_finite;
  if (pre.counts.non_finite > 0) {
    spdlog::warn("frame {}: dropped {} non-finite points", frame, pre.counts.non_finite);
  }
  d.points_after_filter = static_cast<int64_t>(pre.points.size());
  d.preprocess_ms = timer.ElapsedMs();
  const Rigid3d motion = PredictMotion();
  if (options_.deskew && frames_.size() >= 2) DeskewScan(motion, &pre);
  ScanSurface surface = ComputeSurface(pre.points, options_.surface, threads_);
  d.surface_ms = timer.ElapsedMs() - d.preprocess_ms;

  if (frames_.empty()) {
    d.status = FrameStatus::kFirstFrame;
    out.world_from_cam = Rigid3d();
    if (options_.deskew) first_scan_ = pre;
  } else {
    RegistrationResult reg = Track(surface, frames_.back().world_from_cam * motion, &d.samples);
    if (options_.deskew && frames_.size() == 1 && reg.ok) {
      reg = RedoFirstPair(pre, reg, &surface, &d.samples);
    }
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
