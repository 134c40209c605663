// evaluate: scores trajectories against ground truth (APE, RPE, KITTI t_rel / r_rel).
//
//   evaluate --gt 09.txt --est ours.txt [--est other.txt ...] [--label NAME ...]
//            [--align none|origin|se3|sim3] [--json metrics.json] [--markdown m.md] [--plot-dir D]
#include <spdlog/spdlog.h>

#include <cstdio>

#include "app/tool.h"
#include "eval/report.h"
#include "io/eval_report_io.h"
#include "io/loops_io.h"
#include "run.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("evaluate",
                      "Compare trajectories with ground truth: APE, RPE and the KITTI "
                      "segment metric (t_rel %, r_rel deg/100m).");
  jvl::tools::EvaluateConfig c;
  std::string align = "none", assoc = "frame", rpe_unit = "frames";
  std::string json, markdown, plot_dir, plot_script, python, loops_path;
  CLI::App& cli = tool.cli();
  tool.InputFile(cli.add_option("--gt", c.gt,
                                "Ground truth: trajectory file (KITTI/TUM/.h5) or folder of them")
                     ->required());
  tool.InputFile(
      cli.add_option("--est", c.est, "Estimate(s): file, or folder when --gt is a folder")
          ->required());
  cli.add_option("--label", c.labels, "Name of each estimate in the reports (one per --est)");
  cli.add_option("--align", align, "none | origin | se3 | sim3")->capture_default_str();
  cli.add_flag("--origin-first", c.options.origin_first,
               "With se3/sim3: first express both relative to the first matched pose");
  cli.add_option("--assoc", assoc, "Association: frame (index) | timestamp")->capture_default_str();
  cli.add_option("--max-dt", c.options.association.max_dt, "Timestamp association tolerance (s)")
      ->capture_default_str();
  tool.FieldFlag("delta", "--rpe-delta");
  cli.add_option("--rpe-delta", c.options.rpe.delta, "RPE step (frames or metres)")
      ->capture_default_str();
  cli.add_option("--rpe-unit", rpe_unit, "RPE step unit: frames | m")->capture_default_str();
  cli.add_option("--gt-format", c.gt_format, "auto | kitti | kitti-indexed | tum | h5")
      ->capture_default_str();
  cli.add_option("--est-format", c.est_format, "auto | kitti | kitti-indexed | tum | h5")
      ->capture_default_str();
  cli.add_option("--calib", c.calib, "KITTI calib.txt: LiDAR-frame poses -> cam0 (Tr T Tr^-1)");
  cli.add_option("--lidar-poses", c.lidar_poses, "With --calib: est | gt | both")
      ->capture_default_str();
  cli.add_option("--seqs", c.seqs, "Folder mode: sequence names to evaluate (default: all)");
  tool.OutputFile(
      cli.add_option("--json", json, "Write the metrics report (schemas/metrics.schema.json)"));
  tool.OutputFile(cli.add_option("--markdown", markdown, "Write the comparison as Markdown"));
  cli.add_option("--plot-dir", plot_dir, "Write PNG plots here (needs python3-matplotlib)");
  cli.add_option("--plot-script", plot_script, "Plotting script (default: scripts/plot_eval.py)");
  cli.add_option("--python", python, "Python interpreter for the plots (default: python3)");
  cli.add_option("--loops", loops_path,
                 "loops artifact (loop_detect): the trajectory plot marks its accepted loops "
                 "(query and match on the ground truth, by detector)");
  return tool.Run(argc, argv, [&] {
    c.options.alignment = jvl::eval::ParseAlignment(align);
    c.options.association.mode = jvl::eval::ParseAssociationMode(assoc);
    c.options.rpe.unit = jvl::eval::ParseRpeUnit(rpe_unit);
    // Checked before any work: an explicit --python that cannot plot is an error.
    const std::string plot_python = plot_dir.empty() ? "" : jvl::tools::FindPlotPython(python);
    const jvl::tools::EvaluateRun run = jvl::tools::RunEvaluation(c);
    for (const std::string& input : run.inputs) tool.AddInput(input, /*same_dataset=*/false);
    std::fputs(jvl::eval::FormatTable(run.estimates, c.options).c_str(), stdout);
    std::fflush(stdout);
    if (!json.empty()) {
      jvl::io::WriteMetricsReport(json, jvl::tools::ReportBody(c, run), tool.MakeProvenance());
      spdlog::info("metrics written to {}", json);
    }
    if (!markdown.empty()) {
      jvl::io::WriteTextFileAtomic(markdown, jvl::eval::FormatMarkdown(run.estimates, c.options));
    }
    if (!plot_dir.empty()) {
      nlohmann::json plot_data = jvl::eval::PlotData(run.estimates, c.options);
      if (!loops_path.empty()) {
        tool.AddInput(loops_path, /*same_dataset=*/false);
        // Accepted loops (status 0) as [query, match, detector]; "both" where another
        // detector closed the same query too (its loop kept as a duplicate, status 8).
        const jvl::io::LoopsData loops = jvl::io::ReadLoopsArtifact(loops_path);
        nlohmann::json marks = nlohmann::json::array();
        for (const jvl::io::LoopRecord& r : loops.loops) {
          if (r.status != 0) continue;
          bool both = false;
          for (const jvl::io::LoopRecord& d : loops.loops)
            both |= d.status == 8 && d.query == r.query;
          marks.push_back({r.query, r.match,
                           both              ? "both"
                           : r.detector == 1 ? "visual"
                           : r.detector == 2 ? "proximity"
                                             : "LiDAR"});
        }
        plot_data["loops"] = std::move(marks);
      }
      jvl::tools::MakePlots(plot_dir, plot_data, plot_script, plot_python);
    }
    spdlog::info("evaluated {} estimate(s) in {:.3f} s", run.estimates.size(),
                 tool.MakeProvenance().wall_time_s);
  });
}
