// direction_cluster: direction priors from vanishing points and a prior trajectory (Sec. 4.3,
// Algorithm 2 of the supplement). Reads vps.h5 + any trajectory, writes directions.h5 and
// optionally a CSV of the associations and a top-view PNG.
#include <spdlog/spdlog.h>

#include "app/tool.h"
#include "cli_options.h"
#include "core/check.h"
#include "core/strings.h"
#include "direction/direction_cluster.h"
#include "direction/direction_plot.h"
#include "io/dataset.h"
#include "io/directions_io.h"
#include "io/kitti.h"
#include "io/trajectory_io.h"
#include "io/vps_io.h"

namespace {

using namespace jvl;

Eigen::Vector3d ParseUp(const std::string& text) {
  if (text == "auto") return Eigen::Vector3d::Zero();
  const auto parts = SplitWhitespace(text, /*comma=*/true);
  JVL_CHECK(parts.size() == 3, "--up: expected 'auto' or 'x,y,z', got '" << text << "'");
  Eigen::Vector3d up;
  for (int i = 0; i < 3; ++i) {
    const auto v = ParseDouble(parts[i]);
    JVL_CHECK(v, "--up: '" << parts[i] << "' is not a number");
    up[i] = *v;
  }
  JVL_CHECK(up.norm() > 0, "--up: the vector must not be zero");
  return up;
}

std::vector<direction::VpObservation> ToObservations(const io::VpsData& data) {
  std::vector<direction::VpObservation> out;
  for (const auto& r : data.vps)
    out.push_back({r.frame, r.index, r.uv, r.direction, r.is_forward, r.score});
  return out;
}

io::DirectionsData ToData(const direction::DirectionClusterResult& r, int v_interval) {
  io::DirectionsData d;
  for (const auto& c : r.clusters)
    d.clusters.push_back(
        {c.id, c.direction, c.std_deg, c.size, c.first_frame, c.last_frame, c.centroid});
  for (const auto& a : r.associations)
    d.associations.push_back({a.frame, a.vp_index, a.uv, a.cluster});
  const auto& s = r.stats;
  auto vec = [](const Eigen::Vector3d& v) { return std::vector<double>{v.x(), v.y(), v.z()}; };
  d.summary = {{"input_vps", s.input_vps},
               {"missing_prior", s.missing_prior},
               {"forward_kept", s.forward_kept},
               {"level1_clusters", s.level1_clusters},
               {"level1_kept", s.level1_kept},
               {"window_kept", s.window_kept},
               {"level2_too_wide", s.level2_too_wide},
               {"level2_turning", s.level2_turning},
               {"level2_clusters", s.level2_clusters},
               {"associations_before_interval", s.associations_before_interval},
               {"associations", s.associations},
               {"v_interval", v_interval},
               {"up", vec(r.up)},
               {"ground_e1", vec(r.ground_e1)},
               {"ground_e2", vec(r.ground_e2)}};
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  app::Tool tool("direction_cluster",
                 "Direction priors d_w by bi-level mean-shift of the vanishing directions "
                 "R_wc K^-1 v (Algorithm 2), with at most one VP per frame.");
  std::string vps_path, prior_path, dataset, output, csv, plot, up = "auto";
  direction::DirectionClusterOptions o;
  auto& cli = tool.cli();
  tool.InputFile(cli.add_option("--vps", vps_path, "vps artifact (vp_detect)")->required());
  tool.InputFile(
      cli.add_option("--prior", prior_path, "Prior trajectory (.h5 artifact, KITTI or TUM text)")
          ->required());
  cli.add_option("-d,--dataset", dataset,
                 "Dataset folder: the intrinsics if vps has no camera; must be the sequence the "
                 "VPs were detected on");
  io::DatasetOptions dataset_options;
  tool.AddDatasetOptions(&dataset_options);
  tool.OutputFile(
      cli.add_option("-o,--output", output, "directions artifact to write")->required());
  tool.OutputFile(
      cli.add_option("--csv", csv, "CSV of the associations: frame,cluster,u,v,dwx,dwy,dwz"));
  tool.OutputFile(
      cli.add_option("--plot", plot, "Top-view PNG of the trajectory and the clusters"));
  tools::AddDirectionClusterFlags(tool, &o, &up);

  return tool.Run(argc, argv, [&] {
    o.up = ParseUp(up);
    o.Check();
    tool.AddInput(vps_path);
    tool.AddInput(prior_path);
    std::unique_ptr<io::Dataset> ds;
    if (!dataset.empty()) {
      ds = io::OpenDataset(dataset, dataset_options);
      tool.AddDataset(*ds, dataset);  // refuses a dataset of another sequence than the VPs'
    }
    const io::VpsData vps = io::ReadVpsArtifact(vps_path);
    const Trajectory prior = io::ReadTrajectory(prior_path);
    PinholeCamera camera;
    if (vps.camera.fx > 0) {
      camera = vps.camera;
    } else {
      JVL_CHECK(ds, vps_path << " has no camera; pass --dataset for the intrinsics");
      camera = ds->calibration().Camera(0);
    }
    const auto result = direction::ClusterDirections(ToObservations(vps), prior, camera, o);
    if (result.stats.missing_prior > 0)
      spdlog::warn("{} VPs skipped: their frames are not in the prior {}",
                   result.stats.missing_prior, prior_path);
    if (result.associations.empty()) {
      spdlog::warn(
          "no direction prior found ({} VPs in {}); visual_assoc and global_opt will "
          "run without direction priors",
          result.stats.input_vps, vps_path);
    }
    io::DirectionsData data = ToData(result, o.v_interval);
    data.camera_choice = vps.camera_choice;
    io::WriteDirectionsArtifact(output, data, tool.MakeProvenance());
    if (!csv.empty()) io::WriteDirectionsCsv(csv, data);
    if (!plot.empty()) io::WriteImage(plot, direction::RenderTopView(prior, result));
    const auto& s = result.stats;
    for (const auto& c : result.clusters) {
      spdlog::info(
          "direction prior {}: frames {}-{}, {} associations, std {:.2f} deg, headings "
          "turn {:.2f} deg along the path ({:.2f} deg/100 m)",
          c.id, c.first_frame, c.last_frame, c.size, c.std_deg, c.sweep_deg,
          c.turn_rate_deg_per_100m);
    }
    spdlog::info(
        "{} VPs, {} pass the forward filter, {} first-level clusters ({} kept, {} after "
        "Th_m/Th_l), {} direction priors ({} second-level clusters wider than Th_delta and {} "
        "turning with the road dropped), {} associations ({} before V_interval {})",
        s.input_vps, s.forward_kept, s.level1_clusters, s.level1_kept, s.window_kept,
        s.level2_clusters, s.level2_too_wide, s.level2_turning, s.associations,
        s.associations_before_interval, o.v_interval);
  });
}
