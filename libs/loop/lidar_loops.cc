#include "loop/lidar_loops.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/check.h"
#include "core/threads.h"
#include "lidar/imls.h"

namespace jvl::loop {

void LidarLoopOptions::Check() const {
  descriptor.Check();
  preprocess.Check();
  surface.Check();
  association.Check();
  registration.Check();
  JVL_CHECK(std::isfinite(min_separation_m) && min_separation_m >= 0,
            "min_separation_m must be >= 0, got " << min_separation_m);
  JVL_CHECK(verify_candidates >= 1, "verify_candidates must be >= 1, got " << verify_candidates);
  JVL_CHECK(ring_key_candidates >= 1,
            "ring_key_candidates must be >= 1, got " << ring_key_candidates);
  JVL_CHECK(max_descriptor_distance > 0 && max_descriptor_distance <= 1,
            "max_descriptor_distance must be in (0, 1], got " << max_descriptor_distance);
  JVL_CHECK(coarse_scale >= 1, "coarse_scale must be >= 1, got " << coarse_scale);
  JVL_CHECK(max_residual > 0, "max_residual must be > 0, got " << max_residual);
  JVL_CHECK(min_correspondences >= 1,
            "min_correspondences must be >= 1, got " << min_correspondences);
  JVL_CHECK(max_translation > 0, "max_translation must be > 0, got " << max_translation);
  JVL_CHECK(max_prior_offset > 0 && max_prior_drift >= 0,
            "max_prior_offset must be > 0 and max_prior_drift >= 0, got "
                << max_prior_offset << " and " << max_prior_drift);
  JVL_CHECK(consistency >= 1, "consistency must be >= 1, got " << consistency);
  JVL_CHECK(consistency_yaw_deg > 0 && consistency_yaw_deg <= 180,
            "consistency_yaw_deg must be in (0, 180], got " << consistency_yaw_deg);
  JVL_CHECK(consistency_keyframes >= 0,
            "consistency_keyframes must be >= 0, got " << consistency_keyframes);
}

const char* ToString(LoopStatus status) {
  switch (status) {
    case LoopStatus::kAccepted:
      return "accepted";
    case LoopStatus::kRegistrationFailed:
      return "registration failed";
    case LoopStatus::kResidual:
      return "residual";
    case LoopStatus::kTooFar:
      return "too far";
    case LoopStatus::kInconsistent:
      return "inconsistent";
    case LoopStatus::kFarInPrior:
      return "far in the prior";
    case LoopStatus::kFewInliers:
      return "few inliers";
    case LoopStatus::kDisagree:
      return "registration disagrees";
    case LoopStatus::kDuplicate:
      return "duplicate";
  }
  return "unknown";
}

lidar::RegistrationResult RegisterLoopScans(const lidar::ScanSurface& query,
                                            const lidar::ScanSurface& match, const Rigid3d& initial,
                                            const LidarLoopOptions& o) {
  auto run = [&](const lidar::AssociationOptions& association,
                 const lidar::RegistrationOptions& registration, const Rigid3d& start) {
    lidar::ImlsModel model(association.search_radius);
    lidar::AddScanToModel(match.points, match.normals, Rigid3d(), 0, &model);
    return lidar::RegisterSurface(query, model, start, association, registration, 1);
  };
  Rigid3d start = initial;
  if (o.coarse_scale > 1) {
    lidar::AssociationOptions coarse = o.association;
    lidar::RegistrationOptions coarse_registration = o.registration;
    lidar::ScaleNeighbourhoods(o.coarse_scale, &coarse, &coarse_registration);
    const lidar::RegistrationResult first = run(coarse, coarse_registration, initial);
    if (first.ok) start = first.world_from_scan;
  }
  return run(o.association, o.registration, start);
}

lidar::ScanSurface LoopSurface(const PointCloud& scan, const Calibration& calibration,
                               const LidarLoopOptions& o) {
  const lidar::PreprocessedScan pre =
      lidar::PreprocessScan(scan, calibration.cam0_from_velo, o.preprocess, 1);
  return lidar::ComputeSurface(pre.points, o.surface, 1);
}

LoopStatus RegistrationStatus(const lidar::RegistrationResult& reg, const LidarLoopOptions& o) {
  if (!reg.ok || !reg.converged || reg.degenerate) return LoopStatus::kRegistrationFailed;
  if (reg.residual > o.max_residual || reg.correspondences < o.min_correspondences)
    return LoopStatus::kResidual;
  if (reg.world_from_scan.translation().norm() > o.max_translation) return LoopStatus::kTooFar;
  return LoopStatus::kAccepted;
}

double RelativeHeading(const Rigid3d& match_from_query) {
  const Eigen::Vector3d forward = match_from_query.rotation() * Eigen::Vector3d::UnitZ();
  return std::atan2(-forward.x(), forward.z());
}

std::vector<double> PathLengths(const Trajectory& keyframes) {
  std::vector<double> path(keyframes.size(), 0.0);
  for (size_t i = 1; i < keyframes.size(); ++i) {
    path[i] = path[i - 1] + (keyframes.world_from_cam[i].translation() -
                             keyframes.world_from_cam[i - 1].translation())
                                .norm();
  }
  return path;
}

bool FarInPrior(const Trajectory& keyframes, const std::vector<double>& path, size_t q, size_t m,
                const LidarLoopOptions& o) {
  const double apart =
      (keyframes.world_from_cam[q].translation() - keyframes.world_from_cam[m].translation())
          .norm();
  return apart > o.max_prior_offset + o.max_prior_drift * (path[q] - path[m]);
}

LoopResult DetectLidarLoops(const Trajectory& keyframes,
                            const std::function<PointCloud(int64_t)>& load_scan,
                            const Calibration& calibration, const LidarLoopOptions& o, int threads,
                            const std::function<void()>& tick) {
  o.Check();
  keyframes.Check("loop keyframes");
  const size_t n = keyframes.size();
  LoopResult result;
  result.keyframes = keyframes.frames;
  const std::vector<double> path = PathLengths(keyframes);
  std::vector<ScanDescriptor> descriptors(n);
  ParallelFor(static_cast<int64_t>(n), threads, [&](int64_t i) {
    descriptors[i] = ComputeScanDescriptor(load_scan(keyframes.frames[i]).points, o.descriptor);
    if (tick) tick();
  });

  // Candidate of every keyframe: among the earlier keyframes far enough back along the path,
  // the ring_key_candidates nearest by ring key, then the nearest by descriptor distance.
  struct Pick {
    size_t match = 0;
    double ring = 0;
    DescriptorMatch m, opposite;  // Best shift, and the best one within 30 deg of its opposite.
  };
  std::vector<std::vector<Pick>> picks(n);
  ParallelFor(static_cast<int64_t>(n), threads, [&](int64_t qi) {
    const size_t q = static_cast<size_t>(qi);
    std::vector<std::pair<double, size_t>> near;
    for (size_t j = 0; j < q && path[q] - path[j] >= o.min_separation_m; ++j) {
      near.emplace_back(RingKeyDistance(descriptors[q], descriptors[j]), j);
    }
    if (near.empty()) return;
    const size_t keep = std::min(near.size(), static_cast<size_t>(o.ring_key_candidates));
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(keep), near.end());
    std::vector<std::pair<Pick, std::vector<double>>> scored;
    for (size_t c = 0; c < keep; ++c) {
      std::vector<double> d = ShiftDistances(descriptors[near[c].second], descriptors[q]);
      // As CompareDescriptors, keeping the distances for the opposite yaw below.
      const DescriptorMatch m = BestShiftNear(d, 0, o.descriptor.sectors / 2);
      if (m.distance <= o.max_descriptor_distance)
        scored.emplace_back(Pick{near[c].second, near[c].first, m, {}}, std::move(d));
    }
    // The verify_candidates nearest by descriptor distance (ties: the earlier keyframe).
    std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) {
      return a.first.m.distance != b.first.m.distance ? a.first.m.distance < b.first.m.distance
                                                      : a.first.match < b.first.match;
    });
    if (scored.size() > static_cast<size_t>(o.verify_candidates))
      scored.resize(static_cast<size_t>(o.verify_candidates));
    for (auto& [pick, d] : scored) {
      pick.opposite =
          BestShiftNear(d, pick.m.shift + o.descriptor.sectors / 2, o.descriptor.sectors / 12);
      picks[q].push_back(pick);
    }
  });

  // Verification of every pick (independent, in parallel; results in their slots).
  std::vector<size_t> to_verify;
  for (size_t q = 0; q < n; ++q)
    if (!picks[q].empty()) to_verify.push_back(q);
  std::vector<LoopCandidate> verified(to_verify.size());
  std::vector<size_t> chosen(to_verify.size());  // Keyframe index of each verified match.
  const Rigid3d& cam0_from_velo = calibration.cam0_from_velo;
  auto surface_of = [&](int64_t frame) { return LoopSurface(load_scan(frame), calibration, o); };
  // Query points = Rz(yaw) match points (velodyne frames): velo_match_from_velo_query is
  // Rz(-yaw).
  auto initial_for = [&](double yaw) {
    const Rigid3d velo_match_from_query(
        Eigen::Quaterniond(Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ())),
        Eigen::Vector3d::Zero());
    return cam0_from_velo * velo_match_from_query * cam0_from_velo.Inverse();
  };
  auto status_of = [&](const lidar::RegistrationResult& reg) { return RegistrationStatus(reg, o); };
  // One candidate, registered from its best yaw and from the opposite one.
  auto VerifyPick = [&](const Pick& pick, size_t q, const lidar::ScanSurface& query_surface) {
    LoopCandidate c;
    c.query = keyframes.frames[q];
    c.match = keyframes.frames[pick.match];
    c.ring_key_distance = pick.ring;
    c.descriptor_distance = pick.m.distance;
    const lidar::ScanSurface match_surface = surface_of(c.match);
    double yaw = pick.m.yaw;
    lidar::RegistrationResult reg =
        RegisterLoopScans(query_surface, match_surface, initial_for(yaw), o);
    LoopStatus status = status_of(reg);
    // Both ways round: a street seen from the other direction matches itself turned by 180 deg
    // and shifted across the road nearly as well; the lower residual decides.
    const lidar::RegistrationResult other =
        RegisterLoopScans(query_surface, match_surface, initial_for(pick.opposite.yaw), o);
    const LoopStatus other_status = status_of(other);
    if (other_status == status ? other.residual < reg.residual
                               : other_status == LoopStatus::kAccepted) {
      reg = other;
      status = other_status;
      yaw = pick.opposite.yaw;
    }
    c.yaw_rad = yaw;
    c.match_from_query = reg.world_from_scan;
    c.correspondences = reg.correspondences;
    c.residual = reg.residual;
    c.converged = reg.converged;
    c.degenerate = reg.degenerate;
    if (status == LoopStatus::kAccepted && FarInPrior(keyframes, path, q, pick.match, o))
      status = LoopStatus::kFarInPrior;
    c.status = status;
    return c;
  };
  ParallelFor(static_cast<int64_t>(to_verify.size()), threads, [&](int64_t v) {
    const size_t q = to_verify[v];
    const lidar::ScanSurface query_surface = surface_of(keyframes.frames[q]);
    bool have = false;
    for (const Pick& pick : picks[q]) {
      LoopCandidate c = VerifyPick(pick, q, query_surface);
      const LoopCandidate& kept = verified[v];
      const bool better =
          !have || (c.status == LoopStatus::kAccepted &&
                    (kept.status != LoopStatus::kAccepted || c.residual < kept.residual));
      if (better) {
        verified[v] = c;
        chosen[v] = pick.match;
        have = true;
      }
    }
    if (tick) tick();
  });

  // Temporal consistency: a verified match is accepted when the consistency - 1 keyframes
  // before its query have verified matches too, each within consistency_keyframes keyframes of
  // the next one's and turned the same way (registered headings within consistency_yaw_deg: a
  // street end registered the wrong way round among right ones is not a loop).
  std::vector<std::optional<size_t>> match_of(n);  // Keyframe index of a verified match.
  std::vector<double> heading_of(n, 0.0);          // Its registered relative heading.
  for (size_t v = 0; v < verified.size(); ++v) {
    if (verified[v].status != LoopStatus::kAccepted) continue;
    match_of[to_verify[v]] = chosen[v];
    heading_of[to_verify[v]] = RelativeHeading(verified[v].match_from_query);
  }
  const double max_turn = o.consistency_yaw_deg * M_PI / 180.0;
  for (size_t v = 0; v < verified.size(); ++v) {
    LoopCandidate& c = verified[v];
    if (c.status != LoopStatus::kAccepted) continue;
    const size_t q = to_verify[v];
    bool consistent = q + 1 >= static_cast<size_t>(o.consistency);
    for (int back = 1; consistent && back < o.consistency; ++back) {
      const auto& now = match_of[q - back + 1];
      const auto& before = match_of[q - back];
      const double turn =
          std::remainder(heading_of[q - back + 1] - heading_of[q - back], 2.0 * M_PI);
      consistent = now && before &&
                   std::abs(static_cast<long>(*now) - static_cast<long>(*before)) <=
                       o.consistency_keyframes &&
                   std::abs(turn) <= max_turn;
    }
    if (!consistent) c.status = LoopStatus::kInconsistent;
  }
  result.candidates = std::move(verified);
  return result;
}

}  // namespace jvl::loop
