// Global joint optimisation (Sec. 4.3): problem assembly, fresh IMLS traversal, map export.
#include "mapping/global/global_mapping.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <unordered_set>

#include "core/check.h"
#include "core/memory.h"
#include "core/statistics.h"
#include "core/threads.h"
#include "core/timer.h"
#include "geometry/angles.h"
#include "lidar/imls.h"
#include "lidar/surface.h"
#include "lidar/voxel_grid.h"
#include "optim/correction.h"
#include "optim/cost_functions.h"
#include "optim/pose_block.h"

namespace jvl::mapping {

void GlobalMapInput::Check() const {
  keyframes.Check("global input keyframes");
  const int64_t k = static_cast<int64_t>(keyframes.size());
  JVL_CHECK(k > 0, "global optimisation needs at least one keyframe");
  JVL_CHECK(scans.empty() || static_cast<int64_t>(scans.size()) == k,
            "scans: " << scans.size() << " entries for " << k << " keyframes");
  for (size_t i = 0; i < scans.size(); ++i)
    JVL_CHECK(scans[i].points.size() == scans[i].normals.size(),
              "scan of keyframe row " << i << ": " << scans[i].points.size() << " points, "
                                      << scans[i].normals.size() << " normals");
  for (const auto& o : observations)
    JVL_CHECK(o.keyframe >= 0 && o.keyframe < k && o.map_point >= 0 &&
                  o.map_point < static_cast<int32_t>(map_points.size()),
              "observation of keyframe row " << o.keyframe << " / map point " << o.map_point
                                             << " out of range");
  for (const auto& l : saved_imls)
    JVL_CHECK(l.n >= 0 && l.n < k && l.c >= 0 && l.c < k,
              "IMLS correspondence (" << l.n << ", " << l.c << ") out of range");
  for (const auto& p : saved_imls_pairs)
    JVL_CHECK(p.n >= 0 && p.n < k && p.c >= 0 && p.c < k,
              "IMLS pair (" << p.n << ", " << p.c << ") out of range");
  if (!odometry.empty()) odometry.Check("global input odometry");
  JVL_CHECK(odometry_conditioning.empty() || odometry_conditioning.size() == odometry.size(),
            "odometry conditioning has " << odometry_conditioning.size()
                                         << " entries for an odometry of " << odometry.size()
                                         << " frames");
  for (const double c : odometry_conditioning)
    JVL_CHECK(std::isfinite(c), "odometry conditioning must be finite");
  for (const auto& l : loops)
    JVL_CHECK(l.match >= 0 && l.match < l.query && l.query < k,
              "loop (" << l.match << ", " << l.query << ") out of range or not match < query");
}

int64_t AddLoopPoints(GlobalMapInput* input) {
  int64_t added = 0;
  for (const LoopConstraint& l : input->loops) {
    const Rigid3d& world_from_match = input->keyframes.world_from_cam[static_cast<size_t>(l.match)];
    for (const LoopConstraint::Point& p : l.points) {
      const int32_t row = static_cast<int32_t>(input->map_points.size());
      input->map_points.push_back(world_from_match * p.p_match);
      input->observations.push_back({l.match, row, p.match_uv, p.match_octave});
      input->observations.push_back({l.query, row, p.query_uv, p.query_octave});
      added += 2;
    }
  }
  return added;
}

double ApplyLoopCorrections(GlobalMapInput* input) {
  std::vector<LoopConstraint> loops = input->loops;
  std::stable_sort(
      loops.begin(), loops.end(),
      [](const LoopConstraint& a, const LoopConstraint& b) { return a.query < b.query; });
  std::vector<Rigid3d>& poses = input->keyframes.world_from_cam;
  const std::vector<Rigid3d> before = poses;
  for (const LoopConstraint& l : loops) {
    const size_t m = static_cast<size_t>(l.match), q = static_cast<size_t>(l.query);
    const Rigid3d target = poses[m] * l.match_from_query;
    const std::vector<Rigid3d> segment(poses.begin() + static_cast<std::ptrdiff_t>(m),
                                       poses.begin() + static_cast<std::ptrdiff_t>(q) + 1);
    std::vector<double> positions;
    for (size_t i = m; i <= q; ++i)
      positions.push_back(static_cast<double>(input->keyframes.frames[i]));
    const std::vector<Rigid3d> corrected = optim::DistributeCorrection(segment, target, positions);
    const Rigid3d after = corrected.back() * poses[q].Inverse();  // world frame
    for (size_t i = m; i <= q; ++i) poses[i] = corrected[i - m];
    for (size_t i = q + 1; i < poses.size(); ++i) poses[i] = after * poses[i];
  }
  // Map points follow their first observer.
  std::vector<int64_t> first(input->map_points.size(), -1);
  for (const auto& o : input->observations) {
    int64_t& f = first[static_cast<size_t>(o.map_point)];
    if (f < 0 || o.keyframe < f) f = o.keyframe;
  }
  for (size_t p = 0; p < first.size(); ++p) {
    if (first[p] < 0) continue;
    const size_t k = static_cast<size_t>(first[p]);
    input->map_points[p] = poses[k] * (before[k].Inverse() * input->map_points[p]);
  }
  double largest = 0;
  for (size_t i = 0; i < poses.size(); ++i)
    largest = std::max(largest, (poses[i].translation() - before[i].translation()).norm());
  return largest;
}

void ImlsTraversalOptions::Check() const {
  JVL_CHECK(scan_map_size >= 1, "scan_map_size (N) must be >= 1, got " << scan_map_size);
  association.Check();
}

optim::JointProblemOptions DefaultGlobalJointOptions() {
  optim::JointProblemOptions o;
  o.visual_gate_chi2 = 5.991;     // chi2(2, 0.95)
  o.max_point_sigma_ratio = 0.3;  // hold poorly determined points
  // e_D is whitened by its measured noise and weighted like one measurement per residual (the
  // paper's count rule, gamma = N_V / N_D, made it several hundred times heavier and the
  // direction priors then made every drive of the gains table worse: docs/global_opt.md).
  o.gamma = 1.0;
  // e_L's sigma per keyframe pair from the pair's own residuals (docs/global_opt.md "Noise of
  // e_L per keyframe pair"): on the gains drives it took the steps of the prior that survived
  // from 17 to a few and lowered the APE.
  o.imls_pair_noise_max = 3.0;
  return o;
}

optim::SolveOptions DefaultGlobalSolveOptions() {
  optim::SolveOptions o;
  o.function_tolerance = 1e-5;  // the last 1e-5 of the cost does not move the poses
  return o;
}

GlobalMappingOptions GlobalMappingOptions::EveryObservation() {
  GlobalMappingOptions o;
  o.joint.visual_gate_chi2 = 0;
  o.joint.max_point_sigma_ratio = 0;
  o.points_per_keyframe = 0;
  o.solve.function_tolerance = 1e-6;
  return o;
}

void GlobalMappingOptions::Check() const {
  joint.Check();
  solve.Check();
  traversal.Check();
  JVL_CHECK(rounds >= 1, "rounds must be >= 1, got " << rounds);
  JVL_CHECK(std::isfinite(round_tolerance_m) && round_tolerance_m >= 0,
            "round_tolerance_m must be >= 0 (0 = every round), got " << round_tolerance_m);
  JVL_CHECK(first_direction_round >= 0,
            "first_direction_round must be >= 0, got " << first_direction_round);
  JVL_CHECK(std::isfinite(refit_outlier_deg) && refit_outlier_deg > 0 && refit_outlier_deg < 90,
            "refit_outlier_deg must be in (0, 90) degrees, got " << refit_outlier_deg);
  JVL_CHECK(refit_min_support >= 1, "refit_min_support must be >= 1, got " << refit_min_support);
  JVL_CHECK(points_per_keyframe >= 0,
            "points_per_keyframe must be >= 0 (0 = all), got " << points_per_keyframe);
  JVL_CHECK(std::isfinite(direction_sigma_px) && std::isfinite(min_direction_sigma_px) &&
                min_direction_sigma_px > 0,
            "direction_sigma_px must be finite and min_direction_sigma_px > 0");
  JVL_CHECK(std::isfinite(odometry_gate), "odometry_gate must be finite");
  JVL_CHECK(std::isfinite(odometry_max_inflation) && odometry_max_inflation >= 1,
            "odometry_max_inflation must be >= 1, got " << odometry_max_inflation);
  JVL_CHECK(odometry_local_window >= 0,
            "odometry_local_window must be >= 0 (0 = off), got " << odometry_local_window);
  JVL_CHECK(std::isfinite(odometry_local_max) && odometry_local_max >= 1,
            "odometry_local_max must be >= 1, got " << odometry_local_max);
  JVL_CHECK(std::isfinite(surface_max_distance_m) && surface_max_distance_m > 0 &&
                surface_max_distance_m <= traversal.association.search_radius,
            "surface_max_distance_m must be in (0, " << traversal.association.search_radius
                                                     << "] m (the IMLS search radius), got "
                                                     << surface_max_distance_m);
  JVL_CHECK(motion_sigma_m.allFinite() && motion_sigma_m.minCoeff() > 0,
            "motion_sigma_m must be finite and > 0");
  JVL_CHECK(
      std::isfinite(vertical_bias_deg) && vertical_bias_deg >= 0,
      "vertical_bias_deg must be >= 0 (0: sigma from the VPs' spread), got " << vertical_bias_deg);
  JVL_CHECK(std::isfinite(vertical_bias_per_white) && vertical_bias_per_white >= 0,
            "vertical_bias_per_white must be >= 0, got " << vertical_bias_per_white);
  JVL_CHECK(std::isfinite(vertical_sigma_deg) && vertical_sigma_deg >= 0,
            "vertical_sigma_deg must be >= 0 (0: from the rule), got " << vertical_sigma_deg);
  JVL_CHECK(std::isfinite(min_vertical_sigma_deg) && min_vertical_sigma_deg > 0,
            "min_vertical_sigma_deg must be > 0, got " << min_vertical_sigma_deg);
  JVL_CHECK(vertical_half_window >= 0,
            "vertical_half_window must be >= 0 frames, got " << vertical_half_window);
  JVL_CHECK(std::isfinite(min_odometry_sigma_m) && min_odometry_sigma_m > 0 &&
                std::isfinite(min_odometry_sigma_deg) && min_odometry_sigma_deg > 0,
            "the minimum odometry sigmas must be positive");
}

int64_t SelectObservations(std::vector<optim::VisualObservation>* observations, size_t num_points,
                           int per_keyframe) {
  int64_t num_keyframes = 0;
  std::vector<int32_t> count(num_points, 0);
  for (const auto& o : *observations) {
    JVL_CHECK(o.map_point >= 0 && static_cast<size_t>(o.map_point) < num_points && o.keyframe >= 0,
              "observation of map point " << o.map_point << " in keyframe row " << o.keyframe
                                          << " is out of range");
    ++count[o.map_point];
    num_keyframes = std::max(num_keyframes, o.keyframe + 1);
  }
  if (per_keyframe <= 0)
    return std::count_if(count.begin(), count.end(), [](int32_t c) { return c > 0; });
  // Keyframe rows of each point (CSR).
  std::vector<int64_t> start(num_points + 1, 0);
  for (size_t i = 0; i < num_points; ++i) start[i + 1] = start[i] + count[i];
  std::vector<int64_t> rows(observations->size());
  std::vector<int64_t> fill(start.begin(), start.end() - 1);
  for (const auto& o : *observations) rows[fill[o.map_point]++] = o.keyframe;
  std::vector<int32_t> order(num_points);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int32_t a, int32_t b) { return count[a] > count[b]; });
  std::vector<int32_t> taken_in(static_cast<size_t>(num_keyframes), 0);
  std::vector<char> taken(num_points, 0);
  int64_t points = 0;
  for (const int32_t p : order) {
    bool needed = false;
    for (int64_t k = start[p]; k < start[p + 1] && !needed; ++k)
      needed = taken_in[static_cast<size_t>(rows[k])] < per_keyframe;
    if (!needed) continue;
    taken[p] = 1;
    ++points;
    for (int64_t k = start[p]; k < start[p + 1]; ++k) ++taken_in[static_cast<size_t>(rows[k])];
  }
  observations->erase(
      std::remove_if(observations->begin(), observations->end(),
                     [&](const optim::VisualObservation& o) { return !taken[o.map_point]; }),
      observations->end());
  observations->shrink_to_fit();
  return points;
}

const char* ToString(GlobalMappingOptions::DirectionSource source) {
  switch (source) {
    case GlobalMappingOptions::DirectionSource::kPrior:
      return "prior";
    case GlobalMappingOptions::DirectionSource::kRefit:
      return "refit";
    case GlobalMappingOptions::DirectionSource::kFree:
      return "free";
  }
  return "?";
}

std::vector<optim::DirectionConstraint> ToDirectionConstraints(
    const std::vector<direction::VpPrior>& priors) {
  std::vector<optim::DirectionConstraint> out;
  out.reserve(priors.size());
  for (const auto& p : priors) out.push_back({p.keyframe, p.vp, p.direction_world});
  return out;
}

namespace {

// First model keyframe for keyframe n (local mapping step 2): the first i with f_n - f_i <= N,
// but always at least n - 1 so that sparse keyframes still get a model.
size_t ModelStart(const Trajectory& keyframes, size_t n, int scan_map_size) {
  size_t start = n - 1;
  while (start > 0 && keyframes.frames[n] - keyframes.frames[start - 1] <= scan_map_size) --start;
  return start;
}

// The stored scan as a sampled one: IMLS-SLAM sampling on the stored normals (planarity taken
// as 1: the stored scan keeps only points that had a normal).
lidar::SampledScan Sampled(const lidar::StoredScan& stored, int samples_per_list) {
  lidar::ScanSurface surface;
  surface.points.reserve(stored.size());
  surface.normals.reserve(stored.size());
  for (size_t j = 0; j < stored.size(); ++j) {
    surface.points.push_back(stored.points[j].cast<double>());
    surface.normals.push_back(stored.normals[j].cast<double>());
    surface.valid.push_back(surface.normals.back().squaredNorm() >= 0.25 ? 1 : 0);
  }
  surface.planarity.assign(stored.size(), 1.0);
  return lidar::SampleSurface(surface, samples_per_list);
}

// Steps 3-4 for keyframe n against `model` (the scans of its window, current poses).
std::vector<optim::ImlsCorrespondence> TraverseKeyframe(const Trajectory& keyframes,
                                                        const std::vector<lidar::StoredScan>& scans,
                                                        size_t n, const lidar::ImlsModel& model,
                                                        const ImlsTraversalOptions& options) {
  std::vector<optim::ImlsCorrespondence> out;
  const lidar::AssociationOptions& a = options.association;
  const lidar::SampledScan scan = Sampled(scans[n], a.samples_per_list);
  const Rigid3d& world_from_n = keyframes.world_from_cam[n];
  for (const int j : lidar::SelectSamples(scan, world_from_n, model, a)) {
    lidar::ImlsProjection proj;
    if (!lidar::ProjectPoint(model, world_from_n * scan.points[j], a, &proj)) continue;
    if (proj.nearest_scan < 0) continue;
    const Rigid3d cam_from_world =
        keyframes.world_from_cam[static_cast<size_t>(proj.nearest_scan)].Inverse();
    optim::ImlsCorrespondence l;
    l.n = static_cast<int64_t>(n);
    l.c = proj.nearest_scan;
    l.p_x = scan.points[j];
    l.c_p_y = cam_from_world * proj.projection;  // ^c p_y = T_cw p_y (step 4)
    l.c_normal = (cam_from_world.rotation() * proj.normal).normalized();
    out.push_back(l);
  }
  return out;
}

}  // namespace

std::vector<optim::ImlsCorrespondence> TraverseImls(const Trajectory& keyframes,
                                                    const std::vector<lidar::StoredScan>& scans,
                                                    const ImlsTraversalOptions& options,
                                                    int threads) {
  options.Check();
  JVL_CHECK(scans.size() == keyframes.size(),
            "TraverseImls: " << scans.size() << " scans for " << keyframes.size() << " keyframes");
  // The model of keyframe n holds the scans of keyframes ModelStart(n)..n-1 at the current
  // poses; consecutive keyframes share most of it, so it slides (each scan is added once). The
  // keyframes are cut into fixed chunks that run in parallel, each sliding its own model from
  // the chunk's first keyframe; the chunks do not depend on the thread count, so neither does
  // the result.
  constexpr size_t kChunk = 64;
  const size_t k = keyframes.size();
  const size_t chunks = k > 1 ? (k - 1 + kChunk - 1) / kChunk : 0;
  std::vector<std::vector<optim::ImlsCorrespondence>> parts(chunks);
  ParallelFor(static_cast<int64_t>(chunks), ResolveThreadCount(threads), [&](int64_t chunk) {
    lidar::ImlsModel model(options.association.search_radius);
    const size_t first = 1 + static_cast<size_t>(chunk) * kChunk;
    const size_t last = std::min(k, first + kChunk);
    size_t next = 0;  // next scan to add
    for (size_t n = first; n < last; ++n) {
      const size_t start = ModelStart(keyframes, n, options.scan_map_size);
      for (const int64_t id : model.scan_ids())
        if (static_cast<size_t>(id) < start) model.RemoveScan(id);
      for (next = std::max(next, start); next < n; ++next) {
        lidar::AddScanToModel(scans[next].points, scans[next].normals,
                              keyframes.world_from_cam[next], static_cast<int64_t>(next), &model);
      }
      auto l = TraverseKeyframe(keyframes, scans, n, model, options);
      parts[static_cast<size_t>(chunk)].insert(parts[static_cast<size_t>(chunk)].end(), l.begin(),
                                               l.end());
    }
  });
  std::vector<optim::ImlsCorrespondence> out;
  size_t total = 0;
  for (const auto& part : parts) total += part.size();
  out.reserve(total);
  for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

namespace {

// Loop constraints: each loop's query scan against the scans of the keyframes within
// scan_map_size frames of its match (earlier than the query), at the current poses.
std::vector<optim::ImlsCorrespondence> TraverseLoops(const Trajectory& keyframes,
                                                     const std::vector<lidar::StoredScan>& scans,
                                                     const std::vector<LoopConstraint>& loops,
                                                     const ImlsTraversalOptions& options) {
  std::vector<optim::ImlsCorrespondence> out;
  for (const LoopConstraint& l : loops) {
    const size_t m = static_cast<size_t>(l.match), q = static_cast<size_t>(l.query);
    lidar::ImlsModel model(options.association.search_radius);
    for (size_t i = 0; i < q; ++i) {
      if (std::abs(keyframes.frames[i] - keyframes.frames[m]) > options.scan_map_size) continue;
      lidar::AddScanToModel(scans[i].points, scans[i].normals, keyframes.world_from_cam[i],
                            static_cast<int64_t>(i), &model);
    }
    const auto c = TraverseKeyframe(keyframes, scans, q, model, options);
    out.insert(out.end(), c.begin(), c.end());
  }
  return out;
}

// What stays the same over the rounds of Eq. (7).
struct FixedTerms {
  direction::DirectionSelection directions;  // e_D's priors as selected from the artifact
  std::vector<direction::VpRay> vp_rays;     // candidates of the vertical prior
  bool aggregate = false;                    // e_L summed per keyframe pair (compressed form)
  bool summed_saved = false;                 // the saved set L given to the problem summed per pair
  std::vector<optim::ImlsPair> saved_pairs;  // summed_saved: L summed per keyframe pair
  int64_t saved_count = 0;                   // correspondences in L
  bool fresh = false;                        // a fresh traversal in every round
  int rounds = 1;
};

// e_D once it has entered the problem (GlobalMappingOptions::first_direction_round).
struct DirectionTerm {
  bool entered = false;
  std::vector<direction::VpPrior> priors;  // d_w as it was when e_D entered
  std::vector<int32_t> clusters;           // cluster of each prior
  std::vector<optim::DirectionConstraint> constraints;
  std::vector<Eigen::Vector3d> free_directions;  // kFree: current d_w of each kept cluster
  int vertical_block = -1;  // index of the vertical prior's direction in free_directions
};

// e_O once it has entered the problem (GlobalMappingOptions::use_odometry).
struct OdometryTerm {
  bool entered = false;
  std::vector<optim::RelativePoseConstraint> constraints;  // keyframe rows i, i + 1
};

// The residual of E = Z^-1 (T_i^-1 T_j) per axis, [2 vec(q_E); t_E] (optim::RelativePoseCost with
// unit whitening), divided by `scale` (the pair's sigma in units of one well-conditioned frame's).
Eigen::Matrix<double, 6, 1> RelativeError(const optim::RelativePoseConstraint& c,
                                          const Trajectory& keyframes, double scale) {
  const optim::RelativePoseCost cost(c.i_from_j.rotation(), c.i_from_j.translation(),
                                     Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones());
  const optim::PoseBlock i = optim::ToPoseBlock(keyframes.world_from_cam[c.i]);
  const optim::PoseBlock j = optim::ToPoseBlock(keyframes.world_from_cam[c.j]);
  Eigen::Matrix<double, 6, 1> r;
  cost(i.data(), j.data(), r.data());
  return r / scale;
}

// Squared norm of the whitened residual of `c` at `keyframes`.
double WhitenedSquaredNorm(const optim::RelativePoseConstraint& c, const Trajectory& keyframes) {
  const Eigen::Matrix<double, 6, 1> r = RelativeError(c, keyframes, 1.0);
  return r.head<3>().cwiseQuotient(c.sigma_rad).squaredNorm() +
         r.tail<3>().cwiseQuotient(c.sigma_m).squaredNorm();
}

// Per odometry row, the variance factor of its frame's motion (GlobalMappingOptions::
// odometry_conditioning): lambda_ref / lambda clamped to [1, max_inflation^2]; all 1 without
// conditioning values.
std::vector<double> OdometryVarianceFactors(const std::vector<double>& conditioning,
                                            const GlobalMappingOptions& options) {
  std::vector<double> factor(conditioning.size(), 1.0);
  if (!options.odometry_conditioning) return factor;
  std::vector<double> registered;
  for (const double c : conditioning)
    if (c > 0) registered.push_back(c);
  if (registered.empty()) return factor;
  const double ref = Median(registered);
  const double max_factor = options.odometry_max_inflation * options.odometry_max_inflation;
  for (size_t k = 0; k < conditioning.size(); ++k)
    factor[k] =
        conditioning[k] > 0 ? std::clamp(ref / conditioning[k], 1.0, max_factor) : max_factor;
  return factor;
}

// Per odometry pair, the factor of its local noise (GlobalMappingOptions::odometry_local_window):
// the median of the whitened residual norms within the window, divided by the drive's median,
// clamped to [1, odometry_local_max]; all 1 when off.
std::vector<double> OdometryLocalFactors(const std::vector<double>& norm,
                                         const GlobalMappingOptions& options,
                                         GlobalMappingResult* result) {
  std::vector<double> factor(norm.size(), 1.0);
  if (options.odometry_local_window <= 0 || norm.empty()) return factor;
  const double reference = Median(norm);
  result->odometry_median_norm = reference;
  if (!(reference > 0)) return factor;
  const auto w = static_cast<size_t>(options.odometry_local_window);
  for (size_t k = 0; k < norm.size(); ++k) {
    const size_t begin = k >= w ? k - w : 0;
    const size_t end = std::min(norm.size(), k + w + 1);
    const double local = Median(std::vector<double>(norm.begin() + begin, norm.begin() + end));
    factor[k] = std::clamp(local / reference, 1.0, options.odometry_local_max);
  }
  return factor;
}

// The odometry's motion between consecutive keyframes whose frames it holds, with a sigma per
// axis measured against `keyframes` (the first round's solution): 1.4826 x the median absolute
// per-frame residual (MAD about zero; each residual divided by its pair's scale), at least the
// minimum; the pairs above the gate are left out. A pair's scale is the square root of its
// frame count times the mean variance factor of the odometry rows after the first keyframe up to
// the second (OdometryVarianceFactors).
void EnterOdometry(const Trajectory& keyframes, const Trajectory& odometry,
                   const std::vector<double>& conditioning, const GlobalMappingOptions& options,
                   OdometryTerm* term, GlobalMappingResult* result) {
  term->entered = true;
  if (odometry.empty()) return;
  const std::vector<double> factor = OdometryVarianceFactors(conditioning, options);
  result->odometry_conditioned =
      options.odometry_conditioning &&
      std::any_of(conditioning.begin(), conditioning.end(), [](double c) { return c > 0; });
  std::vector<optim::RelativePoseConstraint> pairs;
  std::vector<double> scale;
  std::vector<double> inflation;
  for (size_t i = 0; i + 1 < keyframes.size(); ++i) {
    const auto a = odometry.IndexOf(keyframes.frames[i]);
    const auto b = odometry.IndexOf(keyframes.frames[i + 1]);
    if (!a || !b) continue;
    optim::RelativePoseConstraint c;
    c.i = static_cast<int64_t>(i);
    c.j = static_cast<int64_t>(i + 1);
    c.i_from_j = odometry.world_from_cam[*a].Inverse() * odometry.world_from_cam[*b];
    pairs.push_back(c);
    double mean_factor = 1.0;
    if (!factor.empty() && *b > *a) {
      double sum = 0;
      for (size_t r = *a + 1; r <= *b; ++r) sum += factor[r];
      mean_factor = sum / static_cast<double>(*b - *a);
    }
    const auto frames =
        static_cast<double>(std::max<int64_t>(keyframes.frames[i + 1] - keyframes.frames[i], 1));
    scale.push_back(std::sqrt(frames * mean_factor));
    inflation.push_back(std::sqrt(mean_factor));
  }
  result->odometry_pairs = static_cast<int64_t>(pairs.size());
  if (pairs.empty()) {
    spdlog::warn("odometry term: the odometry holds no consecutive keyframe pair; left out");
    return;
  }
  std::vector<std::vector<double>> abs(6);
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Eigen::Matrix<double, 6, 1> r = RelativeError(pairs[k], keyframes, scale[k]);
    for (int a = 0; a < 6; ++a) abs[a].push_back(std::abs(r(a)));
  }
  Eigen::Vector3d sigma_rad, sigma_m;
  for (int a = 0; a < 3; ++a) {
    sigma_rad(a) = std::max(options.min_odometry_sigma_deg / kDegPerRad, 1.4826 * Median(abs[a]));
    sigma_m(a) = std::max(options.min_odometry_sigma_m, 1.4826 * Median(abs[3 + a]));
  }
  result->odometry_sigma_deg = sigma_rad * kDegPerRad;
  result->odometry_sigma_m = sigma_m;
  std::vector<double> norm(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    pairs[k].sigma_rad = sigma_rad * scale[k];
    pairs[k].sigma_m = sigma_m * scale[k];
    norm[k] = std::sqrt(WhitenedSquaredNorm(pairs[k], keyframes));
  }
  const std::vector<double> local = OdometryLocalFactors(norm, options, result);
  for (size_t k = 0; k < pairs.size(); ++k) {
    optim::RelativePoseConstraint c = pairs[k];
    if (inflation[k] > 2.0) ++result->odometry_inflated;
    if (options.odometry_gate > 0 && norm[k] > options.odometry_gate) {
      ++result->odometry_gated;
      continue;
    }
    if (local[k] > 1.0) {
      c.sigma_rad *= local[k];
      c.sigma_m *= local[k];
      ++result->odometry_local_inflated;
    }
    term->constraints.push_back(c);
  }
  spdlog::info(
      "odometry term: {} keyframe pairs ({} left out above the gate, {} with a sigma raised "
      "over 2x by a weakly conditioned registration, {} raised by the local noise), sigma per "
      "frame ({:.4f}, {:.4f}, {:.4f}) m, ({:.4f}, {:.4f}, {:.4f}) deg (camera x, y, z; measured "
      "against the first round)",
      term->constraints.size(), result->odometry_gated, result->odometry_inflated,
      result->odometry_local_inflated, sigma_m.x(), sigma_m.y(), sigma_m.z(),
      result->odometry_sigma_deg.x(), result->odometry_sigma_deg.y(),
      result->odometry_sigma_deg.z());
}

// e_O of this round: from the second round on (its sigmas need a solution without it; a single
// round, without a fresh traversal, leaves it out).
void SetOdometryTerm(int round, const GlobalMapInput& input, const GlobalMappingOptions& options,
                     OdometryTerm* term, optim::JointProblemInput* problem,
                     GlobalMappingResult* result) {
  problem->relative_poses.clear();
  if (!options.use_odometry || input.odometry.empty() || round < 1) return;
  if (!term->entered)
    EnterOdometry(result->keyframes, input.odometry, input.odometry_conditioning, options, term,
                  result);
  problem->relative_poses = term->constraints;
}

// e_M: every three consecutive keyframes (GlobalMappingOptions::use_motion; their frames
// increase, GlobalMapInput::Check).
std::vector<optim::MotionConstraint> MotionConstraints(const Trajectory& keyframes,
                                                       const GlobalMappingOptions& options) {
  std::vector<optim::MotionConstraint> out;
  if (!options.use_motion) return out;
  for (size_t b = 1; b + 1 < keyframes.size(); ++b) {
    optim::MotionConstraint m;
    m.a = static_cast<int64_t>(b - 1);
    m.b = static_cast<int64_t>(b);
    m.c = static_cast<int64_t>(b + 1);
    m.frames_ab = static_cast<double>(keyframes.frames[b] - keyframes.frames[b - 1]);
    m.frames_bc = static_cast<double>(keyframes.frames[b + 1] - keyframes.frames[b]);
    m.sigma_m = options.motion_sigma_m * std::sqrt(0.5 * (m.frames_ab + m.frames_bc));
    out.push_back(m);
  }
  return out;
}

// Triples of the final solution whose whitened e_M is above the kernel scale.
int64_t CountMotionOutliers(const std::vector<optim::MotionConstraint>& motion,
                            const Trajectory& keyframes, double cauchy) {
  if (cauchy <= 0) return 0;
  int64_t n = 0;
  for (const auto& m : motion) {
    const optim::MotionSmoothnessCost cost(m.frames_ab, m.frames_bc, m.sigma_m.cwiseInverse());
    const optim::PoseBlock a = optim::ToPoseBlock(keyframes.world_from_cam[m.a]);
    const optim::PoseBlock b = optim::ToPoseBlock(keyframes.world_from_cam[m.b]);
    const optim::PoseBlock c = optim::ToPoseBlock(keyframes.world_from_cam[m.c]);
    Eigen::Vector3d r;
    cost(a.data(), b.data(), c.data(), r.data());
    if (r.squaredNorm() > cauchy * cauchy) ++n;
  }
  return n;
}

// Pairs of the final solution whose whitened e_O is above the kernel scale.
int64_t CountOdometryOutliers(const OdometryTerm& term, const Trajectory& keyframes,
                              double cauchy) {
  if (cauchy <= 0) return 0;
  int64_t n = 0;
  for (const auto& c : term.constraints)
    if (WhitenedSquaredNorm(c, keyframes) > cauchy * cauchy) ++n;
  return n;
}

// e_V (Eq. 5): the subset of the map points of GlobalMappingOptions::points_per_keyframe.
void SelectVisualTerm(const GlobalMappingOptions& options, GlobalMapInput* input,
                      GlobalMappingResult* result) {
  result->input_observations = static_cast<int64_t>(input->observations.size());
  result->input_points = static_cast<int64_t>(input->map_points.size());
  result->selected_points = SelectObservations(&input->observations, input->map_points.size(),
                                               options.points_per_keyframe);
  result->selected_observations = static_cast<int64_t>(input->observations.size());
  if (options.points_per_keyframe > 0) {
    spdlog::info(
        "visual term: {} of {} map points ({} of {} observations), at least {} per "
        "keyframe",
        result->selected_points, result->input_points, result->selected_observations,
        result->input_observations, options.points_per_keyframe);
  }
}

// Also releases the saved correspondences once they are summed per pair (they are a large part
// of the memory on a long sequence).
FixedTerms PrepareFixedTerms(GlobalMapInput* in, const GlobalMappingOptions& options,
                             GlobalMappingResult* result) {
  const GlobalMapInput& input = *in;
  FixedTerms t;
  t.directions = direction::SelectDirections(input.keyframes, input.directions);
  if (options.use_directions && options.use_vertical) t.vp_rays = input.vp_rays;
  result->directions_not_keyframe = t.directions.not_keyframe;
  result->directions_at_infinity = t.directions.at_infinity;
  if (options.use_directions)
    result->directions_used = static_cast<int64_t>(t.directions.priors.size());
  t.fresh = options.fresh_traversal && !input.scans.empty();
  t.rounds = t.fresh ? options.rounds : 1;
  // The saved set L does not change between rounds: summed per keyframe pair once (exact, see
  // optim/imls_pair_cost.h) instead of copying millions of correspondences into every round.
  t.aggregate = options.joint.SumsImlsPerPair();
  t.summed_saved = options.use_saved_imls && t.aggregate;
  JVL_CHECK(input.saved_imls_pairs.empty() || !options.use_saved_imls || t.summed_saved,
            "the saved IMLS set is given summed per keyframe pair, which needs the compressed "
            "e_L form (no Huber kernel on e_L)");
  if (t.summed_saved) {
    t.saved_pairs = optim::AggregateImls(input.saved_imls);
    t.saved_pairs.insert(t.saved_pairs.end(), input.saved_imls_pairs.begin(),
                         input.saved_imls_pairs.end());
  }
  t.saved_count = static_cast<int64_t>(input.saved_imls.size());
  for (const auto& p : input.saved_imls_pairs) t.saved_count += p.sum.count();
  if (t.summed_saved) {
    std::vector<optim::ImlsCorrespondence>().swap(in->saved_imls);
    ReleaseFreeHeapMemory();
  }
  return t;
}

// The direction constraints when e_D enters: as selected (kPrior), with re-estimated fixed d_w
// (kRefit) or with one free d_w block per cluster initialised by the re-estimate (kFree); VPs
// far from their cluster's direction are dropped in both re-estimated forms.
void EnterDirections(const Trajectory& keyframes, const PinholeCamera& camera,
                     const direction::DirectionSelection& dirs, const GlobalMappingOptions& options,
                     DirectionTerm* term, GlobalMappingResult* result) {
  using Source = GlobalMappingOptions::DirectionSource;
  term->entered = true;
  if (options.direction_source == Source::kPrior) {
    term->priors = dirs.priors;
    term->clusters = dirs.clusters;
    term->constraints = ToDirectionConstraints(term->priors);
    return;
  }
  const direction::DirectionRefit refit = direction::RefitDirections(
      keyframes, camera, dirs, options.refit_outlier_deg, options.refit_min_support);
  term->priors = refit.selection.priors;
  term->clusters = refit.selection.clusters;
  term->constraints = ToDirectionConstraints(term->priors);
  result->directions_outliers = refit.outliers;
  result->directions_small_cluster = refit.small_cluster_vps;
  result->direction_change_deg = refit.change_deg;
  result->directions_used = static_cast<int64_t>(term->constraints.size());
  for (const auto& [cluster, change] : refit.change_deg)
    spdlog::debug("direction prior of cluster {} re-estimated: moved {:.3f} deg", cluster, change);
  if (options.direction_source != Source::kFree) return;
  std::map<int32_t, int32_t> block_of;
  result->free_direction_clusters.clear();
  for (const auto& [cluster, d] : refit.directions) {
    block_of[cluster] = static_cast<int32_t>(term->free_directions.size());
    term->free_directions.push_back(d);
    result->free_direction_clusters.push_back(cluster);
  }
  for (size_t i = 0; i < term->constraints.size(); ++i)
    term->constraints[i].free_direction = block_of.at(refit.selection.clusters[i]);
}

// The vertical direction prior, selected at the poses where e_D enters: one free direction
// block (after the clusters' ones) and a ray-form constraint per inlier keyframe.
void EnterVertical(const std::vector<direction::VpRay>& rays, const GlobalMappingOptions& options,
                   DirectionTerm* term, optim::JointProblemOptions* joint,
                   GlobalMappingResult* result) {
  if (rays.empty() || result->keyframes.size() == 0) return;
  const Eigen::Vector3d up =
      -(result->keyframes.world_from_cam.front().rotation() * Eigen::Vector3d::UnitY());
  const direction::VerticalSelection v =
      direction::SelectVertical(result->keyframes, rays, up, options.vertical_max_deg,
                                options.vertical_outlier_deg, options.min_vertical_sigma_deg);
  result->vertical_candidates = v.candidates;
  result->vertical_outliers = v.outliers;
  if (static_cast<int>(v.rows.size()) < options.refit_min_support) {
    spdlog::info(
        "vertical direction prior: {} of {} candidate keyframes kept, fewer than {}: "
        "not used",
        v.rows.size(), v.candidates, options.refit_min_support);
    return;
  }
  std::vector<int64_t> frames;
  for (const int64_t row : v.rows) frames.push_back(result->keyframes.frames[row]);
  const direction::SlowError slow =
      direction::MeasureSlowError(frames, v.errors_deg, options.vertical_half_window);
  result->vertical_disagreement_deg = slow.slow_deg;
  result->vertical_white_deg = slow.white_deg.maxCoeff();
  result->vertical_rho = v.rho;
  // The slow bias is at least a share of the white spread (noisier VPs are also more slowly
  // biased); 0 keeps the spread rule.
  const double b = options.vertical_bias_deg > 0
                       ? std::max(options.vertical_bias_deg,
                                  options.vertical_bias_per_white * result->vertical_white_deg)
                       : 0.0;
  result->vertical_bias_deg = b;
  const double d = result->vertical_disagreement_deg;
  if (options.vertical_sigma_deg > 0) {
    result->vertical_sigma_rule = "given";
    result->vertical_sigma_deg = options.vertical_sigma_deg;
  } else if (b > 0 && v.rows.size() >= 3) {
    // Left out also where D exceeds B by a rounding error (sigma would be infinite).
    if (d <= b * (1.0 + 1e-9)) {
      result->vertical_sigma_rule = "left_out";
      spdlog::info(
          "vertical direction prior: left out, its VPs disagree with the poses by {:.3f} deg at "
          "low frequency, within their own slow bias of {:.3f} deg (no evidence of tilt; {} "
          "keyframes, white spread {:.3f} deg)",
          d, b, v.rows.size(), result->vertical_white_deg);
      return;
    }
    result->vertical_sigma_rule = "evidence";
    result->vertical_sigma_deg =
        std::max(options.min_vertical_sigma_deg, b * d / std::sqrt((d - b) * (d + b)));
  } else {
    if (b > 0)
      spdlog::info(
          "vertical direction prior: {} keyframes are too few to measure the low-frequency "
          "disagreement; sigma from the VPs' spread",
          v.rows.size());
    result->vertical_sigma_rule = "spread";
    result->vertical_sigma_deg = v.sigma_deg;
  }
  result->vertical_used = static_cast<int64_t>(v.rows.size());
  result->vertical_direction = v.direction;
  joint->direction_sigma_rad = result->vertical_sigma_deg / kDegPerRad;
  term->vertical_block = static_cast<int>(term->free_directions.size());
  term->free_directions.push_back(v.direction);
  for (size_t i = 0; i < v.rows.size(); ++i) {
    optim::DirectionConstraint c;
    c.keyframe = v.rows[i];
    c.ray_form = true;
    c.ray = v.rays[i];
    c.free_direction = term->vertical_block;
    term->constraints.push_back(c);
  }
  spdlog::info(
      "vertical direction prior: {} keyframes ({} candidates, {} outliers), sigma {:.3f} deg "
      "(low-frequency disagreement {:.3f} deg, bias {:.3f} deg; white spread {:.3f} deg, lag-1 "
      "correlation {:.2f})",
      v.rows.size(), v.candidates, v.outliers, result->vertical_sigma_deg, d, b,
      result->vertical_white_deg, v.rho);
}

// sigma of e_D: given, or estimated where e_D enters from the median |e_D| (2D Gaussian: median
// |e| = sigma sqrt(2 ln 2)). Measured at the warm-started poses, so it also holds what is left
// of the drift: an upper bound of the VP noise.
void SetDirectionSigma(const Trajectory& keyframes, const PinholeCamera& camera,
                       const DirectionTerm& term, const GlobalMappingOptions& options,
                       GlobalMappingResult* result) {
  if (options.direction_sigma_px > 0) {
    result->direction_sigma_px = options.direction_sigma_px;
    return;
  }
  // The VPs of neighbouring keyframes share their edges: the AR(1) effective-sample-size
  // inflation sqrt((1 + rho) / (1 - rho)) of the lag-1 correlation within the clusters.
  result->direction_rho =
      direction::DirectionErrorCorrelation(keyframes, camera, term.priors, term.clusters);
  const double inflation = std::sqrt((1.0 + result->direction_rho) / (1.0 - result->direction_rho));
  const auto at_least_min = [&](double sigma) {
    return (std::isfinite(sigma) ? std::max(options.min_direction_sigma_px, sigma) : 1.0) *
           inflation;
  };
  result->direction_sigma_estimated = true;
  if (options.direction_sigma_per_axis) {
    constexpr double kMadToSigma = 1.0 / 0.6744897501960817;  // 1D Gaussian
    const Eigen::Vector2d mad = direction::MedianAbsDirectionError(keyframes, camera, term.priors);
    result->direction_sigma_px = at_least_min(mad.x() * kMadToSigma);
    result->direction_sigma_v_px = at_least_min(mad.y() * kMadToSigma);
    spdlog::info("e_D sigma estimated: u {:.3f} px, v {:.3f} px (lag-1 correlation {:.2f})",
                 result->direction_sigma_px, result->direction_sigma_v_px, result->direction_rho);
    return;
  }
  const double sigma =
      direction::MedianDirectionError(keyframes, camera, term.priors) / std::sqrt(2.0 * M_LN2);
  result->direction_sigma_px = at_least_min(sigma);
  spdlog::info("e_D sigma estimated: {:.3f} px (lag-1 correlation {:.2f})",
               result->direction_sigma_px, result->direction_rho);
}

// e_D (Eq. 6) of this round: left out before GlobalMappingOptions::first_direction_round.
void SetDirectionTerm(int round, const FixedTerms& terms, const PinholeCamera& camera,
                      const GlobalMappingOptions& options, DirectionTerm* term,
                      optim::JointProblemOptions* joint, optim::JointProblemInput* problem,
                      GlobalMappingResult* result) {
  problem->directions.clear();
  problem->free_directions.clear();
  if (!options.use_directions || round < std::min(options.first_direction_round, terms.rounds - 1))
    return;
  if (!term->entered) {
    EnterDirections(result->keyframes, camera, terms.directions, options, term, result);
    SetDirectionSigma(result->keyframes, camera, *term, options, result);
    joint->direction_sigma_px = result->direction_sigma_px;
    joint->direction_sigma_v_px = result->direction_sigma_v_px;
    EnterVertical(terms.vp_rays, options, term, joint, result);
  }
  problem->directions = term->constraints;
  problem->free_directions = term->free_directions;
}

// e_S of this round (GlobalMappingOptions::use_surface): every observation's map point, at
// the current point and pose, projected onto the IMLS surface of its keyframe's own scan (the
// traversal's association options: kernel, radius, largest distance). One model per keyframe,
// keyframes in parallel, joined in keyframe order (the same for any thread count).
std::vector<optim::PointSurfaceConstraint> SurfaceConstraints(
    const Trajectory& keyframes, const std::vector<lidar::StoredScan>& scans,
    const std::vector<optim::VisualObservation>& observations,
    const std::vector<Eigen::Vector3d>& map_points, const lidar::AssociationOptions& association,
    int threads) {
  const size_t k = keyframes.size();
  JVL_CHECK(scans.size() == k,
            "surface term: " << scans.size() << " scans for " << k << " keyframes");
  std::vector<std::vector<size_t>> by_keyframe(k);
  for (size_t o = 0; o < observations.size(); ++o)
    by_keyframe[static_cast<size_t>(observations[o].keyframe)].push_back(o);
  std::vector<std::vector<optim::PointSurfaceConstraint>> parts(k);
  ParallelFor(static_cast<int64_t>(k), ResolveThreadCount(threads), [&](int64_t row) {
    const size_t n = static_cast<size_t>(row);
    if (by_keyframe[n].empty() || scans[n].size() == 0) return;
    lidar::ImlsModel model(association.search_radius);
    lidar::AddScanToModel(scans[n].points, scans[n].normals, Rigid3d(), row, &model);
    const Rigid3d cam_from_world = keyframes.world_from_cam[n].Inverse();
    for (const size_t o : by_keyframe[n]) {
      const int32_t point = observations[o].map_point;
      lidar::ImlsProjection proj;
      if (!lidar::ProjectPoint(model, cam_from_world * map_points[static_cast<size_t>(point)],
                               association, &proj))
        continue;
      optim::PointSurfaceConstraint c;
      c.keyframe = row;
      c.map_point = point;
      c.k_p_y = proj.projection;
      c.k_normal = proj.normal.normalized();
      parts[n].push_back(c);
    }
  });
  std::vector<optim::PointSurfaceConstraint> out;
  for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

// e_S of this round (GlobalMappingOptions::use_surface), at the round's poses and map points;
// before SetImlsTerm, which releases the scans after the last round's traversal.
void SetSurfaceTerm(int round, const GlobalMapInput& input, const GlobalMappingOptions& options,
                    optim::JointProblemInput* problem, GlobalMappingResult* result) {
  problem->point_surfaces.clear();
  if (!options.use_surface) return;
  if (input.scans.empty()) {
    if (round == 0) spdlog::info("surface term left out: the local map holds no scans");
    return;
  }
  lidar::AssociationOptions association = options.traversal.association;
  association.max_distance = options.surface_max_distance_m;
  problem->point_surfaces =
      SurfaceConstraints(result->keyframes, input.scans, input.observations, problem->map_points,
                         association, options.solve.threads);
  result->surface_constraints = static_cast<int64_t>(problem->point_surfaces.size());
  spdlog::info("surface term: {} map point observations on their keyframe's scan",
               problem->point_surfaces.size());
}

// e_L (Eq. 3-4) of this round: the saved set L and, with a fresh traversal, Eq. (3) against the
// current poses (the paper's single traversal in round 0). The scans are released after the
// last traversal (on a long sequence they are a large part of the memory).
void SetImlsTerm(int round, const FixedTerms& terms, const GlobalMappingOptions& options,
                 GlobalMapInput* input, optim::JointProblemInput* problem,
                 GlobalMappingResult* result) {
  problem->imls.clear();
  problem->imls_pairs.clear();
  if (options.use_saved_imls) {
    if (terms.summed_saved) {
      problem->imls_pairs = terms.saved_pairs;
    } else {
      problem->imls = input->saved_imls;
    }
    result->saved_imls = terms.saved_count;
  }
  if (!terms.fresh) return;
  const Timer t;
  const auto l =
      TraverseImls(result->keyframes, input->scans, options.traversal, options.solve.threads);
  if (terms.aggregate) {  // kept summed as well (the raw list is not needed for the solve)
    const auto fresh_pairs = optim::AggregateImls(l);
    problem->imls_pairs.insert(problem->imls_pairs.end(), fresh_pairs.begin(), fresh_pairs.end());
  } else {
    problem->imls.insert(problem->imls.end(), l.begin(), l.end());
  }
  result->fresh_imls = static_cast<int64_t>(l.size());
  if (options.use_loops && !input->loops.empty()) {
    const auto loop_l =
        TraverseLoops(result->keyframes, input->scans, input->loops, options.traversal);
    if (terms.aggregate) {
      const auto loop_pairs = optim::AggregateImls(loop_l);
      problem->imls_pairs.insert(problem->imls_pairs.end(), loop_pairs.begin(), loop_pairs.end());
    } else {
      problem->imls.insert(problem->imls.end(), loop_l.begin(), loop_l.end());
    }
    result->loop_imls = static_cast<int64_t>(loop_l.size());
  }
  result->traversal_time_s += t.ElapsedSeconds();
  spdlog::debug("round {}: fresh IMLS traversal {:.1f} s ({} correspondences)", round + 1,
                t.ElapsedSeconds(), l.size());
  if (round == terms.rounds - 1) std::vector<lidar::StoredScan>().swap(input->scans);
}

// The report's "before" is the full energy at the input poses. When round 0 warm-starts without
// e_D, e_D's part is evaluated on its own with the weights the full problem would have (no
// second copy of the large terms).
std::optional<optim::ResidualStats> DirectionCostBefore(int round, const FixedTerms& terms,
                                                        const optim::JointProblemInput& problem,
                                                        const optim::JointProblemOptions& joint,
                                                        const GlobalMappingOptions& options) {
  if (round != 0 || !options.use_directions || !problem.directions.empty() ||
      terms.directions.priors.empty())
    return std::nullopt;
  optim::JointProblemInput only;
  only.camera = problem.camera;
  only.camera_offset = problem.camera_offset;
  only.poses = problem.poses;
  only.fixed = problem.fixed;
  only.directions = ToDirectionConstraints(terms.directions.priors);
  const optim::JointWeights w = optim::ResolveWeights(
      joint, static_cast<int64_t>(problem.Observations().size()), optim::CountImls(problem),
      static_cast<int64_t>(only.directions.size()));
  optim::JointProblemOptions o = joint;
  o.alpha = w.alpha;
  o.beta = w.beta;
  o.gamma = w.gamma;
  auto built = optim::BuildJointProblem(only, o);
  return optim::EvaluateJointCost(built).direction;
}

// The first round after which the rounds may stop on GlobalMappingOptions::round_tolerance_m:
// e_O enters in round 1 and e_D in first_direction_round, and both are in the last round.
int MinStopRound(const GlobalMappingOptions& options) {
  return std::max(1, options.first_direction_round);
}

// One Levenberg-Marquardt solve of the round's problem; only round 0's costs before and the
// costs after of each round that may be the last are evaluated (they are what the report gives).
optim::JointSolveResult SolveRound(int round, int rounds, const GlobalMappingOptions& options,
                                   const optim::JointProblemInput& problem,
                                   const optim::JointProblemOptions& joint) {
  optim::SolveOptions solve = options.solve;
  if (!solve.progress_label.empty())
    solve.progress_label += " round " + std::to_string(round + 1) + "/" + std::to_string(rounds);
  solve.evaluate_before = round == 0;
  solve.evaluate_after =
      round == rounds - 1 || (options.round_tolerance_m > 0 && round >= MinStopRound(options));
  return optim::OptimizeJoint(problem, joint, solve);
}

// Largest change (m) of a keyframe-to-keyframe motion between two solutions of the same
// keyframes: |t(M_old^-1 M_new)| over the consecutive pairs, M = T_i^-1 T_i+1. It is what a
// further round of re-association could still move (GlobalMappingOptions::round_tolerance_m).
struct MotionChange {
  double largest_m = 0;
  size_t at = 0;  // the pair's first keyframe
};
MotionChange LargestMotionChange(const std::vector<Rigid3d>& old_poses,
                                 const std::map<int64_t, Rigid3d>& new_poses) {
  MotionChange out;
  for (size_t i = 0; i + 1 < old_poses.size(); ++i) {
    const Rigid3d old_motion = old_poses[i].Inverse() * old_poses[i + 1];
    const Rigid3d new_motion =
        new_poses.at(static_cast<int64_t>(i)).Inverse() * new_poses.at(static_cast<int64_t>(i + 1));
    const double change = (old_motion.Inverse() * new_motion).translation().norm();
    if (change > out.largest_m) out = {change, i};
  }
  return out;
}

// The round's solution is the next round's start.
void AcceptRound(DirectionTerm* direction, optim::JointProblemInput* problem,
                 GlobalMappingResult* result) {
  const MotionChange change =
      LargestMotionChange(result->keyframes.world_from_cam, result->solve.poses);
  result->round_motion_change_m.push_back(change.largest_m);
  spdlog::info("round {}: keyframe-to-keyframe motions changed by up to {:.2f} mm (frames {}-{})",
               result->rounds, 1e3 * change.largest_m, result->keyframes.frames[change.at],
               result->keyframes.frames[std::min(change.at + 1, result->keyframes.size() - 1)]);
  for (size_t i = 0; i < result->keyframes.size(); ++i)
    result->keyframes.world_from_cam[i] = result->solve.poses.at(static_cast<int64_t>(i));
  problem->map_points = result->solve.map_points;
  if (!direction->free_directions.empty()) {
    direction->free_directions = result->solve.free_directions;
    result->free_directions = direction->free_directions;
    if (direction->vertical_block >= 0) {
      result->vertical_direction =
          direction->free_directions[static_cast<size_t>(direction->vertical_block)];
      result->free_directions.pop_back();  // the vertical block is the last one
    }
  }
}

}  // namespace

GlobalMappingResult OptimizeGlobal(GlobalMapInput input, const GlobalMappingOptions& options) {
  const Timer total;
  options.Check();
  input.Check();
  GlobalMappingResult result;
  if (options.use_loops && !input.loops.empty()) {
    result.loop_correction_m = ApplyLoopCorrections(&input);
    result.loops_used = static_cast<int64_t>(input.loops.size());
    spdlog::info("loops: {} applied before the optimisation (keyframes moved by up to {:.3f} m)",
                 input.loops.size(), result.loop_correction_m);
  }
  result.keyframes = input.keyframes;
  SelectVisualTerm(options, &input, &result);
  const size_t first_loop_point = input.map_points.size();
  if (options.use_loops && options.use_loop_points && !input.loops.empty()) {
    result.loop_visual = AddLoopPoints(&input);
    if (result.loop_visual > 0)
      spdlog::info("loops: {} visual observations of {} loop points", result.loop_visual,
                   result.loop_visual / 2);
  }
  const FixedTerms terms = PrepareFixedTerms(&input, options, &result);
  optim::JointProblemInput problem;
  problem.camera = input.camera;
  problem.camera_offset = input.camera_choice.offset;
  problem.fixed = {0};  // gauge: the first keyframe
  problem.map_points = input.map_points;
  problem.shared_observations = &input.observations;
  problem.drop_weak_from = first_loop_point;  // Loop points are dropped, not held, when weak.
  optim::JointProblemOptions joint = options.joint;  // direction sigma set once e_D enters
  DirectionTerm direction;
  OdometryTerm odometry;
  problem.motion = MotionConstraints(result.keyframes, options);
  result.motion_triples = static_cast<int64_t>(problem.motion.size());
  if (options.use_odometry && !input.odometry.empty() && terms.rounds < 2)
    spdlog::info("odometry term left out: it needs a second round (a fresh traversal)");
  optim::JointCostBreakdown before;  // Eq. (7) at the input poses
  for (int round = 0; round < terms.rounds; ++round) {
    for (size_t i = 0; i < result.keyframes.size(); ++i)
      problem.poses[static_cast<int64_t>(i)] = result.keyframes.world_from_cam[i];
    SetDirectionTerm(round, terms, input.camera, options, &direction, &joint, &problem, &result);
    SetSurfaceTerm(round, input, options, &problem, &result);
    SetImlsTerm(round, terms, options, &input, &problem, &result);
    SetOdometryTerm(round, input, options, &odometry, &problem, &result);
    const auto direction_before = DirectionCostBefore(round, terms, problem, joint, options);
    result.solve = SolveRound(round, terms.rounds, options, problem, joint);
    if (joint.imls_pair_noise_max > 1.0 && result.solve.imls_blocks > 0)
      spdlog::info(
          "round {}: e_L noise per keyframe pair: median RMS residual {:.1f} mm, {} of {} pairs "
          "with a larger sigma (up to {:g}x)",
          round + 1, 1e3 * result.solve.imls_pair_median_rms_m, result.solve.imls_pairs_inflated,
          result.solve.imls_blocks, joint.imls_pair_noise_max);
    ReleaseFreeHeapMemory();  // the round's Ceres problem is gone (core/memory.h)
    ++result.rounds;
    result.total_iterations += result.solve.iterations;
    if (round == 0) {
      before = result.solve.before;
      if (direction_before) {
        before.direction = *direction_before;
        before.total += direction_before->cost;
      }
    }
    if (!result.solve.usable) {
      spdlog::warn(
          "global optimisation round {} failed ({}); keyframes keep the poses of the "
          "previous round",
          round, result.solve.termination);
      break;
    }
    AcceptRound(&direction, &problem, &result);
    const double change = result.round_motion_change_m.back();
    if (round + 1 < terms.rounds && round >= MinStopRound(options) &&
        change < options.round_tolerance_m) {
      spdlog::info("rounds: converged after {} (largest motion change {:.2f} mm < {:.2f} mm)",
                   round + 1, 1e3 * change, 1e3 * options.round_tolerance_m);
      break;
    }
  }
  result.solve.before = before;  // report the costs at the input poses
  result.odometry_outliers =
      CountOdometryOutliers(odometry, result.keyframes, options.joint.relative_cauchy);
  if (!odometry.constraints.empty())
    spdlog::info("odometry term: {} of {} keyframe pairs above the kernel scale (down-weighted)",
                 result.odometry_outliers, odometry.constraints.size());
  result.motion_outliers =
      CountMotionOutliers(problem.motion, result.keyframes, options.joint.motion_cauchy);
  if (!problem.motion.empty())
    spdlog::info("motion term: {} of {} keyframe triples above the kernel scale (down-weighted)",
                 result.motion_outliers, problem.motion.size());
  result.total_time_s = total.ElapsedSeconds();
  return result;
}

namespace {

nlohmann::json StatsOf(const optim::ResidualStats& s) {
  return {{"count", s.count}, {"cost", s.cost}, {"rms", s.rms}};
}

nlohmann::json ChangeJson(const std::map<int32_t, double>& change) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [cluster, deg] : change) j[std::to_string(cluster)] = deg;
  return j;
}

nlohmann::json VectorJson(const Eigen::Vector3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

nlohmann::json FreeJson(const GlobalMappingResult& r) {
  nlohmann::json j = nlohmann::json::object();
  for (size_t i = 0; i < r.free_directions.size() && i < r.free_direction_clusters.size(); ++i) {
    j[std::to_string(r.free_direction_clusters[i])] = VectorJson(r.free_directions[i]);
  }
  return j;
}

nlohmann::json BreakdownOf(const optim::JointCostBreakdown& b) {
  return {{"visual", StatsOf(b.visual)},
          {"imls", StatsOf(b.imls)},
          {"direction", StatsOf(b.direction)},
          {"odometry", StatsOf(b.relative)},
          {"motion", StatsOf(b.motion)},
          {"surface", StatsOf(b.surface)},
          {"total", b.total}};
}

}  // namespace

nlohmann::json GlobalStatsJson(const GlobalMappingResult& r, const GlobalMappingOptions& o) {
  const auto& s = r.solve;
  nlohmann::json j = {
      {"before", BreakdownOf(s.before)},
      {"after", BreakdownOf(s.after)},
      {"weights",
       {{"alpha", s.weights.alpha}, {"beta", s.weights.beta}, {"gamma", s.weights.gamma}}},
      {"weights_from_rule", {{"beta", o.joint.beta <= 0}, {"gamma", o.joint.gamma <= 0}}},
      {"imls",
       {{"saved", r.saved_imls},
        {"fresh", r.fresh_imls},
        {"blocks", s.imls_blocks},
        {"pair_noise_max", o.joint.imls_pair_noise_max},
        {"pair_median_rms_m", s.imls_pair_median_rms_m},
        {"pairs_inflated", s.imls_pairs_inflated}}},
      {"visual",
       {{"gate_chi2", o.joint.visual_gate_chi2},
        {"behind_camera", s.dropped_observations},
        {"gated_observations", s.gated_observations},
        {"gated_points", s.gated_points},
        {"max_point_sigma_ratio", o.joint.max_point_sigma_ratio},
        {"weak_points_held", s.weak_points},
        {"drop_weak_points", o.joint.drop_weak_points},
        {"points_per_keyframe", o.points_per_keyframe},
        {"input_points", r.input_points},
        {"selected_points", r.selected_points},
        {"input_observations", r.input_observations},
        {"selected_observations", r.selected_observations}}},
      {"directions",
       {{"used", r.directions_used},
        {"not_keyframe", r.directions_not_keyframe},
        {"at_infinity", r.directions_at_infinity},
        {"enabled", o.use_directions},
        {"source", ToString(o.direction_source)},
        {"refit_outlier_deg", o.refit_outlier_deg},
        {"sigma_px", r.direction_sigma_px},
        {"sigma_v_px", r.direction_sigma_v_px > 0 ? r.direction_sigma_v_px : r.direction_sigma_px},
        {"sigma_estimated", r.direction_sigma_estimated},
        {"rho", r.direction_rho},
        {"outliers", r.directions_outliers},
        {"small_cluster", r.directions_small_cluster},
        {"change_deg", ChangeJson(r.direction_change_deg)},
        {"free", FreeJson(r)}}},
      {"vertical",
       {{"enabled", o.use_directions && o.use_vertical},
        {"candidates", r.vertical_candidates},
        {"used", r.vertical_used},
        {"outliers", r.vertical_outliers},
        {"sigma_deg", r.vertical_sigma_deg},
        {"rho", r.vertical_rho},
        {"disagreement_deg", r.vertical_disagreement_deg},
        {"white_deg", r.vertical_white_deg},
        {"bias_deg", r.vertical_bias_deg},
        {"half_window", o.vertical_half_window},
        {"sigma_rule", r.vertical_sigma_rule},
        {"direction",
         r.vertical_used > 0 ? VectorJson(r.vertical_direction) : nlohmann::json(nullptr)}}},
      {"odometry",
       {{"enabled", o.use_odometry},
        {"pairs", r.odometry_pairs},
        {"gate", o.odometry_gate},
        {"gated", r.odometry_gated},
        {"outliers", r.odometry_outliers},
        {"sigma_m", VectorJson(r.odometry_sigma_m)},
        {"sigma_deg", VectorJson(r.odometry_sigma_deg)},
        {"conditioning",
         {{"used", r.odometry_conditioned},
          {"max_inflation", o.odometry_max_inflation},
          {"inflated", r.odometry_inflated}}},
        {"local",
         {{"window", o.odometry_local_window},
          {"max", o.odometry_local_max},
          {"median_norm", r.odometry_median_norm},
          {"inflated", r.odometry_local_inflated}}},
        {"cauchy", o.joint.relative_cauchy}}},
      {"surface",
       {{"enabled", o.use_surface},
        {"constraints", r.surface_constraints},
        {"sigma_m", o.joint.surface_sigma_m},
        {"max_distance_m", o.surface_max_distance_m},
        {"cauchy", o.joint.surface_cauchy}}},
      {"motion",
       {{"enabled", o.use_motion},
        {"triples", r.motion_triples},
        {"outliers", r.motion_outliers},
        {"sigma_m", VectorJson(o.motion_sigma_m)},
        {"cauchy", o.joint.motion_cauchy}}},
      {"solver",
       {{"usable", s.usable},
        {"iterations", r.total_iterations},
        {"rounds", r.rounds},
        {"max_rounds", o.rounds},
        {"round_tolerance_m", o.round_tolerance_m},
        {"round_motion_change_m", r.round_motion_change_m},
        {"last_round_iterations", s.iterations},
        {"time_s", s.time_s},
        {"termination", s.termination},
        {"linear_solver", s.linear_solver},
        {"threads", o.solve.threads},
        {"max_iterations", o.solve.max_iterations}}},
      {"traversal_time_s", r.traversal_time_s},
      {"total_time_s", r.total_time_s}};
  if (r.loops_used > 0) {
    j["loops"] = {{"used", r.loops_used},
                  {"imls", r.loop_imls},
                  {"visual", r.loop_visual},
                  {"correction_m", r.loop_correction_m}};
  }
  return j;
}

std::vector<Eigen::Vector3f> AccumulateMap(const Trajectory& keyframes,
                                           const std::vector<lidar::StoredScan>& scans,
                                           double voxel_size) {
  JVL_CHECK(scans.size() == keyframes.size(),
            "AccumulateMap: " << scans.size() << " scans for " << keyframes.size() << " keyframes");
  std::vector<Eigen::Vector3f> out;
  std::unordered_set<uint64_t, lidar::CellHash> occupied;
  const double inv = voxel_size > 0 ? 1.0 / voxel_size : 0.0;
  for (size_t k = 0; k < scans.size(); ++k) {
    for (const Eigen::Vector3f& p : scans[k].points) {
      const Eigen::Vector3d w = keyframes.world_from_cam[k] * p.cast<double>();
      if (voxel_size > 0) {
        const Eigen::Vector3i c = lidar::CellOf(w, inv);
        if (!occupied.insert(lidar::PackCell(c.x(), c.y(), c.z())).second) continue;
      }
      out.push_back(w.cast<float>());
    }
  }
  return out;
}

}  // namespace jvl::mapping
