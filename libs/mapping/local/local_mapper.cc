// RunLocalMapping: the per-keyframe loop of Sec. 4.2 (see local_mapping.h).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "core/check.h"
#include "core/timer.h"
#include "mapping/local/local_mapping.h"

namespace jvl::mapping {
namespace {

class LocalMapper {
 public:
  LocalMapper(const LocalMappingInput& input, const LocalMappingOptions& options, int threads)
      : in_(input), options_(options) {
    options_.solve.threads = std::max(1, threads);
    // The keyframe statistics need only the total cost, which Ceres reports.
    options_.solve.evaluate_before = false;
    options_.solve.evaluate_after = false;
    adjacency_ = CovisibilityAdjacency(in_.size(), in_.covisibility);
    observations_of_.resize(in_.size());
    first_observer_.assign(in_.map_points.size(), in_.size());
    for (size_t o = 0; o < in_.observations.size(); ++o) {
      const auto& obs = in_.observations[o];
      observations_of_[static_cast<size_t>(obs.keyframe)].push_back(o);
      size_t& first = first_observer_[static_cast<size_t>(obs.map_point)];
      first = std::min(first, static_cast<size_t>(obs.keyframe));
    }
    result_.poses = in_.prior;
    result_.map_points = in_.map_points;
    result_.scans.resize(in_.size());
    point_placed_.assign(in_.map_points.size(), 0);
    saved_range_.assign(in_.size(), {0, 0});
  }

  // `get_scan` returns keyframe n's prepared scan (loaded now or taken from a prefetch).
  KeyframeStats Process(size_t n, const std::function<KeyframeScan()>& get_scan);
  LocalMappingResult Take() {
    // Points no optimisation touched still follow the correction of their first observer.
    for (size_t m = 0; m < point_placed_.size(); ++m) {
      if (first_observer_[m] < in_.size()) PlacePoint(m);
    }
    return std::move(result_);
  }

 private:
  struct Problem {
    optim::JointProblemInput input;
    std::vector<int32_t> point_rows;  // Problem map point -> input row.
    int reused = 0;
  };
  void PlacePoint(size_t m);
  Problem BuildProblem(const std::vector<int64_t>& local,
                       const std::vector<optim::ImlsCorrespondence>& fresh);
  std::vector<optim::ImlsCorrespondence> Associate(size_t n, size_t start) const;
  bool Solve(Problem& p, KeyframeStats* stats, bool first_round);

  const LocalMappingInput& in_;
  LocalMappingOptions options_;
  std::vector<std::vector<int>> adjacency_;
  std::vector<std::vector<size_t>> observations_of_;  // Keyframe row -> observation indices.
  std::vector<size_t> first_observer_;                // Map point -> first observing keyframe.
  std::vector<uint8_t> point_placed_;
  std::map<size_t, KeyframeScan> scans_;  // Rows that may still enter S_model.
  // Keyframe row -> [begin, end) of its own correspondences in result_.correspondences (L).
  std::vector<std::pair<size_t, size_t>> saved_range_;
  LocalMappingResult result_;
};

// The visual map was triangulated with map_poses; a point joins the refined map with the
// correction of its first observing keyframe, so the map follows the refined trajectory.
void LocalMapper::PlacePoint(size_t m) {
  if (point_placed_[m]) return;
  const size_t k = first_observer_[m];
  const Rigid3d correction = result_.poses[k] * in_.map_poses[k].Inverse();
  result_.map_points[m] = correction * result_.map_points[m];
  point_placed_[m] = 1;
}

std::vector<optim::ImlsCorrespondence> LocalMapper::Associate(size_t n, size_t start) const {
  std::vector<const KeyframeScan*> scans;
  std::vector<int64_t> rows;
  for (size_t r = start; r < n; ++r) {
    scans.push_back(&scans_.at(r));
    rows.push_back(static_cast<int64_t>(r));
  }
  const lidar::ImlsModel model =
      BuildScanModel(scans, rows, result_.poses, options_.association.search_radius);
  return AssociateScan(static_cast<int64_t>(n), scans_.at(n), result_.poses[n], model,
                       result_.poses, options_.association);
}

LocalMapper::Problem LocalMapper::BuildProblem(
    const std::vector<int64_t>& local, const std::vector<optim::ImlsCorrespondence>& fresh) {
  Problem p;
  optim::JointProblemInput& in = p.input;
  in.camera = in_.camera;
  in.camera_offset = in_.camera_choice.offset;
  const std::set<int64_t> local_set(local.begin(), local.end());
  for (const int64_t r : local) in.poses[r] = result_.poses[static_cast<size_t>(r)];
  // Step 4: the new correspondences join K_n with K_c (fixed when K_c is not local) ...
  for (const auto& l : fresh) {
    in.poses[l.c] = result_.poses[static_cast<size_t>(l.c)];
    in.imls.push_back(l);
  }
  // ... and the saved ones within K_local are reused (supplement Eq. 1).
  for (const size_t i : ReusableCorrespondences(result_.correspondences, saved_range_, local_set)) {
    in.imls.push_back(result_.correspondences[i]);
    ++p.reused;
  }
  // Step 1: every observation of a K_local keyframe, points seen often enough among them.
  std::map<int32_t, int> count;
  for (const int64_t r : local) {
    for (const size_t o : observations_of_[static_cast<size_t>(r)]) {
      ++count[in_.observations[o].map_point];
    }
  }
  std::map<int32_t, int32_t> slot;
  for (const auto& [m, c] : count) {
    if (c < options_.min_point_observations) continue;
    PlacePoint(static_cast<size_t>(m));
    slot[m] = static_cast<int32_t>(p.point_rows.size());
    p.point_rows.push_back(m);
    in.map_points.push_back(result_.map_points[static_cast<size_t>(m)]);
  }
  for (const int64_t r : local) {
    for (const size_t o : observations_of_[static_cast<size_t>(r)]) {
      optim::VisualObservation obs = in_.observations[o];
      const auto it = slot.find(obs.map_point);
      if (it == slot.end()) continue;
      obs.map_point = it->second;
      in.observations.push_back(obs);
    }
  }
  std::set<int64_t> ids;
  for (const auto& [id, pose] : in.poses) ids.insert(id);
  in.fixed = FixedKeyframes(local, ids);
  return p;
}

bool LocalMapper::Solve(Problem& p, KeyframeStats* stats, bool first_round) {
  const optim::JointProblemInput& in = p.input;
  const bool any_free = in.fixed.size() < in.poses.size();
  if (!any_free || (in.observations.empty() && in.imls.empty())) return false;
  const optim::JointSolveResult r = optim::OptimizeJoint(in, options_.joint, options_.solve);
  if (first_round) stats->cost_before = r.before.total;
  stats->cost_after = r.usable ? r.after.total : r.before.total;
  stats->visual_residuals = static_cast<int>(r.after.visual.count);
  stats->imls_residuals = static_cast<int>(r.after.imls.count);
  stats->beta = r.weights.beta;
  stats->iterations += r.iterations;
  if (!r.usable) {
    spdlog::warn("keyframe {}: solver failed ({}); poses kept", stats->frame, r.termination);
    return false;
  }
  for (const auto& [id, pose] : r.poses) {
    if (!in.fixed.count(id)) result_.poses[static_cast<size_t>(id)] = pose;
  }
  for (size_t i = 0; i < p.point_rows.size(); ++i) {
    result_.map_points[static_cast<size_t>(p.point_rows[i])] = r.map_points[i];
  }
  return true;
}

KeyframeStats LocalMapper::Process(size_t n, const std::function<KeyframeScan()>& get_scan) {
  const Timer timer;
  KeyframeStats stats;
  stats.frame = in_.frames[n];
  if (n > 0 && options_.propagate_corrections) {
    // Keep the prior motion from the (refined) previous keyframe.
    result_.poses[n] = result_.poses[n - 1] * (in_.prior[n - 1].Inverse() * in_.prior[n]);
  }
  const Rigid3d initial = result_.poses[n];
  scans_[n] = get_scan();
  result_.scans[n] = scans_[n].stored;
  stats.scan_ms = timer.ElapsedMs();

  const std::vector<int64_t> local = LocalKeyframes(n, adjacency_);
  const size_t start =
      StartKeyframe(in_.frames, n, options_.scan_map_size, options_.min_model_keyframes);
  stats.local_keyframes = static_cast<int>(local.size());
  stats.model_keyframes = static_cast<int>(n - start);
  std::vector<optim::ImlsCorrespondence> fresh;
  for (int round = 0; round < options_.association_rounds; ++round) {
    const Timer associate;
    fresh = Associate(n, start);
    stats.associate_ms += associate.ElapsedMs();
    Problem p = BuildProblem(local, fresh);
    stats.new_correspondences = static_cast<int>(fresh.size());
    stats.reused_correspondences = p.reused;
    stats.map_points = static_cast<int>(p.point_rows.size());
    stats.fixed_keyframes = static_cast<int>(p.input.fixed.size());
    const bool solved = Solve(p, &stats, round == 0);
    stats.optimized = stats.optimized || solved;
    if (!solved) break;
  }
  // Step 4: save K_n's correspondences in L for later keyframes.
  const size_t begin = result_.correspondences.size();
  for (const auto& l : fresh) {
    JVL_CHECK(l.n == static_cast<int64_t>(n),
              "correspondence of keyframe " << l.n << " saved as " << n << "'s");
  }
  result_.correspondences.insert(result_.correspondences.end(), fresh.begin(), fresh.end());
  saved_range_[n] = {begin, result_.correspondences.size()};
  // Later keyframes start their S_model at or after `start`.
  while (!scans_.empty() && scans_.begin()->first < start) scans_.erase(scans_.begin());
  stats.correction_m = (result_.poses[n].translation() - initial.translation()).norm();
  stats.time_ms = timer.ElapsedMs();
  stats.solve_ms = stats.time_ms - stats.scan_ms;
  return stats;
}

}  // namespace

LocalMappingResult RunLocalMapping(const LocalMappingInput& input, const ScanLoader& load_scan,
                                   const LocalMappingOptions& options, int threads,
                                   const KeyframeCallback& on_keyframe) {
  input.Check();
  options.Check();
  LocalMapper mapper(input, options, threads);
  std::vector<KeyframeStats> stats;
  // With two or more threads, keyframe n+1's scan is read and prepared while keyframe n is
  // associated and solved (Ceres runs on one thread). The preparation depends only on the
  // dataset and the prior, so the result is the same as without the prefetch; the loader is
  // never called by two threads at once.
  const bool prefetch = threads >= 2;
  std::future<KeyframeScan> pending;
  const auto launch = [&](size_t row) {
    pending = std::async(std::launch::async, [&load_scan, row] { return load_scan(row); });
  };
  if (prefetch && input.size() > 0) launch(0);
  for (size_t n = 0; n < input.size(); ++n) {
    const auto get_scan = [&]() -> KeyframeScan {
      if (!prefetch) return load_scan(n);
      KeyframeScan scan = pending.get();
      if (n + 1 < input.size()) launch(n + 1);
      return scan;
    };
    stats.push_back(mapper.Process(n, get_scan));
    if (on_keyframe) on_keyframe(n, stats.back());
  }
  LocalMappingResult result = mapper.Take();
  result.stats = std::move(stats);
  return result;
}

}  // namespace jvl::mapping
