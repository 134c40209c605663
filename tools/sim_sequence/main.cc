// sim_sequence: writes a synthetic driving sequence in the KITTI odometry layout
// (OUT/sequences/NN/{velodyne,image_0,calib.txt,times.txt}, OUT/poses/NN.txt) or the KITTI-360
// layout (--layout kitti360, io/sim_io.h) plus ground truth KITTI lacks:
// DATASET/sim/{gt_vps.csv, gt_vps.json, scene.json}.
#include <spdlog/spdlog.h>

#include <cctype>
#include <cstdio>

#include "app/tool.h"
#include "cli_options.h"
#include "core/check.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/kitti.h"
#include "io/sim_io.h"
#include "sim/describe.h"
#include "sim/preview.h"
#include "sim/sequence.h"
#include "sim/write_sequence.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("sim_sequence",
                      "Generate a synthetic driving sequence in the KITTI (or KITTI-360) layout.");
  jvl::sim::SequenceOptions opt;
  std::string output, sequence = "00", scenario = "urban", layout_name = "kitti";
  bool no_images = false, no_scans = false;
  auto& cli = tool.cli();
  cli.add_option("--output,-o", output, "Output root (of the dataset layout, --layout)")
      ->required();
  cli.add_option("--sequence", sequence, "Sequence name (two digits)")->capture_default_str();
  cli.add_option("--layout", layout_name,
                 "Dataset layout: kitti (OUT/sequences/NN, OUT/poses/NN.txt), kitti360 "
                 "(OUT/calibration, OUT/data_3d_raw/sim_drive_00NN_sync, data_2d_raw, "
                 "data_poses; the tools' --dataset is OUT/data_3d_raw/sim_drive_00NN_sync) or "
                 "oxford (OUT/sim-oxford-NN, the tools' --dataset, with OUT/extrinsics and "
                 "OUT/models)")
      ->capture_default_str();
  cli.add_option("--frames", opt.frames, "Frames to write (0 = whole route)")
      ->capture_default_str();
  cli.add_option("--scenario", scenario,
                 "urban, suburban, highway, straight (highway scenery, one 1.2 km straight) or "
                 "loop (urban scenery: a street, --laps circuits of a city block, back along "
                 "the street) or figure8 (urban scenery: a street, --laps figure eights round "
                 "two blocks that meet at a crossing, back along the street)")
      ->capture_default_str();
  jvl::tools::AddSimSequenceFlags(tool, &opt);
  tool.FieldFlag("frames", "--frames");
  int64_t preview = -1;
  cli.add_option("--preview-frame", preview,
                 "Also write sim/topview_<frame>.png, a bird's-eye view of that frame's scan");
  cli.add_flag("--no-images", no_images, "Do not render camera images");
  cli.add_option("--cameras", opt.cameras,
                 "Cameras to render (kitti layout; e.g. --cameras 0,2): each at its offset from "
                 "camera 0 in the calibration, 2 and 3 as colour images")
      ->delimiter(',')
      ->capture_default_str();
  cli.add_flag("--no-scans", no_scans, "Do not simulate LiDAR scans");
  return tool.Run(argc, argv, [&] {
    opt.scenario = jvl::sim::ParseScenario(scenario);
    opt.render_images = !no_images;
    opt.simulate_scans = !no_scans;
    JVL_CHECK(sequence.size() == 2 && std::isdigit(sequence[0]) && std::isdigit(sequence[1]),
              "--sequence must be two digits, got '" << sequence << "'");
    const jvl::io::SequenceLayout layout{output, sequence, jvl::io::ParseSimLayout(layout_name)};
    JVL_CHECK(layout.layout == jvl::io::SimLayout::kKitti || opt.cameras == std::vector<int>{0},
              "--cameras: the " << layout_name << " layout is written with camera 0 only");
    jvl::Timer timer;
    const auto world = jvl::sim::BuildWorld(opt);
    spdlog::info("world: {} triangles, {} buildings, {} frames, built in {:.2f} s",
                 world->scene.mesh.triangles.size(), world->scene.buildings.size(),
                 world->ground_truth.size(), timer.ElapsedSeconds());
    tool.SetDatasetId("sim:" + scenario + ":" + std::to_string(opt.seed));
    jvl::Progress progress("sim_sequence", static_cast<int64_t>(world->ground_truth.size()),
                           !tool.quiet());
    const auto st = jvl::sim::WriteSequence(
        *world, layout, tool.threads(), [&] { return tool.MakeProvenance(); },
        [&] { progress.Tick(); });
    if (preview >= 0) {
      const auto f = jvl::sim::SimulateFrame(*world, preview);
      char name[64];
      std::snprintf(name, sizeof(name), "/topview_%06lld.png", static_cast<long long>(preview));
      jvl::io::WriteImage(layout.SimDir() + name, jvl::sim::ScanTopView(f.scan, opt.lidar_height));
    }
    const auto rs = jvl::sim::SummarizeRoute(*world);
    spdlog::info(
        "wrote {} frames under {} in {:.1f} s ({:.1f} frames/s on {} threads); {:.0f} m, "
        "{:.1f}-{:.1f} m/s, {} straights >= 100 m, {} turns",
        st.frames, output, st.frame_seconds, st.frames / st.frame_seconds, tool.threads(),
        rs.driven_length_m, rs.min_speed, rs.max_speed, rs.straights_100m, rs.turns);
  });
}
