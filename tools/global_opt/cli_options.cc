#include "cli_options.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include "app/option_group.h"
#include "core/check.h"

namespace jvl::tools {

void AddGlobalOptFlags(app::Tool& tool, mapping::GlobalMappingOptions* o, GlobalOptFlags* f) {
  f->direction_source = mapping::ToString(o->direction_source);
  app::OptionGroup method(tool, "Method");
  method.Add("--alpha", o->joint.alpha, "Weight of the visual term");
  method.Add("--beta", o->joint.beta, "Weight of e_L (<= 0: from the residual counts)");
  method.Add("--gamma", o->joint.gamma,
             "Weight of the whitened e_D (1: each residual one measurement of its measured "
             "noise; <= 0: the paper's rule from the residual counts, N_V / N_D)");
  method.Flag("--no-direction", f->no_direction, "Ablation: no direction projection residuals");
  method.Flag("--no-saved-imls", f->no_saved_imls, "Leave out the saved correspondence set L");
  method.Flag("--no-fresh-imls", f->no_fresh_imls, "Leave out the fresh IMLS traversal");
  method.Add("--scan-map-size,--scan-map-frames", o->traversal.scan_map_size,
             "N: model scans within N frames before each keyframe (the paper's N)");
  method.Add("--samples-per-list", o->traversal.association.samples_per_list,
             "IMLS-SLAM samples per list (9 lists) in the fresh traversal");
  method.Add("--max-iterations", o->solve.max_iterations,
             "Levenberg-Marquardt iterations per round");
  method.Add("--function-tolerance", o->solve.function_tolerance,
             "LM stops when an iteration lowers the cost by less than this fraction");
  method.Add("--rounds", "rounds", o->rounds,
             "Rounds of (fresh IMLS traversal at the current poses, LM solve); with "
             "--round-tolerance, the most rounds");
  method.Add("--round-tolerance", "round_tolerance_m", o->round_tolerance_m,
             "Stop the rounds once one changed no keyframe-to-keyframe motion by more than "
             "this (m; 0 = always --rounds rounds)");
  method.Add("--first-direction-round", o->first_direction_round,
             "Rounds before this one run without e_D (warm start; 0 = e_D in every round)");
  method
      .Add("--direction-source", f->direction_source,
           "d_w of e_D: 'free' re-estimates each cluster's direction from the rotations "
           "after the warm-start round (robust mean, outlier VPs dropped) and optimises it "
           "with the poses; 'refit' keeps that re-estimate fixed; 'prior' uses "
           "direction_cluster's d_w as is (the paper)")
      ->check(CLI::IsMember({"free", "refit", "prior"}));
  method.Add("--refit-outlier-deg", o->refit_outlier_deg,
             "refit/free: smallest gate (deg) for VPs far from their cluster's direction");
  method.Add("--direction-sigma", "direction_sigma_px", o->direction_sigma_px,
             "sigma of e_D in pixels (<= 0: estimated from the VP residuals when e_D enters)");
  method.Flag("--direction-sigma-per-axis", o->direction_sigma_per_axis,
              "Estimate e_D's sigma per image axis (u, v): on sloped roads the VP row also "
              "follows the grade ahead, so its part weighs less");
  method.Flag("!--no-vertical", o->use_vertical,
              "Leave out the vertical direction prior of --vps (ablation)");
  method.Add("--vertical-max-deg", o->vertical_max_deg,
             "Vertical prior: a VP is a candidate within this angle of the world's up (deg)");
  method.Add("--vertical-bias", o->vertical_bias_deg,
             "Vertical prior: the slow bias of the vertical VPs (deg). Left out where they "
             "disagree with the poses by no more than this at low frequency, weighted by the "
             "excess otherwise (0: sigma from the VPs' spread)");
  method.Add("--vertical-bias-per-white", o->vertical_bias_per_white,
             "Vertical prior: the slow bias is at least this share of the VPs' white spread");
  method.Add("--vertical-window", o->vertical_half_window,
             "Vertical prior: half window (frames) of the low-frequency disagreement");
  method.Add("--vertical-sigma", o->vertical_sigma_deg,
             "Vertical prior: its sigma in degrees as given (0: from --vertical-bias)");
  method.Flag("!--no-loops", o->use_loops, "Leave out the loops of --loops (ablation)");
  method.Flag("--loop-points,!--no-loop-points", o->use_loop_points,
              "Put the visual loops' points (PnP inliers) into the visual term, observed by both "
              "ends; weak ones left out (--no-loop-points: the loops' correction and IMLS term "
              "only)");
  method.Add("--imls-pair-noise-max", o->joint.imls_pair_noise_max,
             "e_L's noise per keyframe pair: a pair whose RMS point-to-surface residual at the "
             "round's starting poses is f times the median pair's gets the sigma times min(f, "
             "this), so rough surfaces (vegetation) weigh less (<= 1: one sigma for all pairs)");
  method.Flag("!--no-odometry", o->use_odometry,
              "Leave out the odometry term e_O (the paper's energy; ablation)");
  method.Add("--odometry-gate", o->odometry_gate,
             "Leave out odometry pairs whose whitened e_O exceeds this at the first round's "
             "solution (the odometry's steps; <= 0: keep all)");
  method.Flag("!--no-odometry-conditioning", o->odometry_conditioning,
              "Give every odometry frame e_O's sigma of the drive, also where the odometry "
              "artifact says its registration was weakly conditioned (ablation)");
  method.Add("--odometry-max-inflation", o->odometry_max_inflation,
             "Largest factor on a weakly conditioned (or unregistered) frame's e_O sigma, "
             "sqrt(median / own smallest eigenvalue of the registration), >= 1");
  method.Add("--odometry-local-window", o->odometry_local_window,
             "e_O's local noise: pairs on either side whose median whitened residual (first "
             "round, relative to the drive's median) multiplies a pair's sigma (0: off)");
  method.Add("--odometry-local-max", o->odometry_local_max,
             "Largest factor of e_O's local noise on a pair's sigma, >= 1");
  method.Add("--odometry-cauchy", o->joint.relative_cauchy,
             "Cauchy kernel scale of e_O on its whitened norm (<= 0: none)");
  method.Flag("!--no-surface", o->use_surface,
              "Leave out the surface term e_S (visual map points on their keyframe's LiDAR "
              "surface; beyond the paper; ablation)");
  method.Add("--surface-sigma", "surface_sigma_m", o->joint.surface_sigma_m,
             "e_S's sigma: a map point's distance to the LiDAR surface, m");
  method.Add("--surface-max-distance", "surface_max_distance_m", o->surface_max_distance_m,
             "e_S: a map point farther than this (m) from its keyframe's surface is left out");
  method.Add("--surface-cauchy", "surface_cauchy", o->joint.surface_cauchy,
             "Cauchy kernel scale of e_S on its whitened residual (<= 0: none)");
  method.Flag("!--no-motion", o->use_motion,
              "Leave out the motion term e_M (the car's acceleration between three consecutive "
              "keyframes; beyond the paper; ablation)");
  f->motion_sigma_mm = {1e3 * o->motion_sigma_m.x(), 1e3 * o->motion_sigma_m.y(),
                        1e3 * o->motion_sigma_m.z()};
  method
      .Add("--motion-sigma", f->motion_sigma_mm,
           "e_M's sigma: change of the body-frame velocity per frame, mm, camera x y z "
           "(right, down, forward; default: the real KITTI ground truth of sequences 09/10)")
      ->expected(3)
      ->check(CLI::Validator(
          [](std::string& v) {
            char* end = nullptr;
            const double x = std::strtod(v.c_str(), &end);
            return end != v.c_str() && *end == '\0' && std::isfinite(x) && x > 0
                       ? std::string()
                       : "'" + v + "' is not a sigma > 0 in mm";
          },
          "MM>0"));
  method.Add("--motion-cauchy", o->joint.motion_cauchy,
             "Cauchy kernel scale of e_M on its whitened norm (<= 0: none)");
  method.Add("--direction-huber", o->joint.direction_huber,
             "Huber threshold of e_D in sigmas (<= 0: none)");
  method.Add("--visual-gate", o->joint.visual_gate_chi2,
             "Leave out visual observations whose squared reprojection error in sigmas "
             "exceeds this at the start of a round, and free map points left with < 2 "
             "(<= 0: keep all; with --max-point-sigma it makes free map points converge on long "
             "sequences, docs/global_opt.md)");
  method.Add("--max-point-sigma", o->joint.max_point_sigma_ratio,
             "Hold free map points constant whose position sigma at the start of a round "
             "exceeds this fraction of their distance to the nearest observing camera "
             "(<= 0: all free)");
  method.Flag("--drop-weak-points", o->joint.drop_weak_points,
              "Leave the points of --max-point-sigma out (with their observations) instead of "
              "holding them constant");
  method.Add("--points-per-keyframe", o->points_per_keyframe,
             "Visual term on a subset of the map points (longest tracks first) that keeps at "
             "least this many observations per keyframe (0 = all points)");
  method.Flag("!--fixed-map-points", o->joint.optimize_map_points,
              "Keep the map points at their local-mapping positions (Eq. 8 optimises poses only; "
              "several times faster on long sequences, see docs/global_opt.md)");
}

void ApplyGlobalOptFlags(const GlobalOptFlags& f, mapping::GlobalMappingOptions* o) {
  o->use_directions = !f.no_direction;
  using Source = mapping::GlobalMappingOptions::DirectionSource;
  o->direction_source = f.direction_source == "prior"   ? Source::kPrior
                        : f.direction_source == "refit" ? Source::kRefit
                                                        : Source::kFree;
  o->use_saved_imls = !f.no_saved_imls;
  o->fresh_traversal = !f.no_fresh_imls;
  JVL_CHECK(f.motion_sigma_mm.size() == 3,
            "--motion-sigma takes three values (x y z, mm) once, got " << f.motion_sigma_mm.size());
  o->motion_sigma_m =
      1e-3 * Eigen::Vector3d(f.motion_sigma_mm[0], f.motion_sigma_mm[1], f.motion_sigma_mm[2]);
}

}  // namespace jvl::tools
