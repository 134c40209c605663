// Result export of local mapping: refined trajectory, summary and the "local" artifact layout.
#include <algorithm>

#include "mapping/local_mapping.h"

namespace jvl::mapping {
namespace {

template <typename T, typename F>
double Quantile(const std::vector<T>& items, double q, F&& get) {
  std::vector<double> v;
  for (const T& item : items) v.push_back(static_cast<double>(get(item)));
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

void AppendVector(const Eigen::Vector3d& v, std::vector<double>* out) {
  out->insert(out->end(), {v.x(), v.y(), v.z()});
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
      {"total_time_s", total_ms / 1000.0},
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

io::LocalMapData ExportLocalMap(const LocalMappingInput& input, const LocalMappingResult& result,
                                const Trajectory& prior, const nlohmann::json& summary) {
  io::LocalMapData d;
  d.camera = input.camera;
  d.keyframes = RefinedKeyframes(input, result);
  for (const optim::ImlsCorrespondence& l : result.correspondences) {
    d.imls_n.push_back(static_cast<int32_t>(l.n));
    d.imls_c.push_back(static_cast<int32_t>(l.c));
    AppendVector(l.p_x, &d.imls_p_x);
    AppendVector(l.c_p_y, &d.imls_p_y);
    AppendVector(l.c_normal, &d.imls_normal);
  }
  for (const Eigen::Vector3d& p : result.map_points) AppendVector(p, &d.mappoint_position);
  d.scan_offset.push_back(0);
  for (const lidar::StoredScan& scan : result.scans) {
    for (size_t i = 0; i < scan.points.size(); ++i) {
      const Eigen::Vector3f& p = scan.points[i];
      const Eigen::Vector3f& n = scan.normals[i];
      d.scan_points.insert(d.scan_points.end(), {p.x(), p.y(), p.z()});
      d.scan_normals.insert(d.scan_normals.end(), {n.x(), n.y(), n.z()});
    }
    d.scan_offset.push_back(d.scan_offset.back() + static_cast<int64_t>(scan.points.size()));
  }
  for (const KeyframeStats& k : result.stats) {
    d.stats_frame.push_back(k.frame);
    d.stats_visual_residuals.push_back(k.visual_residuals);
    d.stats_imls_residuals.push_back(k.imls_residuals);
    d.stats_cost_before.push_back(k.cost_before);
    d.stats_cost_after.push_back(k.cost_after);
    d.stats_time_ms.push_back(k.time_ms);
  }
  d.prior = prior;
  d.summary = summary;
  return d;
}

}  // namespace jvl::mapping
