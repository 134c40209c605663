#include "mapping/local/local_mapping.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>

#include "core/check.h"
#include "core/timer.h"

namespace jvl::mapping {

void LocalMappingInput::Check() const {
  const size_t k = frames.size();
  JVL_CHECK(map_poses.size() == k && prior.size() == k,
            "local mapping input: " << k << " keyframes but " << map_poses.size()
                                    << " map poses and " << prior.size() << " prior poses");
  for (size_t i = 1; i < k; ++i) {
    JVL_CHECK(frames[i] > frames[i - 1], "keyframe frames must increase (row " << i << ")");
  }
  for (const optim::VisualObservation& o : observations) {
    JVL_CHECK(o.keyframe >= 0 && static_cast<size_t>(o.keyframe) < k && o.map_point >= 0 &&
                  static_cast<size_t>(o.map_point) < map_points.size(),
              "observation of keyframe " << o.keyframe << ", map point " << o.map_point
                                         << " out of range");
  }
  for (const auto& e : covisibility) {
    JVL_CHECK(e[0] >= 0 && e[1] >= 0 && static_cast<size_t>(std::max(e[0], e[1])) < k,
              "covisibility edge (" << e[0] << ", " << e[1] << ") out of range");
  }
}

void LocalMappingOptions::Check() const {
  JVL_CHECK(scan_map_size >= 1, "scan_map_size must be >= 1, got " << scan_map_size);
  JVL_CHECK(min_model_keyframes >= 0,
            "min_model_keyframes must be >= 0, got " << min_model_keyframes);
  JVL_CHECK(association_rounds >= 1, "association_rounds must be >= 1, got " << association_rounds);
  JVL_CHECK(min_point_observations >= 1,
            "min_point_observations must be >= 1, got " << min_point_observations);
  association.Check();
  joint.Check();
  solve.Check();
}

size_t StartKeyframe(const std::vector<int64_t>& frames, size_t n, int scan_map_size,
                     int min_model_keyframes) {
  JVL_CHECK(n < frames.size(), "keyframe row " << n << " out of range");
  size_t start = n;
  // The first keyframe with f_n - f_i <= N (Sec. 4.2 step 2); frames increase, so scan back.
  while (start > 0 && frames[n] - frames[start - 1] <= scan_map_size) --start;
  const size_t min_k = static_cast<size_t>(min_model_keyframes);
  if (n - start < min_k) start = n >= min_k ? n - min_k : 0;
  return start;
}

std::vector<std::vector<int>> CovisibilityAdjacency(size_t num_keyframes,
                                                    const std::vector<std::array<int, 2>>& edges) {
  std::vector<std::vector<int>> adjacency(num_keyframes);
  for (const auto& e : edges) {
    if (e[0] == e[1]) continue;
    adjacency.at(static_cast<size_t>(e[0])).push_back(e[1]);
    adjacency.at(static_cast<size_t>(e[1])).push_back(e[0]);
  }
  for (auto& a : adjacency) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  return adjacency;
}

std::vector<int64_t> LocalKeyframes(size_t n, const std::vector<std::vector<int>>& adjacency) {
  std::vector<int64_t> local;
  // Keyframes after K_n have not arrived yet when K_n triggers local mapping.
  for (const int k : adjacency.at(n)) {
    if (static_cast<size_t>(k) < n) local.push_back(k);
  }
  local.push_back(static_cast<int64_t>(n));
  std::sort(local.begin(), local.end());  // Rows are in time order.
  return local;
}

std::vector<size_t> ReusableCorrespondences(const std::vector<optim::ImlsCorrespondence>& saved,
                                            const std::vector<std::pair<size_t, size_t>>& ranges,
                                            const std::set<int64_t>& local) {
  std::vector<size_t> out;
  for (const int64_t r : local) {
    if (r < 0 || static_cast<size_t>(r) >= ranges.size()) continue;
    const auto [begin, end] = ranges[static_cast<size_t>(r)];
    for (size_t i = begin; i < end; ++i) {
      if (saved[i].n == r && local.count(saved[i].c)) out.push_back(i);
    }
  }
  return out;
}

std::set<int64_t> FixedKeyframes(const std::vector<int64_t>& local,
                                 const std::set<int64_t>& problem_poses) {
  const std::set<int64_t> local_set(local.begin(), local.end());
  std::set<int64_t> fixed;
  for (const int64_t id : problem_poses) {
    if (id == 0 || !local_set.count(id)) fixed.insert(id);
  }
  if (fixed.empty() && !local.empty()) fixed.insert(local.front());
  return fixed;
}

}  // namespace jvl::mapping
