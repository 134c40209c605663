// global_opt: global joint optimisation of all keyframes with direction priors (Sec. 4.3,
// Eq. 5-8). Reads only artifacts (local.h5, visual.h5, directions.h5, optional prior), so a rerun
// with other weights needs neither the dataset nor a new feature association.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <vector>

#include "app/tool.h"
#include "cli_options.h"
#include "core/check.h"
#include "core/memory.h"
#include "core/statistics.h"
#include "core/timer.h"
#include "io/global_io.h"
#include "io/loops_io.h"
#include "io/odometry_io.h"
#include "io/ply_io.h"
#include "io/trajectory_io.h"
#include "io/vps_io.h"
#include "mapping/global/global_artifact.h"
#include "mapping/global/global_mapping.h"
#include "optim/correction.h"

int main(int argc, char** argv) {
  using namespace jvl;
  app::Tool tool("global_opt",
                 "Global joint optimisation: visual reprojection + point-to-IMLS + direction "
                 "projection errors over all keyframes (Eq. 7), full-rate trajectory and map.");
  std::string local_path, visual_path, directions_path, vps_path, prior_path, odometry_path, output,
      kitti, map_path, loops_path;
  double map_voxel = 0.2;
  bool map_ascii = false;
  mapping::GlobalMappingOptions o;  // the library's defaults are the tool's
  auto& cli = tool.cli();
  tool.InputFile(cli.add_option("--local", local_path, "local artifact (local_map)")->required());
  tool.InputFile(
      cli.add_option("--visual", visual_path, "visual artifact (visual_assoc)")->required());
  tool.InputFile(
      cli.add_option("--directions", directions_path, "directions artifact (direction_cluster)"));
  tool.InputFile(cli.add_option(
      "--vps", vps_path,
      "vps artifact (vp_detect): its vertical VPs give the vertical direction prior, one "
      "direction shared by the whole drive (with e_D; --no-vertical leaves it out)"));
  tool.InputFile(cli.add_option(
      "--prior", prior_path,
      "Full-rate prior to correct (.h5 artifact, KITTI, TUM); default: local's prior"));
  tool.InputFile(cli.add_option(
      "--odometry", odometry_path,
      "Odometry of the odometry term e_O: its motion between consecutive keyframes, robustly "
      "weighted (.h5 artifact, KITTI, TUM; default: the prior). In a re-association pass, "
      "pass the chain's first prior (lidar_odom) here: its motion is locally smoother than a "
      "global result's. A lidar_odom artifact also gives each frame's registration "
      "conditioning, which widens e_O where the scan held the motion weakly"));
  tool.InputFile(cli.add_option(
      "--loops", loops_path,
      "loops artifact (loop_detect): its accepted loops correct the keyframes before the "
      "optimisation (Algorithm 1) and tie each loop's query scan to the scans around its match "
      "(--no-loops leaves them out)"));
  tool.OutputFile(cli.add_option("-o,--output", output, "global artifact to write")->required());
  tool.OutputFile(
      cli.add_option("--kitti-poses", kitti, "Full-rate trajectory as KITTI poses text"));
  tools::GlobalOptFlags flags;
  tools::AddGlobalOptFlags(tool, &o, &flags);
  tool.OutputFile(
      cli.add_option("--map", map_path, "Accumulated map PLY (stored scans, optimised poses)"));
  cli.add_option("--map-voxel", map_voxel, "Voxel size (m) of the map")->capture_default_str();
  cli.add_flag("--map-ascii", map_ascii, "Write the PLY as ASCII instead of binary");
  return tool.Run(argc, argv, [&] {
    tools::ApplyGlobalOptFlags(flags, &o);
    o.solve.threads = tool.threads();
    if (!tool.quiet()) o.solve.progress_label = "global LM";
    o.Check();
    JVL_CHECK(map_voxel == 0 || (map_voxel >= 0.01 && map_voxel <= 100),
              "--map-voxel must be 0 (every point) or in [0.01, 100] m, got " << map_voxel);
    JVL_CHECK(flags.no_direction || !directions_path.empty(),
              "--directions is required unless --no-direction is given");
    // The artifacts are released once the problem input is assembled (the largest parts are
    // moved into it), so they do not add to the peak memory of the solve.
    mapping::GlobalMapInput input;
    Trajectory prior;
    const Timer reading;
    {
      tool.AddInput(visual_path);
      // Positions and octaves of the keypoints only: the descriptors are not used here.
      const auto visual = io::ReadVisualMap(visual_path, io::VisualMapParts::kWithoutDescriptors);
      JVL_CHECK(!visual.keyframes.empty(), visual_path << ": no keyframes (nothing to optimise)");
      tool.AddInput(local_path);
      auto local = mapping::ReadStoredLocalMap(local_path);
      JVL_CHECK(local.keyframes.frames == visual.keyframes.frames,
                local_path << " and " << visual_path << " have different keyframes ("
                           << local.keyframes.size() << " vs " << visual.keyframes.size()
                           << "): local_map must have run on this visual artifact");
      io::WarnIfCovisibilitySplit(visual, visual_path);
      // Pixels of one artifact must be of the camera the visual map was built from.
      auto same_camera = [&](const CameraChoice& c, const std::string& path, const char* what) {
        JVL_CHECK(c.index == visual.camera_choice.index,
                  path << ": " << what << " are pixels of camera " << c.index << ", but "
                       << visual_path << " was built from camera " << visual.camera_choice.index
                       << " (run the image stages with the same --camera)");
      };
      io::DirectionsData directions;
      if (!directions_path.empty()) {
        directions = io::ReadDirectionsArtifact(directions_path);
        tool.AddInput(directions_path);
        if (!directions.associations.empty())
          same_camera(directions.camera_choice, directions_path, "its vanishing points");
        if (!flags.no_direction && directions.associations.empty()) {
          spdlog::warn("{}: no direction prior (no associated VP); optimising without e_D",
                       directions_path);
        }
      }
      prior = local.prior.empty() ? visual.prior : local.prior;
      if (!prior_path.empty()) {
        prior = io::ReadTrajectory(prior_path);
        tool.AddInput(prior_path);
      }
      JVL_CHECK(!prior.empty(), "no prior trajectory: pass --prior");
      Trajectory odometry = prior;
      std::vector<double> conditioning;
      if (!odometry_path.empty()) {
        odometry = io::ReadTrajectory(odometry_path);
        conditioning = io::ReadOdometryConditioning(odometry_path);
        tool.AddInput(odometry_path);
      } else if (!prior_path.empty()) {
        conditioning = io::ReadOdometryConditioning(prior_path);
      }
      if (o.use_odometry && o.odometry_conditioning && conditioning.empty())
        spdlog::info(
            "odometry term: no lidar_odom artifact given (--odometry, or --prior); every frame "
            "gets the drive's sigma (no registration conditioning)");
      o.joint.octave_scale_factor = visual.scale_factor;
      input = mapping::AssembleGlobalInput(visual, std::move(local),
                                           directions_path.empty() ? nullptr : &directions);
      if (o.use_odometry) {
        input.odometry = std::move(odometry);
        input.odometry_conditioning = std::move(conditioning);
      }
      if (!loops_path.empty()) {
        tool.AddInput(loops_path);
        // A loop end that is not a keyframe moves to the nearest keyframe within
        // kLoopSnapFrames frames; the prior's motion between the two carries the relative pose.
        constexpr int64_t kLoopSnapFrames = 5;
        const auto nearest = [&](int64_t frame) -> std::optional<size_t> {
          const auto& f = input.keyframes.frames;
          const auto it = std::lower_bound(f.begin(), f.end(), frame);
          std::optional<size_t> best;
          for (auto c = it == f.begin() ? it : std::prev(it); c != f.end() && c <= it; ++c) {
            if (std::abs(*c - frame) > kLoopSnapFrames) continue;
            if (!best || std::abs(*c - frame) < std::abs(f[*best] - frame))
              best = static_cast<size_t>(c - f.begin());
          }
          return best;
        };
        int64_t accepted = 0, unplaced = 0;
        const io::LoopsData loops_data = io::ReadLoopsArtifact(loops_path);
        for (const io::LoopRecord& r : loops_data.loops)
          if (r.status == 0 && !r.points.empty())
            same_camera(loops_data.camera_choice, loops_path, "its loop points");
        for (const io::LoopRecord& r : loops_data.loops) {
          if (r.status != 0) continue;
          ++accepted;
          const auto q = nearest(r.query), m = nearest(r.match);
          const auto pq = prior.IndexOf(r.query), pm = prior.IndexOf(r.match);
          if (!q || !m || !pq || !pm || *m >= *q) {
            ++unplaced;
            continue;
          }
          const auto pq2 = prior.IndexOf(input.keyframes.frames[*q]);
          const auto pm2 = prior.IndexOf(input.keyframes.frames[*m]);
          if (!pq2 || !pm2) {
            ++unplaced;
            continue;
          }
          const auto& w = prior.world_from_cam;
          const Rigid3d rel =
              w[*pm2].Inverse() * w[*pm] * r.match_from_query * w[*pq].Inverse() * w[*pq2];
          mapping::LoopConstraint loop{static_cast<int64_t>(*q), static_cast<int64_t>(*m), rel, {}};
          // The image points hold only where both ends are keyframes themselves.
          if (input.keyframes.frames[*q] == r.query && input.keyframes.frames[*m] == r.match) {
            for (const io::LoopPointRecord& p : r.points)
              loop.points.push_back(
                  {p.p_match, p.match_uv, p.query_uv, p.match_octave, p.query_octave});
          }
          input.loops.push_back(loop);
        }
        if (unplaced > 0) {
          spdlog::warn(
              "{}: {} of {} accepted loops have an end more than {} frames from a keyframe of "
              "{} or outside the prior (left out)",
              loops_path, unplaced, accepted, kLoopSnapFrames, local_path);
        }
        if (o.use_loops) spdlog::info("{}: {} loops", loops_path, input.loops.size());
      }
      if (!vps_path.empty() && !flags.no_direction && o.use_vertical) {
        tool.AddInput(vps_path);
        for (const io::VpRecord& v : io::ReadVpsArtifact(vps_path).vps)
          input.vp_rays.push_back({v.frame, v.direction});
      }
    }
    // e_M's sigma is per frame of a 10 Hz drive (the rate of the KITTI ground truth it comes
    // from); at another rate the car's acceleration per frame scales with (interval / 0.1 s)^1.5.
    if (o.use_motion && prior.has_timestamps() && prior.size() >= 2) {
      std::vector<double> dt;
      for (size_t i = 1; i < prior.size(); ++i)
        if (prior.frames[i] == prior.frames[i - 1] + 1)
          dt.push_back(prior.timestamps[i] - prior.timestamps[i - 1]);
      const double interval = dt.empty() ? 0.1 : Median(dt);
      if (interval > 0 && (interval < 0.08 || interval > 0.125))
        spdlog::warn(
            "the prior's frames are {:.3f} s apart; the motion term's --motion-sigma is per frame "
            "at 10 Hz: for this rate scale it by {:.2f} (docs/global_opt.md \"Motion term\")",
            interval, std::pow(interval / 0.1, 1.5));
    }
    ReleaseFreeHeapMemory();  // what reading the artifacts allocated and freed (core/memory.h)
    spdlog::debug("artifacts read and assembled in {:.1f} s", reading.ElapsedSeconds());
    const auto result = mapping::OptimizeGlobal(std::move(input), o);
    const Timer writing;
    std::map<int64_t, Rigid3d> kf;
    for (size_t i = 0; i < result.keyframes.size(); ++i)
      kf[result.keyframes.frames[i]] = result.keyframes.world_from_cam[i];
    io::GlobalData out;
    out.keyframes = result.keyframes;
    int64_t bridged = 0;
    out.trajectory = optim::InterpolateFullRate(prior, kf, 5.0, &bridged);
    if (bridged > 0) {
      spdlog::info(
          "full-rate trajectory: {} keyframe interval(s) where the prior's motion "
          "disagrees with the optimised keyframes (a step inside) take the optimised "
          "poses' geodesic interpolation",
          bridged);
    }
    out.prior = prior;
    out.stats = mapping::GlobalStatsJson(result, o);
    io::WriteGlobalArtifact(output, out, tool.MakeProvenance());
    if (!kitti.empty()) io::WriteTrajectoryKitti(kitti, out.trajectory);
    if (!map_path.empty()) {
      // OptimizeGlobal released its scans before the last solve; they are read again.
      io::WritePly(
          map_path,
          mapping::AccumulateMap(result.keyframes, mapping::ReadStoredScans(local_path), map_voxel),
          !map_ascii);
    }
    spdlog::debug("outputs written in {:.1f} s", writing.ElapsedSeconds());
    const auto& s = result.solve;
    spdlog::info(
        "{} keyframes, {} frames: {} visual, {} IMLS ({} saved + {} fresh, {} keyframe-pair "
        "blocks), {} direction "
        "residuals ({} skipped: not keyframes, {} at infinity, {} refit outliers; sigma {:.2f} "
        "px); weights alpha {:.3g} beta {:.3g} "
        "gamma {:.3g}; cost {:.6g} -> {:.6g}; {} rounds, {} iterations ({:.2f} s IMLS "
        "traversal, {:.2f} s total)",
        result.keyframes.size(), out.trajectory.size(), s.before.visual.count, s.before.imls.count,
        result.saved_imls, result.fresh_imls, s.imls_blocks, result.directions_used,
        result.directions_not_keyframe, result.directions_at_infinity, result.directions_outliers,
        result.direction_sigma_px, s.weights.alpha, s.weights.beta, s.weights.gamma, s.before.total,
        s.after.total, result.rounds, result.total_iterations, result.traversal_time_s,
        result.total_time_s);
  });
}
