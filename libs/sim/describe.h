// Summaries of a synthetic world: route statistics and the scene description written as
// sequences/NN/sim/scene.json (schema "sim_scene").
#pragma once

#include <nlohmann/json.hpp>

#include "sim/sequence.h"

namespace jvl::sim {

struct RouteSummary {
  double driven_length_m = 0;  // Along the ground-truth poses.
  double duration_s = 0;
  double min_speed = 0, max_speed = 0, mean_speed = 0;  // m/s between frames.
  int straights_100m = 0;                               // Straight pieces of >= 100 m fully driven.
  int turns = 0;                                        // Arc pieces fully driven.
  int sharp_turns = 0;                                  // Of which radius < 50 m.
};
RouteSummary SummarizeRoute(const World& world);

nlohmann::json DescribeScene(const World& world);

}  // namespace jvl::sim
