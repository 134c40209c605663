// The body of the evaluate tool: read ground truth and estimates, evaluate, write reports.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/evaluate.h"

namespace jvl::tools {

struct EvaluateConfig {
  std::string gt;                   // A trajectory file, or a folder of per-sequence files.
  std::vector<std::string> est;     // Same kind as gt (file or folder), one per estimate.
  std::vector<std::string> labels;  // Defaults to the file/folder names.
  std::string gt_format = "auto", est_format = "auto";
  std::string calib;                // KITTI calib.txt: convert LiDAR-frame poses to cam0.
  std::string lidar_poses = "est";  // Which poses are in the LiDAR frame: est|gt|both.
  std::vector<std::string> seqs;    // Folder mode: only these sequence names.
  eval::EvalOptions options;
  void Check() const;
};

struct EvaluateRun {
  std::vector<eval::EstimateEval> estimates;
  std::vector<std::string> inputs;  // Every file read, for the provenance.
};

EvaluateRun RunEvaluation(const EvaluateConfig& config);
// The report body with the input paths added.
nlohmann::json ReportBody(const EvaluateConfig& config, const EvaluateRun& run);

// The interpreter for the plots. `requested` (--python) must have matplotlib and numpy, else
// this throws; without it, the first of python3 on PATH and /usr/bin/python3 that has them,
// or "" (plots are skipped with a warning: they are optional).
std::string FindPlotPython(const std::string& requested);

// Writes <dir>/plot_data.json and runs scripts/plot_eval.py on it with `python` (from
// FindPlotPython). Returns false (after a warning naming the reason) when there is no python,
// the script is missing or it fails.
bool MakePlots(const std::string& dir, const nlohmann::json& plot_data, std::string script,
               const std::string& python);

}  // namespace jvl::tools
