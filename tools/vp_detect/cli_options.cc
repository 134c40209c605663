#include "cli_options.h"

#include "app/option_group.h"

namespace jvl::tools {

void AddVpDetectFlags(app::Tool& tool, VpDetectRunOptions* run, std::string* detector) {
  LineSegmentOptions& seg = run->detect.segments;
  VpOptions& vp = run->detect.vp;
  app::OptionGroup method(tool, "Method");
  method.Add("--detector", *detector, "Line detector: fld or lsd");
  method.Add("--line-scale", "scale", seg.scale, "Resize factor before line detection");
  method.Add("--min-length", "min_length_px", seg.min_length_px,
             "Min segment length (px, full res)");
  method.Add("--canny-low", seg.canny_low, "FLD Canny low threshold");
  method.Add("--canny-high", seg.canny_high, "FLD Canny high threshold");
  method.Add("--max-vps", vp.max_vps, "Max VPs per image");
  method.Add("--inlier-threshold-deg", vp.inlier_threshold_deg, "Inlier angle (deg)");
  method.Add("--ransac-iterations", vp.ransac_iterations, "Segment pairs drawn per VP");
  method.Add("--seed", vp.seed, "RANSAC seed");
  method.Add("--min-inliers", vp.min_inliers, "Min inlier segments per VP");
  method.Add("--refine-iterations", vp.refine_iterations, "Least-squares refinement rounds");
  method.Add("--min-separation-deg", vp.min_separation_deg, "Min angle between VPs (deg)");
  method.Add("--forward-max-angle-deg", vp.forward_max_angle_deg,
             "Forward VP must lie within this angle of the optical axis (deg)");
}

}  // namespace jvl::tools
