#include "sim/lidar.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "sim/random.h"
#include "sim/shading.h"

namespace jvl::sim {

constexpr double kPi = 3.14159265358979323846;

void LidarOptions::Check() const {
  JVL_CHECK(beams >= 2 && beams <= 256, "beams must be in [2, 256], got " << beams);
  JVL_CHECK(elevation_max_deg > elevation_min_deg,
            "elevation_max_deg must exceed elevation_min_deg");
  JVL_CHECK(beam_table != BeamTable::kKitti04 || beams == 64,
            "the kitti04 beam table has 64 beams, got beams = " << beams);
  JVL_CHECK(azimuth_steps >= 16, "azimuth_steps must be >= 16, got " << azimuth_steps);
  JVL_CHECK(
      max_range > min_range && min_range >= 0,
      "min_range must be >= 0 and below max_range, got " << min_range << " and " << max_range);
  JVL_CHECK(range_noise >= 0, "range_noise must be >= 0, got " << range_noise);
  JVL_CHECK(std::isfinite(elevation_bias_deg) && std::abs(elevation_bias_deg) <= 2,
            "elevation_bias_deg must be in [-2, 2] deg, got " << elevation_bias_deg);
  JVL_CHECK(dropout >= 0 && dropout < 1, "dropout must be in [0, 1), got " << dropout);
  JVL_CHECK(glass_dropout >= 0 && glass_dropout <= 1,
            "glass_dropout must be in [0, 1], got " << glass_dropout);
  JVL_CHECK(sweep_period > 0, "sweep_period must be > 0, got " << sweep_period);
}

namespace {

// Median elevation (deg) of each ring of the KITTI odometry 04 excerpt's 51 scans, highest ring
// first: a ring is one turn of the azimuth from a scan's first point, the elevation that of the
// point seen from the sensor origin (as a user of the .bin files sees it, with the sensor's own
// per-laser corrections and its elevation error in it).
constexpr double kKitti04RingElevationsDeg[64] = {
    2.366,   2.001,   1.737,   1.284,   0.995,   0.596,   0.344,   -0.031,  -0.390,  -0.792,
    -1.085,  -1.413,  -1.773,  -2.110,  -2.450,  -2.797,  -3.107,  -3.480,  -3.735,  -4.085,
    -4.381,  -4.699,  -5.025,  -5.340,  -5.688,  -5.999,  -6.287,  -6.546,  -6.902,  -7.242,
    -7.465,  -7.830,  -8.408,  -8.927,  -9.391,  -9.785,  -10.248, -10.855, -11.348, -11.768,
    -12.215, -12.635, -13.160, -13.682, -14.251, -14.679, -15.186, -15.571, -16.198, -16.737,
    -17.307, -17.767, -18.264, -18.691, -19.121, -19.691, -20.118, -20.789, -21.251, -21.672,
    -22.103, -22.734, -23.169, -23.696};
// The default elevation bias: kKitti04's beams are fired this much above the real rings.
constexpr double kKitti04BeamRaiseDeg = 0.12;

}  // namespace

std::vector<double> LidarOptions::ElevationsRad() const {
  if (beam_table == BeamTable::kKitti04) {
    std::vector<double> e;
    for (const double deg : kKitti04RingElevationsDeg)
      e.push_back((deg + kKitti04BeamRaiseDeg) * kPi / 180.0);
    return e;
  }
  // Split point of the two laser blocks scaled from the HDL-64E's -8.33 / -8.83 deg.
  const double span = elevation_max_deg - elevation_min_deg;
  const double upper_end = elevation_max_deg - span * (10.33 / 26.9);
  const double lower_start = elevation_max_deg - span * (10.83 / 26.9);
  const int upper = beams / 2, lower = beams - upper;
  std::vector<double> e;
  for (int i = 0; i < upper; ++i) {
    e.push_back(elevation_max_deg + (upper_end - elevation_max_deg) * i / std::max(1, upper - 1));
  }
  for (int i = 0; i < lower; ++i) {
    e.push_back(lower_start + (elevation_min_deg - lower_start) * i / std::max(1, lower - 1));
  }
  for (double& x : e) x *= kPi / 180.0;
  return e;
}

PointCloud SimulateScan(const Scene& scene, const RayCaster& caster, const Rigid3d& world_from_velo,
                        const std::vector<Box>& moving, const LidarOptions& options, uint64_t seed,
                        const SweepPose* sweep_pose) {
  const std::vector<double> elev = options.ElevationsRad();
  const int nb = static_cast<int>(elev.size()), na = options.azimuth_steps;
  std::vector<double> ce(nb), se(nb), ce_reported(nb), se_reported(nb);
  const double bias = options.elevation_bias_deg * kPi / 180.0;
  for (int b = 0; b < nb; ++b) {
    ce[b] = std::cos(elev[b]), se[b] = std::sin(elev[b]);
    ce_reported[b] = std::cos(elev[b] - bias), se_reported[b] = std::sin(elev[b] - bias);
  }
  // Per slot: point in the frame-time velodyne frame, intensity, and validity.
  std::vector<Eigen::Vector3f> pts(static_cast<size_t>(nb) * na);
  std::vector<float> inten(pts.size());
  std::vector<uint8_t> ok(pts.size(), 0);
  Rng rng(seed);
  const NormalTable normal;
  std::vector<int32_t> beam_hint(nb, -1);
  for (int a = 0; a < na; ++a) {
    const double az = kPi - 2 * kPi * a / na;  // Clockwise from behind.
    Rigid3d pose = world_from_velo;
    if (options.motion_distortion && sweep_pose != nullptr) {
      pose = (*sweep_pose)(options.sweep_period * (static_cast<double>(a) / na - 0.5));
    }
    const Eigen::Matrix3d R = pose.RotationMatrix();
    const Eigen::Vector3d o = pose.translation();
    const double ca = std::cos(az), sa = std::sin(az);
    for (int b = 0; b < nb; ++b) {
      const Eigen::Vector3d d_velo(ce[b] * ca, ce[b] * sa, se[b]);
      const Eigen::Vector3d d = R * d_velo;
      // Hinted by the beam's previous return (the caster's answer does not depend on it).
      Hit hit = caster.Intersect(o, d, 0.05, options.max_range, beam_hint[b]);
      if (hit.triangle >= 0) beam_hint[b] = hit.triangle;
      IntersectBoxes(moving, o, d, &hit);
      // Draw the random numbers for every slot so that the stream does not depend on hits.
      const double u_drop = rng.Uniform(), u_glass = rng.Uniform(), noise = normal.Sample(rng);
      const double n_int = normal.Sample(rng);
      if (!hit.valid() || hit.t < options.min_range || hit.t > options.max_range) continue;
      if (u_drop < options.dropout) continue;
      const Eigen::Vector3d p = o + hit.t * d;
      const Surface surf = ShadeSurface(scene, hit, p);
      if (surf.glass && u_glass < options.glass_dropout) continue;
      const double r = hit.t + options.range_noise * noise;
      const size_t k = static_cast<size_t>(b) * na + a;
      // The sensor reports the return in its own frame at firing time: with motion distortion
      // the scan is not compensated for the motion during the sweep (as raw KITTI scans).
      // (Along the beam as the sensor reports it: lower by the elevation bias, if any.)
      const Eigen::Vector3d d_reported(ce_reported[b] * ca, ce_reported[b] * sa, se_reported[b]);
      pts[k] = (r * d_reported).cast<float>();
      const double incidence = std::abs(hit.normal.dot(d));
      inten[k] = static_cast<float>(
          std::clamp(surf.reflectance * (0.45 + 0.55 * incidence) + 0.02 * n_int, 0.0, 0.99));
      ok[k] = 1;
    }
  }
  PointCloud cloud;
  for (size_t k = 0; k < pts.size(); ++k) {
    if (!ok[k]) continue;
    cloud.points.push_back(pts[k].cast<double>());
    cloud.intensity.push_back(inten[k]);
  }
  return cloud;
}

}  // namespace jvl::sim
