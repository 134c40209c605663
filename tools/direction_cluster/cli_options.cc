#include "cli_options.h"

#include "app/option_group.h"

namespace jvl::tools {

void AddDirectionClusterFlags(app::Tool& tool, direction::DirectionClusterOptions* o,
                              std::string* up) {
  app::OptionGroup method(tool, "Method");
  method.Add("--v-interval", o->v_interval,
             "V_interval: keep associations of a cluster >= K frames apart (0 = all)");
  method.Add("--up", *up, "World up vector x,y,z, or auto = -y of the first prior camera");
  method.Add("--th-f", o->forward_max_angle_deg,
             "Th_f: max angle (deg) between a VP's ground projection and the motion");
  method.Add("--forward-baseline", o->forward_baseline_m,
             "Path length (m) over which the motion direction is measured");
  method.Add("--min-ground", o->min_ground_component, "Min ground component of a VP direction");
  method.Flag("--use-forward-flag", o->use_forward_flag,
              "Also require vp_detect's is_forward flag");
  method.Add("--bandwidth1", o->bandwidth1_deg, "First-level mean-shift bandwidth (deg)");
  method.Add("--max-member-angle", o->max_member_angle_deg,
             "Max angle (deg) of a member to its first-level mode");
  method.Add("--slope-subset", o->slope_subset_deg, "Slope gap (deg) that separates subsets");
  method.Add("--max-sweep", o->max_sweep_deg,
             "A direction prior whose VP headings turn by more than this along its path (deg) "
             "at more than --max-turn-rate is a bend and dropped");
  method.Add("--max-turn-rate", o->max_turn_rate_deg_per_100m,
             "Turn rate (deg/100 m) above which a turning direction prior is a bend; the "
             "prior's own yaw drift turns far slower");
  method.Add("--th-delta", o->max_std_deg, "Th_delta: max cluster std (deg)");
  method.Add("--th-n", o->min_size, "Th_n: min cluster size");
  method.Add("--th-m", o->clusters_per_window, "Th_m: clusters kept per window");
  method.Add("--th-l", o->window_length_m, "Th_l: window length (m of path)");
  method.Add("--bandwidth2", o->bandwidth2_m, "Second-level mean-shift bandwidth (m)");
  method.Add("--link-gap", o->link_gap_m,
             "Join second-level sub-clusters closer than this along the path (m, 0 = off)");
}

}  // namespace jvl::tools
