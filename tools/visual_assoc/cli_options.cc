#include "cli_options.h"

#include "app/option_group.h"

namespace jvl::tools {

void AddVisualMapFlags(app::Tool& tool, mapping::VisualMapOptions* o) {
  app::OptionGroup method(tool, "Method");
  method.Add("--orb-features", o->orb.num_features, "ORB features per image");
  method.Add("--orb-levels", o->orb.num_levels, "ORB pyramid levels");
  method.Add("--orb-scale", o->orb.scale_factor, "ORB pyramid scale factor");
  method.Add("--fast-threshold", o->orb.fast_threshold, "FAST threshold tried first in each cell");
  method.Add("--fast-min-threshold", o->orb.fast_min_threshold,
             "FAST threshold for cells with none");
  method.Add("--orb-cell", o->orb.cell_size, "Grid cell size (px) spreading the features");
  method.Add("--window", o->projection.window_px, "Projection search radius (px at level 0)");
  method.Add("--projection-max-distance", o->projection.max_distance,
             "Hamming threshold, projection matching");
  method.Add("--projection-ratio", o->projection.ratio, "Ratio test, projection matching");
  method.Add("--epipolar-max-distance", o->epipolar.max_distance,
             "Hamming threshold, epipolar matching");
  method.Add("--epipolar-ratio", o->epipolar.ratio, "Ratio test, epipolar matching");
  method.Add("--epipolar-chi2", o->epipolar.epipolar_chi2,
             "Epipolar distance bound (x level variance)");
  method.Add("--epipolar-max-octave-diff", o->epipolar.max_octave_difference,
             "Largest octave difference of epipolar candidates");
  method.Add("--epipolar-min-depth", o->epipolar.min_depth,
             "Nearest depth (m) searched along the line");
  method.Add("--min-parallax-cos", o->triangulation.max_cos_parallax,
             "Triangulate only if the cosine of the ray angle is below this");
  method.Add("--reprojection-chi2", o->triangulation.max_reprojection_chi2,
             "Reprojection bound for new points (x level variance)");
  method.Add("--kf-min-frames", o->keyframe.min_frames_between, "Frames between keyframes (C2)");
  method.Add("--kf-min-tracked", o->keyframe.min_tracked, "Tracked points of C3");
  method.Add("--kf-ref-ratio", o->keyframe.reference_ratio, "Ratio to the reference keyframe (C4)");
  method.Add("--local-keyframes", o->local_keyframes,
             "Keyframes whose points are tracked and fused");
  method.Add("--triangulation-neighbors", o->triangulation_neighbors,
             "Recent keyframes matched with a new keyframe");
  method.Add("--min-baseline-ratio", o->min_baseline_ratio,
             "Baseline / median depth to triangulate");
  method.Add("--min-view-cos", o->min_view_cos, "Cosine limit to a point's mean viewing direction");
  method.Add("--min-observations", o->min_observations, "Culling: keyframes observing a point");
  method.Add("--min-found-ratio", o->min_found_ratio, "Culling: found / visible ratio");
  method.Add("--final-chi2", o->max_final_chi2, "Final outlier bound (x level variance)");
  method.Add("--track-chi2", o->track_chi2,
             "Tracking reprojection gate (x level variance, 0: off)");
  method.Add("--min-covisibility", o->min_covisibility_weight,
             "Covisibility edge weight threshold");
  method.Add("--refine-points", o->refine_points, "Structure-only point refinement");
  method.Add("--align-patches", o->align_patches,
             "Align observations to the point's reference patch (sub-pixel)");
  method.Add("--require-alignment", o->require_alignment,
             "Drop observations whose patch does not align");
  method.Add("--align-min-ncc", o->align.min_ncc, "Correlation required of an aligned patch");
  method.Add("--align-affine", o->align.affine,
             "Fit a 2 x 2 warp of the patch as well (oblique surfaces)");
  method.Add("--align-warp-prior", o->align.warp_prior,
             "Pull of the warp towards the predicted scale");
  method.Add("--refine-on-insert", o->refine_on_insert,
             "Refine points and drop outlier observations as keyframes are added");
  method.Add("--track-pose", o->track_pose,
             "Refine each frame's pose from its matches where the prior's motion disagrees with "
             "them (a registration glitch); false: every frame at the prior's pose (the paper)");
  method.Add("--track-min-inliers", o->track_min_inliers,
             "Inliers a refined pose needs to be used");
  method.Add(
      "--track-min-rotation", o->track_min_rotation_deg,
      "A refinement replaces the prediction only if it turns it by more than this (deg) ...");
  method.Add("--track-min-translation", o->track_min_translation_m,
             "... or moves its camera centre by more than this (m)");
  method.Add("--track-max-rotation", o->track_max_rotation_deg,
             "Largest rotation (deg) a refinement may apply to the prediction");
  method.Add("--track-max-translation", o->track_max_translation_m,
             "Largest camera centre shift (m) a refinement may apply to the prediction");
  method.Add("--track-center-sigma", o->pose.center_sigma,
             "Sigma (m) tying the refined camera centre to the prediction (0: free)");
}

}  // namespace jvl::tools
