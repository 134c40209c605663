// sim_map_check: how far the points of a visual map (visual_assoc) lie from the true scene surface
// of the simulated sequence they were built from.
//
//   sim_map_check --sequence OUT/sequences/00 --visual visual.h5 [--max-depth 30] [--json r.json]
#include <spdlog/spdlog.h>

#include <cstdio>

#include "app/tool.h"
#include "io/artifact.h"
#include "io/dataset.h"
#include "io/files.h"
#include "io/visual_io.h"
#include "map_check_run.h"

namespace {

void PrintStats(const char* label, const jvl::sim::SurfaceDistanceStats& s) {
  std::printf("%-9s %7lld %8.3f %8.3f %8.3f %8.3f %7.1f%% %6lld %6lld\n", label,
              static_cast<long long>(s.points), s.median_perpendicular, s.p90_perpendicular,
              s.median_along, s.p90_along, 100 * s.within_threshold,
              static_cast<long long>(s.no_hit), static_cast<long long>(s.moving_car));
}

}  // namespace

int main(int argc, char** argv) {
  jvl::app::Tool tool("sim_map_check",
                      "Distance of visual map points to the true surface of a simulated sequence.");
  std::string sequence_dir, visual_path, json_path, csv_path;
  jvl::sim::SurfaceCheckOptions options;
  auto& cli = tool.cli();
  cli.add_option("--sequence", sequence_dir, "Simulated sequence folder (with sim/scene.json)")
      ->required();
  tool.InputFile(
      cli.add_option("--visual", visual_path, "visual.h5 built from that sequence")->required());
  cli.add_option("--max-depth", options.max_depth,
                 "Points deeper in their nearest view are skipped (m)")
      ->capture_default_str();
  tool.FieldFlag("threshold", "--threshold");
  cli.add_option("--threshold", options.threshold, "On the surface: perpendicular distance (m)")
      ->capture_default_str();
  tool.OutputFile(
      cli.add_option("--json", json_path, "Write the report (schemas/sim_map_check.schema.json)"));
  tool.OutputFile(
      cli.add_option("--points-csv", csv_path, "Write one line per map point (diagnostics)"));
  return tool.Run(argc, argv, [&] {
    options.depth_bins = {0};
    for (double edge = 10; edge < options.max_depth; edge += 10) options.depth_bins.push_back(edge);
    options.depth_bins.push_back(options.max_depth);
    options.Check();
    // scene.json names the simulated world ('sim:<scenario>:<seed>'), not the dataset id the
    // stages record (from the folder's calib.txt and times.txt): the visual map is checked
    // against the latter.
    tool.AddDataset(*jvl::io::OpenDataset(sequence_dir), sequence_dir);
    tool.AddInput(sequence_dir + "/sim/scene.json", /*same_dataset=*/false);
    tool.AddInput(visual_path);
    const auto world = jvl::tools::RebuildSequenceWorld(sequence_dir);
    const jvl::io::VisualMapData visual = jvl::io::ReadVisualMap(visual_path);
    const auto result = jvl::tools::RunMapCheck(*world, visual, options, tool.threads());
    if (result.max_keyframe_position_error_m > 0.01 ||
        result.max_keyframe_rotation_error_deg > 0.05) {
      spdlog::warn(
          "keyframe poses differ from the ground truth (up to {:.3f} m, {:.3f} deg): the distances "
          "include the prior's pose errors",
          result.max_keyframe_position_error_m, result.max_keyframe_rotation_error_deg);
    }
    const auto& s = result.summary;
    std::printf(
        "map points %lld, beyond %.0f m or unseen %lld; distances in m, on surface <= %.3f\n",
        static_cast<long long>(s.total_points), options.max_depth,
        static_cast<long long>(s.beyond_max_depth), s.threshold);
    std::printf("%-9s %7s %8s %8s %8s %8s %8s %6s %6s\n", "depth", "points", "med perp", "p90 perp",
                "med ray", "p90 ray", "on surf", "no hit", "car");
    for (const auto& b : s.bins) {
      char label[32];
      std::snprintf(label, sizeof(label), "%.0f-%.0f", b.min_depth, b.max_depth);
      PrintStats(label, b);
    }
    PrintStats("all", s.all);
    if (!csv_path.empty()) {
      jvl::io::WriteTextFileAtomic(csv_path, jvl::tools::FormatPointsCsv(result, *world, visual));
    }
    if (!json_path.empty()) {
      jvl::io::WriteJsonArtifact(json_path, "sim_map_check", 1, jvl::tools::ToJson(result),
                                 tool.MakeProvenance());
      spdlog::info("sim_map_check: wrote {}", json_path);
    }
  });
}
