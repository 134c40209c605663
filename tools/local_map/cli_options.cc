#include "cli_options.h"

#include <string>

#include "app/option_group.h"
#include "io/dataset.h"

namespace jvl::tools {

void AddLocalMapFlags(app::Tool& tool, mapping::LocalMappingOptions* o, mapping::ScanOptions* s,
                      std::string* vertical_correction) {
  app::OptionGroup method(tool, "Method");
  method.Add("--scan-map-size", o->scan_map_size,
             "N: S_model holds the keyframes within N frames of K_n (Sec. 4.2 step 2)");
  method.Add("--min-model-keyframes", o->min_model_keyframes,
             "S_model keeps at least this many previous keyframes (0 = literal rule)");
  method.Add("--association-rounds", o->association_rounds,
             "Associate + solve rounds per keyframe (1 = the paper)");
  method.Add("--min-point-observations", o->min_point_observations,
             "Map points need this many observations among K_local");
  method.Flag("--propagate,!--no-propagate", o->propagate_corrections,
              "Next keyframe starts from the refined previous one + prior motion");
  method.Add("--alpha", o->joint.alpha, "Weight of the visual term (Eq. 4)");
  method.Add("--beta", o->joint.beta,
             "Weight of the point-to-IMLS term (<= 0: N_visual / N_imls per keyframe)");
  method.Add("--imls-sigma", o->joint.imls_sigma_m, "Noise of e_L (m)");
  method.Add("--visual-huber", o->joint.visual_huber, "Huber threshold of e_V (whitened)");

  app::OptionGroup imls(tool, "IMLS");
  imls.Add("--samples-per-list", o->association.samples_per_list,
           "s: points per sampling list (x9)");
  imls.Add("--imls-h", "kernel_h", o->association.kernel_h, "Kernel width h of Eq. (2) (m)");
  imls.Add("--imls-radius", "search_radius", o->association.search_radius,
           "Neighbourhood radius r (m)");
  imls.Add("--imls-max-distance", "max_distance", o->association.max_distance,
           "Reject samples with |I(p_x)| above this (m)");

  app::OptionGroup scan(tool, "Scans");
  scan.Add("--min-range", s->preprocess.min_range, "Drop points closer than this (m)");
  scan.Add("--vertical-correction", "vertical_correction_deg", *vertical_correction,
           io::kVerticalCorrectionHelp);
  scan.Add("--voxel-size", s->preprocess.voxel_size, "Voxel downsampling of each scan (m)");
  scan.Add("--scan-voxel", "stored_voxel", s->stored_voxel,
           "Voxel of the scans stored in the artifact (m)");
  scan.Add("--normal-neighbors", s->surface.normal_neighbors, "k nearest points of the normal PCA");
  scan.Add("--normal-radius", s->surface.normal_radius, "Max neighbour distance of the PCA (m)");

  app::OptionGroup solver(tool, "Solver");
  solver.Add("--max-iterations", o->solve.max_iterations,
             "Levenberg-Marquardt iterations per solve");
  solver.Add("--function-tolerance", o->solve.function_tolerance, "Ceres function tolerance");
  solver.Flag("--schur-lm,!--no-schur-lm", o->solve.schur_lm,
              "Solve each window with this project's Levenberg-Marquardt (SCHUR_LM, "
              "docs/optimization.md); --no-schur-lm: Ceres' DENSE_SCHUR, the same steps in "
              "1.4-1.9x the time (measured drives), for comparison");
}

}  // namespace jvl::tools
