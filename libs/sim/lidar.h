// Velodyne HDL-64E-like scan simulation: 64 beams from +2 to -24.9 deg elevation, one column
// of returns per azimuth step, ranges with Gaussian noise, random and glass dropouts.
#pragma once

#include <functional>
#include <vector>

#include "geometry/point_cloud.h"
#include "geometry/rigid3.h"
#include "sim/raycaster.h"
#include "sim/scene.h"

namespace jvl::sim {

// The beams' elevations. kNominal: the HDL-64E's two blocks of evenly spaced lasers between
// elevation_max_deg and elevation_min_deg. kKitti04: the median elevation of each of the 64
// rings of the real KITTI odometry 04 scans in ../shared/data (51 scans; 2.37 to -23.70 deg),
// raised by the default elevation bias (0.12 deg), so that at the default bias the simulated
// rings are reported at the real rings' elevations (docs/sim.md, `--lidar-beams`).
enum class BeamTable { kNominal, kKitti04 };

struct LidarOptions {
  int beams = 64;
  BeamTable beam_table = BeamTable::kNominal;
  double elevation_max_deg = 2.0;
  double elevation_min_deg = -24.9;
  int azimuth_steps = 2000;
  double max_range = 120.0;
  double min_range = 2.5;
  double range_noise = 0.02;       // Standard deviation (m).
  double dropout = 0.02;           // Probability of a missing return on any surface.
  double glass_dropout = 0.6;      // Probability of no return from a window pane.
  bool motion_distortion = false;  // Move the sensor during the sweep (like raw KITTI scans).
  double sweep_period = 0.1;       // s
  // Elevation error of the returns (deg): each is reported this much below the beam it was
  // fired along. The KITTI HDL-64E scans have such an error (IMLS-SLAM and CT-ICP turn every
  // point up by 0.22 deg; lidar_odom --vertical-correction does the same). The default, 0.12,
  // gives calib_check the pitch reading of KITTI 04's scans (+0.115 deg; docs/sim.md). 0: none.
  double elevation_bias_deg = 0.12;
  void Check() const;
  // Beam elevations (radians), highest first. The HDL-64E has two blocks of 32 lasers; the
  // upper block is denser (about 1/3 deg) than the lower one (about 1/2 deg).
  std::vector<double> ElevationsRad() const;
};

// Sensor pose at time offset tau (s) from the frame time, for motion distortion.
using SweepPose = std::function<Rigid3d(double tau)>;

// Returns points in the velodyne frame (at each firing's time: with motion distortion the
// sweep is not compensated), ordered ring by ring (highest beam
// first), azimuth from behind the car going clockwise as seen from above (as in KITTI).
// Intensity = reflectance x incidence term. `seed` selects the noise.
PointCloud SimulateScan(const Scene& scene, const RayCaster& caster, const Rigid3d& world_from_velo,
                        const std::vector<Box>& moving, const LidarOptions& options, uint64_t seed,
                        const SweepPose* sweep_pose = nullptr);

}  // namespace jvl::sim
