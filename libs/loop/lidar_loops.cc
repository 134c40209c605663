#include "loop/lidar_loops.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>

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
  JVL_CHECK(
      coarse_samples_per_list >= 1 && coarse_samples_per_list <= association.samples_per_list,
      "coarse_samples_per_list must be in [1, samples_per_list], got " << coarse_samples_per_list);
  JVL_CHECK(std::isfinite(coarse_voxel) && coarse_voxel >= 0,
            "coarse_voxel must be >= 0, got " << coarse_voxel);
  JVL_CHECK(max_residual > 0, "max_residual must be > 0, got " << max_residual);
  JVL_CHECK(min_correspondences >= 1,
            "min_correspondences must be >= 1, got " << min_correspondences);
  JVL_CHECK(max_translation > 0, "max_translation must be > 0, got " << max_translation);
  JVL_CHECK(max_prior_offset > 0 && max_prior_drift >= 0,
            "max_prior_offset must be > 0 and max_prior_drift >= 0, got "
                << max_prior_offset << " and " << max_prior_drift);
  JVL_CHECK(consistency >= 1, "consistency must be >= 1, got " << consistency);
  JVL_CHECK(consistency_m > 0 && consistency_deg > 0 && consistency_deg <= 180,
            "consistency_m must be > 0 and consistency_deg in (0, 180], got "
                << consistency_m << " and " << consistency_deg);
  JVL_CHECK(consistency_keyframes >= 0,
            "consistency_keyframes must be >= 0, got " << consistency_keyframes);
  JVL_CHECK(std::isfinite(proximity_radius_m) && proximity_radius_m > 0 &&
                std::isfinite(proximity_drift) && proximity_drift >= 0,
            "proximity_radius_m must be > 0 and proximity_drift >= 0, got "
                << proximity_radius_m << " and " << proximity_drift);
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

namespace {

lidar::ScanSurface PreparedSurface(const PointCloud& scan, const Calibration& calibration,
                                   const LidarLoopOptions& o) {
  const lidar::PreprocessedScan pre =
      lidar::PreprocessScan(scan, calibration.cam0_from_velo, o.preprocess, 1);
  return lidar::ComputeSurface(pre.points, o.surface, 1);
}

}  // namespace

LoopScan::LoopScan(const PointCloud& scan, const Calibration& calibration,
                   const LidarLoopOptions& o)
    : samples(lidar::SampleSurface(PreparedSurface(scan, calibration, o),
                                   o.association.samples_per_list)),
      descriptor(ComputeScanDescriptor(scan.points, o.descriptor)) {}

lidar::RegistrationResult RegisterLoopScans(const LoopScan& query, const LoopScan& match,
                                            const Rigid3d& initial, const LidarLoopOptions& o) {
  return RegisterLoopScans(query, match, std::vector<Rigid3d>{initial}, o);
}

lidar::RegistrationResult RegisterLoopScans(const LoopScan& query, const LoopScan& match,
                                            const std::vector<Rigid3d>& initials,
                                            const LidarLoopOptions& o, size_t* chosen) {
  JVL_CHECK(!initials.empty(), "RegisterLoopScans needs a start");
  size_t best = 0;
  Rigid3d start = initials[0];
  // The match's surface as IMLS models (built here: a millisecond, where keeping them would
  // double a prepared scan's memory).
  if (o.coarse_scale > 1) {
    lidar::ImlsModel coarse_model(o.association.search_radius * o.coarse_scale);
    const lidar::StoredScan thinned = lidar::StoreScan(match.samples, o.coarse_voxel);
    lidar::AddScanToModel(thinned.points, thinned.normals, Rigid3d(), 0, &coarse_model);
    lidar::AssociationOptions coarse = o.association;
    lidar::RegistrationOptions coarse_registration = o.registration;
    lidar::ScaleNeighbourhoods(o.coarse_scale, &coarse, &coarse_registration);
    coarse.samples_per_list = o.coarse_samples_per_list;
    // The best coarse result: converged without a degenerate direction first, then the lower
    // residual.
    auto rank = [](const lidar::RegistrationResult& r) {
      return std::make_pair(r.ok && r.converged && !r.degenerate ? 0 : r.ok ? 1 : 2, r.residual);
    };
    std::optional<lidar::RegistrationResult> kept;
    for (size_t i = 0; i < initials.size(); ++i) {
      const lidar::RegistrationResult first = lidar::RegisterSampled(
          query.samples, coarse_model, initials[i], coarse, coarse_registration, 1);
      if (!kept || rank(first) < rank(*kept)) {
        kept = first;
        best = i;
        start = first.ok ? first.world_from_scan : initials[i];
      }
    }
  }
  if (chosen) *chosen = best;
  lidar::ImlsModel model(o.association.search_radius);
  lidar::AddScanToModel(match.samples.points, match.samples.normals, Rigid3d(), 0, &model);
  return lidar::RegisterSampled(query.samples, model, start, o.association, o.registration, 1);
}

LoopScanCache::LoopScanCache(std::function<PointCloud(int64_t)> load_scan,
                             const Calibration& calibration, const LidarLoopOptions& options,
                             size_t capacity)
    : load_scan_(std::move(load_scan)),
      calibration_(calibration),
      options_(options),
      cache_(capacity) {}

std::shared_ptr<const LoopScan> LoopScanCache::Get(int64_t frame) {
  return cache_.Get(frame, [&] { return LoopScan(load_scan_(frame), calibration_, options_); });
}

std::shared_ptr<const LoopScan> LoopScanCache::Find(int64_t frame) { return cache_.Find(frame); }

void LoopScanCache::Prepare(const std::vector<int64_t>& frames, int threads) {
  // The first `capacity` distinct frames in the order given (the order they are needed in).
  std::vector<int64_t> first;
  std::unordered_map<int64_t, char> seen;
  for (const int64_t f : frames) {
    if (first.size() >= cache_.capacity()) break;
    if (seen.emplace(f, 1).second) first.push_back(f);
  }
  ParallelFor(static_cast<int64_t>(first.size()), threads,
              [&](int64_t i) { Get(first[static_cast<size_t>(i)]); });
}

LoopStatus RegistrationStatus(const lidar::RegistrationResult& reg, const LidarLoopOptions& o) {
  if (!reg.ok || !reg.converged || reg.degenerate) return LoopStatus::kRegistrationFailed;
  if (reg.residual > o.max_residual || reg.correspondences < o.min_correspondences)
    return LoopStatus::kResidual;
  if (reg.world_from_scan.translation().norm() > o.max_translation) return LoopStatus::kTooFar;
  return LoopStatus::kAccepted;
}

void TakeRegistration(const lidar::RegistrationResult& reg, const LidarLoopOptions& o,
                      LoopCandidate* c) {
  c->match_from_query = reg.world_from_scan;
  c->correspondences = reg.correspondences;
  c->residual = reg.residual;
  c->converged = reg.converged;
  c->degenerate = reg.degenerate;
  c->status = RegistrationStatus(reg, o);
}

double RelativeHeading(const Rigid3d& match_from_query) {
  const Eigen::Vector3d forward = match_from_query.rotation() * Eigen::Vector3d::UnitZ();
  return std::atan2(-forward.x(), forward.z());
}

Rigid3d LoopDisagreement(const Rigid3d& query1, const Rigid3d& match1, const Rigid3d& loop1,
                         const Rigid3d& query2, const Rigid3d& match2, const Rigid3d& loop2) {
  const Rigid3d predicted = match2.Inverse() * match1 * loop1 * query1.Inverse() * query2;
  return loop2.Inverse() * predicted;
}

bool FarInPrior(const Trajectory& keyframes, const std::vector<double>& path, size_t q, size_t m,
                const LidarLoopOptions& o) {
  const double apart =
      (keyframes.world_from_cam[q].translation() - keyframes.world_from_cam[m].translation())
          .norm();
  return apart > o.max_prior_offset + o.max_prior_drift * (path[q] - path[m]);
}

namespace {

// Temporal consistency: a verified match is accepted when the consistency - 1 keyframes before
// its query have verified matches too, each within consistency_keyframes keyframes of the next
// one's and agreeing with it in geometry: the relative pose of the later loop predicted from the
// earlier one and the trajectory's motion between the two queries and between the two matches
// (a few metres each, where odometry is accurate) must be within consistency_m and
// consistency_deg of the registered one. A street end registered the wrong way round, or a
// registration slid along a street, among right ones is not a loop. verified[v]: the candidate
// of keyframe to_verify[v] with the match keyframe chosen[v].
void ApplyTemporalConsistency(const Trajectory& keyframes, const std::vector<size_t>& to_verify,
                              const std::vector<size_t>& chosen, const LidarLoopOptions& o,
                              std::vector<LoopCandidate>* verified_out) {
  std::vector<LoopCandidate>& verified = *verified_out;
  const size_t n = keyframes.size();
  std::vector<std::optional<size_t>> match_of(n);  // Keyframe index of a verified match.
  std::vector<Rigid3d> loop_of(n);                 // Its registered match_from_query.
  for (size_t v = 0; v < verified.size(); ++v) {
    if (verified[v].status != LoopStatus::kAccepted) continue;
    match_of[to_verify[v]] = chosen[v];
    loop_of[to_verify[v]] = verified[v].match_from_query;
  }
  const std::vector<Rigid3d>& pose = keyframes.world_from_cam;  // Only relative motions used.
  for (size_t v = 0; v < verified.size(); ++v) {
    LoopCandidate& c = verified[v];
    if (c.status != LoopStatus::kAccepted) continue;
    const size_t q = to_verify[v];
    bool consistent = q + 1 >= static_cast<size_t>(o.consistency);
    for (int back = 1; consistent && back < o.consistency; ++back) {
      const size_t q2 = q - back + 1, q1 = q - back;
      const auto& now = match_of[q2];
      const auto& before = match_of[q1];
      consistent =
          now && before &&
          std::abs(static_cast<long>(*now) - static_cast<long>(*before)) <= o.consistency_keyframes;
      if (!consistent) break;
      const Rigid3d off =
          LoopDisagreement(pose[q1], pose[*before], loop_of[q1], pose[q2], pose[*now], loop_of[q2]);
      const double off_deg = RotationAngle(off.rotation()) * kRadToDeg;
      spdlog::debug("consistency {} -> {} after {} -> {}: {:.3f} m, {:.2f} deg",
                    keyframes.frames[q2], keyframes.frames[*now], keyframes.frames[q1],
                    keyframes.frames[*before], off.translation().norm(), off_deg);
      consistent = off.translation().norm() <= o.consistency_m && off_deg <= o.consistency_deg;
    }
    if (!consistent) c.status = LoopStatus::kInconsistent;
  }
}

// The candidates of the queries skip() does not name: a skipped query was verified only as the
// look-back of a later one's temporal consistency (its own was not checked against verified
// keyframes before it).
std::vector<LoopCandidate> OpenQueries(std::vector<LoopCandidate> verified,
                                       const std::function<bool(int64_t)>& skip) {
  if (!skip) return verified;
  verified.erase(std::remove_if(verified.begin(), verified.end(),
                                [&](const LoopCandidate& c) { return skip(c.query); }),
                 verified.end());
  return verified;
}

// The keyframes to verify: those with a candidate that skip() does not name, and the
// consistency - 1 keyframes before each (with a candidate), which its temporal consistency
// looks back to.
std::vector<size_t> QueriesToVerify(const Trajectory& keyframes,
                                    const std::function<bool(size_t)>& has_candidate,
                                    const std::function<bool(int64_t)>& skip, int consistency) {
  const size_t n = keyframes.size();
  std::vector<char> verify(n, 0);
  for (size_t q = 0; q < n; ++q) {
    if (!has_candidate(q) || (skip && skip(keyframes.frames[q]))) continue;
    for (size_t back = 0; back < static_cast<size_t>(consistency) && back <= q; ++back)
      if (has_candidate(q - back)) verify[q - back] = 1;
  }
  std::vector<size_t> out;
  for (size_t q = 0; q < n; ++q)
    if (verify[q]) out.push_back(q);
  return out;
}

}  // namespace

LoopResult DetectLidarLoops(const Trajectory& keyframes, LoopScanCache& scans,
                            const LidarLoopOptions& o, int threads,
                            const std::function<bool(int64_t)>& skip,
                            const std::function<void()>& tick) {
  o.Check();
  keyframes.Check("loop keyframes");
  const size_t n = keyframes.size();
  LoopResult result;
  result.keyframes = keyframes.frames;
  const std::vector<double> path = PathLengths(keyframes);
  std::vector<ScanDescriptor> descriptors(n);
  const ScanDescriptorOptions& d = scans.options().descriptor;
  const bool same_descriptor = d.rings == o.descriptor.rings && d.sectors == o.descriptor.sectors &&
                               d.max_range == o.descriptor.max_range &&
                               d.sensor_height == o.descriptor.sensor_height;
  ParallelFor(static_cast<int64_t>(n), threads, [&](int64_t i) {
    // From the prepared scan where a detector before prepared it (the same descriptor).
    const std::shared_ptr<const LoopScan> prepared =
        same_descriptor ? scans.Find(keyframes.frames[i]) : nullptr;
    descriptors[i] =
        prepared ? prepared->descriptor
                 : ComputeScanDescriptor(scans.Load(keyframes.frames[i]).points, o.descriptor);
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

  // A pick can only become a loop if a neighbouring keyframe has a pick within
  // consistency_keyframes of it (the temporal consistency below needs consecutive matches that
  // agree); the others are not verified.
  if (o.consistency > 1) {
    auto agrees = [&](const Pick& pick, size_t other) {
      for (const Pick& p : picks[other])
        if (std::abs(static_cast<long>(p.match) - static_cast<long>(pick.match)) <=
            o.consistency_keyframes)
          return true;
      return false;
    };
    std::vector<std::vector<Pick>> kept(n);
    for (size_t q = 0; q < n; ++q)
      for (const Pick& pick : picks[q])
        if ((q > 0 && agrees(pick, q - 1)) || (q + 1 < n && agrees(pick, q + 1)))
          kept[q].push_back(pick);
    picks = std::move(kept);
  }

  // Verification of every keyframe's picks (independent, in parallel; results in their slots).
  const std::vector<size_t> to_verify = QueriesToVerify(
      keyframes, [&](size_t q) { return !picks[q].empty(); }, skip, o.consistency);
  {
    std::vector<int64_t> frames;
    for (const size_t q : to_verify) {
      frames.push_back(keyframes.frames[q]);
      for (const Pick& pick : picks[q]) frames.push_back(keyframes.frames[pick.match]);
    }
    scans.Prepare(std::move(frames), threads);
  }
  std::vector<LoopCandidate> verified(to_verify.size());
  std::vector<size_t> chosen(to_verify.size());  // Keyframe index of each verified match.
  const Rigid3d& cam0_from_velo = scans.calibration().cam0_from_velo;
  // Query points = Rz(yaw) match points (velodyne frames): velo_match_from_velo_query is
  // Rz(-yaw).
  auto initial_for = [&](double yaw) {
    const Rigid3d velo_match_from_query(
        Eigen::Quaterniond(Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ())),
        Eigen::Vector3d::Zero());
    return cam0_from_velo * velo_match_from_query * cam0_from_velo.Inverse();
  };
  // One candidate, registered from its best yaw and from the opposite one.
  auto VerifyPick = [&](const Pick& pick, size_t q, const LoopScan& query_scan) {
    LoopCandidate c;
    c.query = keyframes.frames[q];
    c.match = keyframes.frames[pick.match];
    c.ring_key_distance = pick.ring;
    c.descriptor_distance = pick.m.distance;
    const std::shared_ptr<const LoopScan> match_scan = scans.Get(c.match);
    // From the descriptor's yaw and from the other way round (a street seen from the other
    // direction matches itself turned by 180 deg and shifted across the road nearly as well):
    // the better coarse registration is refined.
    size_t which = 0;
    const lidar::RegistrationResult reg =
        RegisterLoopScans(query_scan, *match_scan,
                          {initial_for(pick.m.yaw), initial_for(pick.opposite.yaw)}, o, &which);
    c.yaw_rad = which == 0 ? pick.m.yaw : pick.opposite.yaw;
    TakeRegistration(reg, o, &c);
    if (c.status == LoopStatus::kAccepted && FarInPrior(keyframes, path, q, pick.match, o))
      c.status = LoopStatus::kFarInPrior;
    return c;
  };
  ParallelFor(static_cast<int64_t>(to_verify.size()), threads, [&](int64_t v) {
    const size_t q = to_verify[v];
    const std::shared_ptr<const LoopScan> query_scan = scans.Get(keyframes.frames[q]);
    // Nearest by descriptor first; the first accepted one is kept, else the first rejected.
    for (size_t k = 0; k < picks[q].size(); ++k) {
      LoopCandidate c = VerifyPick(picks[q][k], q, *query_scan);
      if (k == 0 || c.status == LoopStatus::kAccepted) {
        verified[v] = c;
        chosen[v] = picks[q][k].match;
      }
      if (c.status == LoopStatus::kAccepted) break;
    }
    if (tick) tick();
  });

  ApplyTemporalConsistency(keyframes, to_verify, chosen, o, &verified);
  result.candidates = OpenQueries(std::move(verified), skip);
  return result;
}

LoopResult DetectProximityLoops(const Trajectory& keyframes, LoopScanCache& scans,
                                const LidarLoopOptions& o, int threads,
                                const std::function<bool(int64_t)>& skip,
                                const std::function<void()>& tick) {
  o.Check();
  keyframes.Check("loop keyframes");
  const size_t n = keyframes.size();
  LoopResult result;
  result.keyframes = keyframes.frames;
  const std::vector<double> path = PathLengths(keyframes);
  const std::vector<Rigid3d>& pose = keyframes.world_from_cam;
  // The candidate of every keyframe: the nearest earlier keyframe within the bound (ties: the
  // earlier one).
  std::vector<std::optional<size_t>> candidate(n);
  for (size_t q = 0; q < n; ++q) {
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < q && path[q] - path[j] >= o.min_separation_m; ++j) {
      const double apart = (pose[q].translation() - pose[j].translation()).norm();
      if (apart <= o.proximity_radius_m + o.proximity_drift * (path[q] - path[j]) &&
          apart < nearest) {
        nearest = apart;
        candidate[q] = j;
      }
    }
  }
  const std::vector<size_t> to_verify = QueriesToVerify(
      keyframes, [&](size_t q) { return candidate[q].has_value(); }, skip, o.consistency);
  std::vector<size_t> chosen;
  std::vector<int64_t> frames;
  for (const size_t q : to_verify) {
    chosen.push_back(*candidate[q]);
    frames.push_back(keyframes.frames[q]);
    frames.push_back(keyframes.frames[*candidate[q]]);
  }
  scans.Prepare(std::move(frames), threads);
  std::vector<LoopCandidate> verified(to_verify.size());
  ParallelFor(static_cast<int64_t>(to_verify.size()), threads, [&](int64_t v) {
    const size_t q = to_verify[static_cast<size_t>(v)], m = chosen[static_cast<size_t>(v)];
    LoopCandidate c;
    c.query = keyframes.frames[q];
    c.match = keyframes.frames[m];
    c.detector = "proximity";
    const Rigid3d initial = pose[m].Inverse() * pose[q];
    c.yaw_rad = RelativeHeading(initial);
    const lidar::RegistrationResult reg =
        RegisterLoopScans(*scans.Get(c.query), *scans.Get(c.match), initial, o);
    TakeRegistration(reg, o, &c);
    if (c.status == LoopStatus::kAccepted && FarInPrior(keyframes, path, q, m, o))
      c.status = LoopStatus::kFarInPrior;
    verified[static_cast<size_t>(v)] = c;
    if (tick) tick();
  });
  ApplyTemporalConsistency(keyframes, to_verify, chosen, o, &verified);
  result.candidates = OpenQueries(std::move(verified), skip);
  return result;
}

}  // namespace jvl::loop
