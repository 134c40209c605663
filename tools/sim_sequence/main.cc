// sim_sequence: writes a synthetic driving sequence in the KITTI odometry layout
// (OUT/sequences/NN/{velodyne,image_0,calib.txt,times.txt}, OUT/poses/NN.txt) plus ground truth
// KITTI lacks: OUT/sequences/NN/sim/{gt_vps.csv, gt_vps.json, scene.json}.
#include <spdlog/spdlog.h>

#include <cctype>
#include <cstdio>

#include "app/tool.h"
#include "core/check.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/kitti.h"
#include "sim/describe.h"
#include "sim/preview.h"
#include "sim/sequence.h"
#include "sim/write_sequence.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("sim_sequence", "Generate a synthetic KITTI-layout driving sequence.");
  jvl::sim::SequenceOptions opt;
  std::string output, sequence = "00", scenario = "urban";
  bool no_images = false, no_scans = false;
  auto& cli = tool.cli();
  cli.add_option("--output,-o", output, "Output root (KITTI odometry layout)")->required();
  cli.add_option("--sequence", sequence, "Sequence name (two digits)")->capture_default_str();
  cli.add_option("--frames", opt.frames, "Frames to write (0 = whole route)")
      ->capture_default_str();
  cli.add_option("--scenario", scenario,
                 "urban, suburban, highway or straight (highway scenery, one 1.2 km straight)")
      ->capture_default_str();
  cli.add_option("--laps", opt.laps,
                 "Drive the route this many times, every second lap mirrored (long sequences)")
      ->capture_default_str();
  cli.add_option("--seed", opt.seed, "Random seed (world layout and noise)")->capture_default_str();
  cli.add_flag("--stop", opt.stop, "Stop for a few seconds before the second corner");
  cli.add_option("--range-noise", opt.lidar.range_noise, "LiDAR range noise sigma (m)")
      ->capture_default_str();
  cli.add_option("--dropout", opt.lidar.dropout, "LiDAR random dropout probability")
      ->capture_default_str();
  cli.add_flag("--motion-distortion", opt.lidar.motion_distortion,
               "Move the LiDAR during the 0.1 s sweep");
  cli.add_option("--pixel-noise", opt.camera.pixel_noise, "Image noise sigma (grey levels)")
      ->capture_default_str();
  cli.add_option("--supersample", opt.camera.supersample,
                 "Camera rays per pixel along each axis, on a rotated grid, where the pixel "
                 "sees an edge (its area is averaged); 1: one ray per pixel centre")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  cli.add_option("--supersample-contrast", opt.camera.supersample_contrast,
                 "A pixel is supersampled where its neighbourhood sees another surface or the "
                 "second difference of neighbouring centre rays exceeds this many grey levels "
                 "(negative: every pixel)")
      ->capture_default_str();
  cli.add_option("--exposure-variation", opt.camera.exposure_variation,
                 "Relative frame-to-frame exposure change")
      ->capture_default_str();
  cli.add_option("--moving-cars", opt.scene.moving_cars, "Moving cars on the route")
      ->capture_default_str();
  cli.add_option("--terrain-scale", opt.scene.terrain_scale,
                 "Scale of the rolling terrain's heights and slopes (0 = flat, 1 = slopes of a "
                 "few percent)")
      ->capture_default_str();
  int64_t preview = -1;
  cli.add_option("--preview-frame", preview,
                 "Also write sim/topview_<frame>.png, a bird's-eye view of that frame's scan");
  cli.add_flag("--no-images", no_images, "Do not render camera images");
  cli.add_flag("--no-scans", no_scans, "Do not simulate LiDAR scans");
  return tool.Run(argc, argv, [&] {
    opt.scenario = jvl::sim::ParseScenario(scenario);
    opt.render_images = !no_images;
    opt.simulate_scans = !no_scans;
    JVL_CHECK(sequence.size() == 2 && std::isdigit(sequence[0]) && std::isdigit(sequence[1]),
              "--sequence must be two digits, got '" << sequence << "'");
    jvl::Timer timer;
    const auto world = jvl::sim::BuildWorld(opt);
    spdlog::info("world: {} triangles, {} buildings, {} frames, built in {:.2f} s",
                 world->scene.mesh.triangles.size(), world->scene.buildings.size(),
                 world->ground_truth.size(), timer.ElapsedSeconds());
    tool.SetDatasetId("sim:" + scenario + ":" + std::to_string(opt.seed));
    jvl::Progress progress("sim_sequence", static_cast<int64_t>(world->ground_truth.size()),
                           !tool.quiet());
    const auto st = jvl::sim::WriteSequence(
        *world, output, sequence, tool.threads(), [&] { return tool.MakeProvenance(); },
        [&] { progress.Tick(); });
    if (preview >= 0) {
      const auto f = jvl::sim::SimulateFrame(*world, preview);
      char name[64];
      std::snprintf(name, sizeof(name), "/sequences/%s/sim/topview_%06lld.png", sequence.c_str(),
                    static_cast<long long>(preview));
      jvl::io::WriteImage(output + name, jvl::sim::ScanTopView(f.scan, opt.lidar_height));
    }
    const auto rs = jvl::sim::SummarizeRoute(*world);
    spdlog::info(
        "wrote {} frames under {} in {:.1f} s ({:.1f} frames/s on {} threads); {:.0f} m, "
        "{:.1f}-{:.1f} m/s, {} straights >= 100 m, {} turns",
        st.frames, output, st.frame_seconds, st.frames / st.frame_seconds, tool.threads(),
        rs.driven_length_m, rs.min_speed, rs.max_speed, rs.straights_100m, rs.turns);
  });
}
