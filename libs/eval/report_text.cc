// Text, Markdown and plot-data views of an evaluation (declared in report.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "eval/report.h"

namespace jvl::eval {

namespace {

// Six significant digits: enough to compare by eye; metrics.json keeps every digit.
std::string Num(double v) {
  if (std::isnan(v)) return "n/a";  // an undefined score (no KITTI segment)
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

struct Row {
  std::string name;
  int64_t matched = 0;
  double ape_t = 0, ape_r = 0, rpe_t = 0, rpe_p = 0, rpe_r = 0, t_rel = 0, r_rel = 0;
  int64_t segments = 0;
};

Row MakeRow(std::string name, int64_t matched, const ErrorStats& ape_t, const ErrorStats& ape_r,
            const ErrorStats& rpe_t, const ErrorStats& rpe_p, const ErrorStats& rpe_r,
            const KittiResult& k) {
  return {std::move(name),      matched,
          ape_t.rmse,           ape_r.rmse,
          rpe_t.mean,           rpe_p.mean,
          rpe_r.mean,           k.t_rel_percent,
          k.r_rel_deg_per_100m, static_cast<int64_t>(k.segments.size())};
}

std::vector<Row> Rows(const std::vector<EstimateEval>& estimates) {
  std::vector<Row> rows;
  for (const EstimateEval& e : estimates) {
    const bool several = e.sequences.size() > 1;
    rows.push_back(MakeRow(several ? e.label + " (all, pooled)" : e.label, e.frames_matched,
                           e.ape_translation, e.ape_rotation, e.rpe_translation, e.rpe_percent,
                           e.rpe_rotation, e.kitti_pooled));
    if (!several) continue;
    for (const SequenceEval& s : e.sequences) {
      rows.push_back(MakeRow(e.label + " / " + s.name, s.frames_matched, s.ape.translation_stats,
                             s.ape.rotation_stats, s.rpe.translation_stats, s.rpe.percent_stats,
                             s.rpe.rotation_stats, s.kitti));
    }
  }
  return rows;
}

std::vector<std::string> Columns() {
  return {"estimate",     "matched",        "APE rmse (m)", "APE rmse (deg)",   "RPE mean (m)",
          "RPE mean (%)", "RPE mean (deg)", "t_rel (%)",    "r_rel (deg/100m)", "segments"};
}

std::vector<std::string> Cells(const Row& r) {
  return {r.name,       std::to_string(r.matched),
          Num(r.ape_t), Num(r.ape_r),
          Num(r.rpe_t), Num(r.rpe_p),
          Num(r.rpe_r), Num(r.t_rel),
          Num(r.r_rel), std::to_string(r.segments)};
}

std::string Header(const EvalOptions& o) {
  std::ostringstream os;
  os << "alignment " << ToString(o.alignment) << (o.origin_first ? " (origin first)" : "")
     << ", association by " << ToString(o.association.mode) << ", RPE delta " << o.rpe.delta << " "
     << ToString(o.rpe.unit) << ", KITTI segments of " << o.kitti.lengths.front() << ".."
     << o.kitti.lengths.back() << " m every " << o.kitti.step_frames << " frames";
  return os.str();
}

std::string MeanOfSequencesNote(const std::vector<EstimateEval>& estimates,
                                const EvalOptions& options) {
  std::ostringstream os;
  for (const EstimateEval& e : estimates) {
    if (!e.kitti_pooled.segments.empty()) continue;
    os << "t_rel and r_rel of " << e.label << " are n/a: its path is shorter than the shortest "
       << "KITTI segment (" << Num(options.kitti.lengths.front())
       << " m), so the score is undefined\n";
  }
  for (const EstimateEval& e : estimates) {
    if (e.sequences.size() < 2) continue;
    os << "mean of per-sequence KITTI scores, " << e.label << ": t_rel "
       << Num(e.kitti_mean_t_rel_percent) << " %, r_rel " << Num(e.kitti_mean_r_rel_deg_per_100m)
       << " deg/100m (the '(all, pooled)' row averages all segments, as the devkit)\n";
  }
  return os.str();
}

}  // namespace

std::string FormatTable(const std::vector<EstimateEval>& estimates, const EvalOptions& options) {
  const std::vector<std::string> cols = Columns();
  std::vector<std::vector<std::string>> cells;
  for (const Row& r : Rows(estimates)) cells.push_back(Cells(r));
  std::vector<size_t> width(cols.size());
  for (size_t c = 0; c < cols.size(); ++c) {
    width[c] = cols[c].size();
    for (const auto& row : cells) width[c] = std::max(width[c], row[c].size());
  }
  std::ostringstream os;
  os << Header(options) << "\n";
  auto line = [&](const std::vector<std::string>& row) {
    for (size_t c = 0; c < row.size(); ++c) {
      const std::string pad(width[c] - row[c].size(), ' ');
      os << (c == 0 ? row[c] + pad : pad + row[c]) << (c + 1 < row.size() ? "  " : "\n");
    }
  };
  line(cols);
  size_t total = 0;
  for (size_t w : width) total += w + 2;
  os << std::string(total - 2, '-') << "\n";
  for (const auto& row : cells) line(row);
  os << MeanOfSequencesNote(estimates, options);
  return os.str();
}

std::string FormatMarkdown(const std::vector<EstimateEval>& estimates, const EvalOptions& options) {
  std::ostringstream os;
  os << "# Trajectory evaluation\n\n" << Header(options) << ".\n\n";
  const std::vector<std::string> cols = Columns();
  os << "|";
  for (const auto& c : cols) os << " " << c << " |";
  os << "\n|";
  for (size_t c = 0; c < cols.size(); ++c) os << (c == 0 ? "---|" : "---:|");
  os << "\n";
  for (const Row& r : Rows(estimates)) {
    os << "|";
    for (const auto& cell : Cells(r)) os << " " << cell << " |";
    os << "\n";
  }
  const std::string note = MeanOfSequencesNote(estimates, options);
  if (!note.empty()) os << "\n" << note;
  os << "\n## APE along the path and about the camera axes (RMS)\n\n"
     << "Position error in the ground truth's path frame (along the direction of travel, lateral, "
        "vertical) and the rotation error about the camera's x, y, z axes (KITTI camera: pitch, "
        "yaw, roll), after the alignment above.\n\n"
     << "| estimate | along (m) | lateral (m) | vertical (m) | pitch (deg) | yaw (deg) | roll "
        "(deg) |\n|---|---:|---:|---:|---:|---:|---:|\n";
  for (const EstimateEval& e : estimates) {
    const ApeComponentStats& c = e.ape_components;
    os << "| " << e.label << " | " << Num(c.along.rmse) << " | " << Num(c.lateral.rmse) << " | "
       << Num(c.vertical.rmse) << " | " << Num(c.pitch.rmse) << " | " << Num(c.yaw.rmse) << " | "
       << Num(c.roll.rmse) << " |\n";
  }
  for (const EstimateEval& e : estimates) {
    os << "\n## KITTI error per segment length: " << e.label << "\n\n"
       << "| length (m) | segments | t_rel (%) | r_rel (deg/100m) |\n|---:|---:|---:|---:|\n";
    for (const KittiLengthRow& row : e.kitti_pooled.per_length) {
      os << "| " << Num(row.length_m) << " | " << row.count << " | " << Num(row.t_rel_percent)
         << " | " << Num(row.r_rel_deg_per_100m) << " |\n";
    }
  }
  return os.str();
}

nlohmann::json PlotData(const std::vector<EstimateEval>& estimates, const EvalOptions& options) {
  nlohmann::json j;
  j["title"] = Header(options);
  j["estimates"] = nlohmann::json::array();
  for (const EstimateEval& e : estimates) {
    nlohmann::json je = {{"label", e.label}, {"sequences", nlohmann::json::array()}};
    je["kitti_per_length"] = nlohmann::json::array();
    for (const KittiLengthRow& row : e.kitti_pooled.per_length) {
      je["kitti_per_length"].push_back(
          {row.length_m, row.count, row.t_rel_percent, row.r_rel_deg_per_100m});
    }
    for (const SequenceEval& s : e.sequences) {
      nlohmann::json js = {{"name", s.name}};
      nlohmann::json gt = nlohmann::json::array(), est = nlohmann::json::array(),
                     est_frames = nlohmann::json::array();
      auto xyz = [&s](const Eigen::Matrix4d& pose) {
        const Eigen::Vector4d p = s.world_from_origin * pose.col(3);
        return nlohmann::json::array({p.x(), p.y(), p.z()});
      };
      for (size_t i = 0; i < s.paired.size(); ++i) {
        gt.push_back(xyz(s.paired.gt[i]));
        if (s.paired.has_est[i]) {
          est.push_back(xyz(s.paired.est[i]));
          est_frames.push_back(s.paired.frames[i]);
        }
      }
      js["gt_frames"] = s.paired.frames;
      js["gt_xyz"] = std::move(gt);
      js["est_xyz"] = std::move(est);
      js["est_frames"] = std::move(est_frames);
      js["ape_frames"] = s.ape.frames;
      js["ape_translation_m"] = s.ape.translation_m;
      je["sequences"].push_back(std::move(js));
    }
    j["estimates"].push_back(std::move(je));
  }
  return j;
}

}  // namespace jvl::eval
