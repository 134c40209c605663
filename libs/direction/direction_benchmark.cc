// ClusterDirections on a 5000-frame synthetic drive (budget: <= 5 s for 5000 frames).
#include <benchmark/benchmark.h>

#include "direction/direction_cluster.h"
#include "direction/synthetic_vps.h"

namespace jvl::direction {
namespace {

// 5000 poses 1 m apart: straight runs of 150-450 m joined by 90 deg turns of 40 m, with a
// slowly drifting prior (0.02 deg/frame yaw random walk).
struct Drive {
  Drive() {
    std::vector<testing::PathSegment> segments;
    double length = 0;
    for (int i = 0; length < 5000; ++i) {
      const double straight = std::min(150.0 + 100.0 * (i % 4), 5000 - length);
      segments.push_back({straight, 0});
      length += straight;
      if (length >= 5000) break;
      const double turn = std::min(40.0, 5000 - length);
      segments.push_back({turn, i % 3 == 2 ? -90.0 : 90.0});
      length += turn;
    }
    path = testing::MakePath(segments);
    vps = testing::SimulateVps(path, testing::KittiCamera(), {});
    std::vector<double> yaw;
    prior = testing::DriftPrior(path.truth, 0.02, 3, &yaw);
  }
  testing::SyntheticPath path;
  std::vector<VpObservation> vps;
  Trajectory prior;
};

void BM_ClusterDirections5000(benchmark::State& state) {
  const Drive drive;
  DirectionClusterResult r;
  for (auto _ : state) {
    r = ClusterDirections(drive.vps, drive.prior, testing::KittiCamera(), {});
    benchmark::DoNotOptimize(r);
  }
  state.counters["frames"] = double(drive.prior.size());
  state.counters["vps"] = double(drive.vps.size());
  state.counters["clusters"] = double(r.clusters.size());
  state.counters["associations"] = double(r.associations.size());
}
BENCHMARK(BM_ClusterDirections5000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace jvl::direction

BENCHMARK_MAIN();
