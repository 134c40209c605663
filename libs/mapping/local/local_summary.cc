// Results of local mapping as plain values: the refined keyframes and the run summary.
#include <utility>

#include "core/statistics.h"
#include "mapping/local/local_mapping.h"

namespace jvl::mapping {
namespace {

// Nearest-rank quantile of one field over the keyframes; 0 for none.
template <typename T, typename F>
double Quantile(const std::vector<T>& items, double q, F&& get) {
  std::vector<double> v;
  for (const T& item : items) v.push_back(static_cast<double>(get(item)));
  return v.empty() ? 0.0 : jvl::Quantile(std::move(v), q);
}

}  // namespace

Trajectory RefinedKeyframes(const LocalMappingInput& input, const LocalMappingResult& result) {
  Trajectory t;
  for (size_t k = 0; k < input.size(); ++k) t.Append(input.frames[k], result.poses[k]);
  return t;
}

nlohmann::json SummarizeLocalMap(const LocalMappingResult& result,
                                 const LocalMappingOptions& options) {
  const auto& s = result.stats;
  size_t scan_points = 0;
  for (const lidar::StoredScan& scan : result.scans) scan_points += scan.points.size();
  double total_ms = 0;
  for (const KeyframeStats& k : s) total_ms += k.time_ms;
  return {
      {"keyframes", s.size()},
      {"optimized_keyframes",
       std::count_if(s.begin(), s.end(), [](const KeyframeStats& k) { return k.optimized; })},
      {"correspondences", result.correspondences.size()},
      {"scan_points", scan_points},
      {"median_time_ms", Quantile(s, 0.5, [](const KeyframeStats& k) { return k.time_ms; })},
      {"p95_time_ms", Quantile(s, 0.95, [](const KeyframeStats& k) { return k.time_ms; })},
      {"median_scan_ms", Quantile(s, 0.5, [](const KeyframeStats& k) { return k.scan_ms; })},
      {"median_solve_ms", Quantile(s, 0.5, [](const KeyframeStats& k) { return k.solve_ms; })},
      {"median_associate_ms",
       Quantile(s, 0.5, [](const KeyframeStats& k) { return k.associate_ms; })},
      {"total_time_s", total_ms / 1000.0},
      {"median_iterations", Quantile(s, 0.5, [](const KeyframeStats& k) { return k.iterations; })},
      {"p95_iterations", Quantile(s, 0.95, [](const KeyframeStats& k) { return k.iterations; })},
      {"median_local_keyframes",
       Quantile(s, 0.5, [](const KeyframeStats& k) { return k.local_keyframes; })},
      {"median_visual_residuals",
       Quantile(s, 0.5, [](const KeyframeStats& k) { return k.visual_residuals; })},
      {"median_imls_residuals",
       Quantile(s, 0.5, [](const KeyframeStats& k) { return k.imls_residuals; })},
      {"median_correction_m",
       Quantile(s, 0.5, [](const KeyframeStats& k) { return k.correction_m; })},
      {"median_beta", Quantile(s, 0.5, [](const KeyframeStats& k) { return k.beta; })},
      {"scan_map_size", options.scan_map_size},
      {"alpha", options.joint.alpha},
      {"beta", options.joint.beta},
  };
}

}  // namespace jvl::mapping
