#include "cli_options.h"

#include <string>

namespace jvl::tools {

void AddLocalMapFlags(CLI::App& cli, mapping::LocalMappingOptions* o, mapping::ScanOptions* s) {
  auto add = [&cli](const std::string& name, auto& value, const std::string& help,
                    const std::string& group) {
    cli.add_option(name, value, help)->capture_default_str()->group(group);
  };
  const std::string method = "Method";
  add("--scan-map-size", o->scan_map_size,
      "N: S_model holds the keyframes within N frames of K_n (Sec. 4.2 step 2)", method);
  add("--min-model-keyframes", o->min_model_keyframes,
      "S_model keeps at least this many previous keyframes (0 = literal rule)", method);
  add("--association-rounds", o->association_rounds,
      "Associate + solve rounds per keyframe (1 = the paper)", method);
  add("--min-point-observations", o->min_point_observations,
      "Map points need this many observations among K_local", method);
  cli.add_flag("--propagate,!--no-propagate", o->propagate_corrections,
               "Next keyframe starts from the refined previous one + prior motion")
      ->capture_default_str()
      ->group(method);
  add("--alpha", o->joint.alpha, "Weight of the visual term (Eq. 4)", method);
  add("--beta", o->joint.beta,
      "Weight of the point-to-IMLS term (<= 0: N_visual / N_imls per keyframe)", method);
  add("--imls-sigma", o->joint.imls_sigma_m, "Noise of e_L (m)", method);
  add("--visual-huber", o->joint.visual_huber, "Huber threshold of e_V (whitened)", method);

  const std::string imls = "IMLS";
  add("--samples-per-list", o->association.samples_per_list, "s: points per sampling list (x9)",
      imls);
  add("--imls-h", o->association.kernel_h, "Kernel width h of Eq. (2) (m)", imls);
  add("--imls-radius", o->association.search_radius, "Neighbourhood radius r (m)", imls);
  add("--imls-max-distance", o->association.max_distance,
      "Reject samples with |I(p_x)| above this (m)", imls);

  const std::string scan = "Scans";
  add("--min-range", s->preprocess.min_range, "Drop points closer than this (m)", scan);
  add("--voxel-size", s->preprocess.voxel_size, "Voxel downsampling of each scan (m)", scan);
  add("--scan-voxel", s->stored_voxel, "Voxel of the scans stored in the artifact (m)", scan);
  add("--normal-neighbors", s->surface.normal_neighbors, "k nearest points of the normal PCA",
      scan);
  add("--normal-radius", s->surface.normal_radius, "Max neighbour distance of the PCA (m)", scan);

  const std::string solver = "Solver";
  add("--max-iterations", o->solve.max_iterations, "Levenberg-Marquardt iterations per solve",
      solver);
  add("--function-tolerance", o->solve.function_tolerance, "Ceres function tolerance", solver);
}

}  // namespace jvl::tools
