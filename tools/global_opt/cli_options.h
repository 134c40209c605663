// Command-line options of global_opt: the terms of Eq. (7), their weights, the rounds and the
// solver.
#pragma once

#include <string>
#include <vector>

#include "app/tool.h"
#include "mapping/global/global_mapping.h"

namespace jvl::tools {

// Switches that map onto GlobalMappingOptions only after parsing.
struct GlobalOptFlags {
  bool no_direction = false;            // --no-direction: the ablation without e_D
  bool no_saved_imls = false;           // --no-saved-imls
  bool no_fresh_imls = false;           // --no-fresh-imls
  std::string direction_source;         // free, refit or prior
  std::vector<double> motion_sigma_mm;  // --motion-sigma X Y Z
};

void AddGlobalOptFlags(app::Tool& tool, mapping::GlobalMappingOptions* options,
                       GlobalOptFlags* flags);
void ApplyGlobalOptFlags(const GlobalOptFlags& flags, mapping::GlobalMappingOptions* options);

}  // namespace jvl::tools
