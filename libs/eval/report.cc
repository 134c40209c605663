#include "eval/report.h"

#include <cmath>

namespace jvl::eval {

namespace {

// An undefined score (no segment) is null in the report.
nlohmann::json Score(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json KittiToJson(const KittiResult& k) {
  nlohmann::json j;
  j["t_rel_percent"] = Score(k.t_rel_percent);
  j["r_rel_deg_per_100m"] = Score(k.r_rel_deg_per_100m);
  j["segments"] = static_cast<int64_t>(k.segments.size());
  j["per_length"] = nlohmann::json::array();
  for (const KittiLengthRow& row : k.per_length) {
    j["per_length"].push_back({{"length_m", row.length_m},
                               {"segments", row.count},
                               {"t_rel_percent", Score(row.t_rel_percent)},
                               {"r_rel_deg_per_100m", Score(row.r_rel_deg_per_100m)}});
  }
  return j;
}

nlohmann::json AlignmentToJson(const SequenceEval& s, const EvalOptions& options) {
  nlohmann::json j;
  j["method"] = ToString(options.alignment);
  j["origin_first"] = options.origin_first || options.alignment == Alignment::kOrigin;
  j["origin_frame"] = s.origin_frame;
  j["rotation"] = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    j["rotation"].push_back(
        {s.alignment.rotation(r, 0), s.alignment.rotation(r, 1), s.alignment.rotation(r, 2)});
  }
  j["translation"] = {s.alignment.translation.x(), s.alignment.translation.y(),
                      s.alignment.translation.z()};
  j["scale"] = s.alignment.scale;
  j["conditioning"] = s.alignment.conditioning;
  return j;
}

nlohmann::json RpeToJson(const ErrorStats& t, const ErrorStats& p, const ErrorStats& r,
                         const EvalOptions& options) {
  return {{"delta", options.rpe.delta},
          {"unit", ToString(options.rpe.unit)},
          {"pairs", t.count},
          {"translation_m", StatsToJson(t)},
          {"translation_percent", StatsToJson(p)},
          {"rotation_deg", StatsToJson(r)}};
}

}  // namespace

nlohmann::json OptionsToJson(const EvalOptions& o) {
  return {{"alignment", ToString(o.alignment)},
          {"origin_first", o.origin_first},
          {"association", ToString(o.association.mode)},
          {"max_dt_s", o.association.max_dt},
          {"rpe_delta", o.rpe.delta},
          {"rpe_unit", ToString(o.rpe.unit)},
          {"kitti_lengths_m", o.kitti.lengths},
          {"kitti_step_frames", o.kitti.step_frames}};
}

nlohmann::json StatsToJson(const ErrorStats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"count", s.count}};
}

namespace {

// The six component statistics of ApeComponentStats.
nlohmann::json ComponentsToJson(const ApeComponentStats& c) {
  return {{"along_m", StatsToJson(c.along)},       {"lateral_m", StatsToJson(c.lateral)},
          {"vertical_m", StatsToJson(c.vertical)}, {"pitch_deg", StatsToJson(c.pitch)},
          {"yaw_deg", StatsToJson(c.yaw)},         {"roll_deg", StatsToJson(c.roll)}};
}

}  // namespace

nlohmann::json SequenceToJson(const SequenceEval& s, const EvalOptions& options) {
  nlohmann::json j;
  j["name"] = s.name;
  j["gt_poses"] = s.gt_poses;
  j["est_poses"] = s.est_poses;
  j["frames_matched"] = s.frames_matched;
  j["est_unmatched_frames"] = s.est_unmatched_frames;
  j["gt_missing_frames"] = s.gt_missing_frames;
  j["alignment"] = AlignmentToJson(s, options);
  j["ape"] = {{"translation_m", StatsToJson(s.ape.translation_stats)},
              {"rotation_deg", StatsToJson(s.ape.rotation_stats)}};
  const ApeComponents& c = s.ape_components;
  j["ape"]["components"] = ComponentsToJson(c);
  j["ape"]["components"]["up"] = {c.up.x(), c.up.y(), c.up.z()};
  j["ape"]["components"]["skipped"] = c.skipped;
  j["rpe"] = RpeToJson(s.rpe.translation_stats, s.rpe.percent_stats, s.rpe.rotation_stats, options);
  j["kitti"] = KittiToJson(s.kitti);
  return j;
}

nlohmann::json EstimateToJson(const EstimateEval& e, const EvalOptions& options) {
  nlohmann::json j;
  j["label"] = e.label;
  j["frames_matched"] = e.frames_matched;
  j["ape"] = {{"translation_m", StatsToJson(e.ape_translation)},
              {"rotation_deg", StatsToJson(e.ape_rotation)}};
  j["ape"]["components"] = ComponentsToJson(e.ape_components);
  j["rpe"] = RpeToJson(e.rpe_translation, e.rpe_percent, e.rpe_rotation, options);
  // Pooled over all segments of all sequences (devkit); equal to the sequence's for one.
  j["kitti"] = KittiToJson(e.kitti_pooled);
  j["kitti"]["pooling"] = "all segments of all sequences (KITTI devkit)";
  j["kitti"]["mean_of_sequences"] = {
      {"t_rel_percent", Score(e.kitti_mean_t_rel_percent)},
      {"r_rel_deg_per_100m", Score(e.kitti_mean_r_rel_deg_per_100m)}};
  if (e.sequences.size() == 1) {
    j["alignment"] = AlignmentToJson(e.sequences.front(), options);
  } else {
    j["alignment"] = {{"method", ToString(options.alignment)},
                      {"origin_first", options.origin_first},
                      {"note", "fitted per sequence; see sequences[].alignment"}};
  }
  j["sequences"] = nlohmann::json::array();
  for (const SequenceEval& s : e.sequences) j["sequences"].push_back(SequenceToJson(s, options));
  return j;
}

nlohmann::json ReportToJson(const std::vector<EstimateEval>& estimates,
                            const EvalOptions& options) {
  nlohmann::json j;
  j["options"] = OptionsToJson(options);
  j["estimates"] = nlohmann::json::array();
  for (const EstimateEval& e : estimates) j["estimates"].push_back(EstimateToJson(e, options));
  return j;
}

}  // namespace jvl::eval
