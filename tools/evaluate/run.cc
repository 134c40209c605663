#include "run.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <map>

#include "core/check.h"
#include "eval/report.h"
#include "io/eval_report_io.h"
#include "io/kitti.h"

namespace jvl::tools {

namespace {

namespace fs = std::filesystem;

std::string Stem(const std::string& path) {
  const fs::path p(path);
  return p.has_filename() ? p.stem().string() : p.parent_path().filename().string();
}

eval::PoseSeries Read(const std::string& path, const std::string& format) {
  io::PoseMatrices m = io::ReadPoseMatrices(path, io::ParseTrajectoryFormat(format));
  eval::PoseSeries s;
  s.frames = std::move(m.frames);
  s.poses = std::move(m.poses);
  s.timestamps = std::move(m.timestamps);
  return s;
}

// (sequence name, gt path, est path) per sequence of one estimate.
struct SequenceFiles {
  std::string name, gt, est;
};

std::vector<SequenceFiles> PairFiles(const EvaluateConfig& c, const std::string& est) {
  if (!io::IsDirectory(c.gt)) {
    JVL_CHECK(!io::IsDirectory(est), "--est " << est << " is a folder but --gt is a file");
    return {{Stem(c.gt), c.gt, est}};
  }
  JVL_CHECK(io::IsDirectory(est), "--gt is a folder, so --est " << est << " must be one too");
  std::vector<SequenceFiles> out;
  for (const std::string& file : io::ListTrajectoryFiles(est)) {
    const std::string name = Stem(file);
    if (!c.seqs.empty() && std::find(c.seqs.begin(), c.seqs.end(), name) == c.seqs.end()) continue;
    const std::string gt = (fs::path(c.gt) / fs::path(file).filename()).string();
    if (!io::FileExists(gt)) {
      spdlog::warn("{}: no ground truth {} in {}; sequence skipped", file, name, c.gt);
      continue;
    }
    out.push_back({name, gt, file});
  }
  JVL_CHECK(!out.empty(),
            "--est " << est << ": no trajectory file with a ground truth in " << c.gt);
  return out;
}

void LogMatching(const std::string& label, const eval::SequenceEval& s) {
  spdlog::info("{} / {}: {} of {} estimated poses matched ({} ground-truth poses)", label, s.name,
               s.frames_matched, s.est_poses, s.gt_poses);
  if (!s.gt_missing_frames.empty()) {
    spdlog::warn(
        "{} / {}: {} ground-truth frame(s) inside the estimate's span have no estimate "
        "(first: {})",
        label, s.name, s.gt_missing_frames.size(), s.gt_missing_frames.front());
  }
  if (s.alignment.IllConditioned()) {
    spdlog::warn(
        "{} / {}: the matched positions are nearly collinear (conditioning {:.2g}): the alignment "
        "cannot fix the rotation about the direction of travel, so aligned rotation errors are "
        "not meaningful; use --align origin or none for rotations",
        label, s.name, s.alignment.conditioning);
  }
  if (!s.est_unmatched_frames.empty()) {
    spdlog::warn("{} / {}: {} estimated pose(s) have no ground truth (first frame: {})", label,
                 s.name, s.est_unmatched_frames.size(), s.est_unmatched_frames.front());
  }
}

}  // namespace

void EvaluateConfig::Check() const {
  options.Check();
  JVL_CHECK(!gt.empty(), "--gt is required");
  JVL_CHECK(!est.empty(), "at least one --est is required");
  JVL_CHECK(labels.empty() || labels.size() == est.size(),
            labels.size() << " --label for " << est.size() << " --est (give one per estimate)");
  JVL_CHECK(lidar_poses == "est" || lidar_poses == "gt" || lidar_poses == "both",
            "--lidar-poses must be est, gt or both (got '" << lidar_poses << "')");
  io::ParseTrajectoryFormat(gt_format);
  io::ParseTrajectoryFormat(est_format);
}

EvaluateRun RunEvaluation(const EvaluateConfig& c) {
  c.Check();
  EvaluateRun run;
  std::optional<Eigen::Matrix4d> cam0_from_velo;
  if (!c.calib.empty()) {
    cam0_from_velo = io::ReadKittiCalibration(c.calib).cam0_from_velo.Matrix4();
    run.inputs.push_back(c.calib);
  }
  const bool convert_gt = cam0_from_velo && c.lidar_poses != "est";
  const bool convert_est = cam0_from_velo && c.lidar_poses != "gt";
  std::map<std::string, eval::PoseSeries> gt_cache;
  for (size_t k = 0; k < c.est.size(); ++k) {
    const std::string label = c.labels.empty() ? Stem(c.est[k]) : c.labels[k];
    std::vector<eval::SequenceEval> sequences;
    for (const SequenceFiles& f : PairFiles(c, c.est[k])) {
      if (!gt_cache.count(f.gt)) {
        eval::PoseSeries gt = Read(f.gt, c.gt_format);
        if (convert_gt) gt = eval::LidarToCamera(gt, *cam0_from_velo);
        gt_cache.emplace(f.gt, std::move(gt));
        run.inputs.push_back(f.gt);
      }
      eval::PoseSeries est = Read(f.est, c.est_format);
      if (convert_est) est = eval::LidarToCamera(est, *cam0_from_velo);
      run.inputs.push_back(f.est);
      sequences.push_back(eval::EvaluateSequence(gt_cache.at(f.gt), est, c.options, f.name, f.est));
      LogMatching(label, sequences.back());
    }
    run.estimates.push_back(eval::CombineSequences(label, std::move(sequences), c.options.kitti));
  }
  return run;
}

nlohmann::json ReportBody(const EvaluateConfig& c, const EvaluateRun& run) {
  nlohmann::json body = eval::ReportToJson(run.estimates, c.options);
  body["ground_truth"] = c.gt;
  for (size_t k = 0; k < run.estimates.size(); ++k) body["estimates"][k]["path"] = c.est[k];
  return body;
}

}  // namespace jvl::tools
