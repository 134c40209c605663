#include "cli_options.h"

namespace jvl::tools {

void AddVisualMapFlags(CLI::App& cli, mapping::VisualMapOptions* o) {
  auto add = [&cli](const char* name, auto& value, const char* help) {
    cli.add_option(name, value, help)->capture_default_str()->group("Method");
  };
  add("--orb-features", o->orb.num_features, "ORB features per image");
  add("--orb-levels", o->orb.num_levels, "ORB pyramid levels");
  add("--orb-scale", o->orb.scale_factor, "ORB pyramid scale factor");
  add("--fast-threshold", o->orb.fast_threshold, "FAST threshold tried first in each cell");
  add("--fast-min-threshold", o->orb.fast_min_threshold, "FAST threshold for cells with none");
  add("--orb-cell", o->orb.cell_size, "Grid cell size (px) spreading the features");
  add("--window", o->projection.window_px, "Projection search radius (px at level 0)");
  add("--projection-max-distance", o->projection.max_distance,
      "Hamming threshold, projection matching");
  add("--projection-ratio", o->projection.ratio, "Ratio test, projection matching");
  add("--epipolar-max-distance", o->epipolar.max_distance, "Hamming threshold, epipolar matching");
  add("--epipolar-ratio", o->epipolar.ratio, "Ratio test, epipolar matching");
  add("--epipolar-chi2", o->epipolar.epipolar_chi2, "Epipolar distance bound (x level variance)");
  add("--epipolar-max-octave-diff", o->epipolar.max_octave_difference,
      "Largest octave difference of epipolar candidates");
  add("--epipolar-min-depth", o->epipolar.min_depth, "Nearest depth (m) searched along the line");
  add("--min-parallax-cos", o->triangulation.max_cos_parallax,
      "Triangulate only if the cosine of the ray angle is below this");
  add("--reprojection-chi2", o->triangulation.max_reprojection_chi2,
      "Reprojection bound for new points (x level variance)");
  add("--kf-min-frames", o->keyframe.min_frames_between, "Frames between keyframes (C2)");
  add("--kf-min-tracked", o->keyframe.min_tracked, "Tracked points of C3");
  add("--kf-ref-ratio", o->keyframe.reference_ratio, "Ratio to the reference keyframe (C4)");
  add("--local-keyframes", o->local_keyframes, "Keyframes whose points are tracked and fused");
  add("--triangulation-neighbors", o->triangulation_neighbors,
      "Recent keyframes matched with a new keyframe");
  add("--min-baseline-ratio", o->min_baseline_ratio, "Baseline / median depth to triangulate");
  add("--min-view-cos", o->min_view_cos, "Cosine limit to a point's mean viewing direction");
  add("--min-observations", o->min_observations, "Culling: keyframes observing a point");
  add("--min-found-ratio", o->min_found_ratio, "Culling: found / visible ratio");
  add("--final-chi2", o->max_final_chi2, "Final outlier bound (x level variance)");
  add("--track-chi2", o->track_chi2, "Tracking reprojection gate (x level variance, 0: off)");
  add("--min-covisibility", o->min_covisibility_weight, "Covisibility edge weight threshold");
  cli.add_option("--refine-points", o->refine_points, "Structure-only point refinement")
      ->capture_default_str()
      ->group("Method");
  cli.add_option("--align-patches", o->align_patches,
                 "Align observations to the point's reference patch (sub-pixel)")
      ->capture_default_str()
      ->group("Method");
  cli.add_option("--require-alignment", o->require_alignment,
                 "Drop observations whose patch does not align")
      ->capture_default_str()
      ->group("Method");
  add("--align-min-ncc", o->align.min_ncc, "Correlation required of an aligned patch");
  cli.add_option("--align-affine", o->align.affine,
                 "Fit a 2 x 2 warp of the patch as well (oblique surfaces)")
      ->capture_default_str()
      ->group("Method");
  add("--align-warp-prior", o->align.warp_prior, "Pull of the warp towards the predicted scale");
  cli.add_option("--refine-on-insert", o->refine_on_insert,
                 "Refine points and drop outlier observations as keyframes are added")
      ->capture_default_str()
      ->group("Method");
}

}  // namespace jvl::tools
