#include "sim/render.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "sim/random.h"
#include "sim/shading.h"

namespace jvl::sim {

void CameraOptions::Check() const {
  JVL_CHECK(pixel_noise >= 0, "pixel noise must be >= 0");
  JVL_CHECK(exposure_variation >= 0 && exposure_variation < 0.5,
            "exposure variation must be in [0, 0.5)");
  JVL_CHECK(blur_sigma >= 0 && blur_sigma < 5, "blur sigma must be in [0, 5)");
  JVL_CHECK(max_range > 1, "camera max range must exceed 1 m");
  JVL_CHECK(sun_direction.norm() > 0, "sun direction must be non-zero");
}

double ExposureGain(int64_t frame, double variation, uint64_t seed) {
  const double k = static_cast<double>(frame);
  const double p1 = 6.2832 * HashUnit(3, 1, seed), p2 = 6.2832 * HashUnit(3, 2, seed);
  const double slow =
      0.6 * std::sin(6.2832 * k / 157.0 + p1) + 0.4 * std::sin(6.2832 * k / 41.0 + p2);
  const double jitter = 0.15 * (2 * HashUnit(frame, 4, seed) - 1);
  return 1.0 + variation * (slow + jitter);
}

namespace {

// Radiance (grey level 0..255 before gain) along one ray.
double ShadeRay(const Scene& scene, const Hit& hit, const Eigen::Vector3d& o,
                const Eigen::Vector3d& d, const Eigen::Vector3d& sun, const CameraOptions& opt) {
  // Sky: brighter towards the horizon.
  const double sky = 255.0 * (0.93 - 0.12 * std::clamp(d.z(), 0.0, 1.0));
  if (!hit.valid()) return sky;
  const Eigen::Vector3d p = o + hit.t * d;
  const Surface s = ShadeSurface(scene, hit, p);
  const double light = 0.5 + 0.55 * std::max(0.0, hit.normal.dot(sun));
  const double value = 255.0 * s.albedo * light;
  if (hit.t <= opt.haze_start) return value;
  const double w = 1.0 - std::exp(-(hit.t - opt.haze_start) / 250.0);
  return value + w * (sky - value);
}

}  // namespace

cv::Mat RenderImage(const Scene& scene, const RayCaster& caster, const PinholeCamera& camera,
                    const Rigid3d& world_from_cam, const std::vector<Box>& moving, double gain,
                    uint64_t noise_seed, const CameraOptions& options) {
  camera.Check();
  const Eigen::Matrix3d R = world_from_cam.RotationMatrix();
  const Eigen::Vector3d o = world_from_cam.translation();
  const Eigen::Vector3d sun = options.sun_direction.normalized();
  std::vector<Box> near;
  for (const Box& b : moving) {
    if (b.size.x() > 0 && (b.center - o).norm() < 200) near.push_back(b);
  }
  cv::Mat radiance(camera.height, camera.width, CV_32F);
  Eigen::Vector3d dirs[8];
  Hit hits[8];
  for (int j = 0; j < camera.height; ++j) {
    float* row = radiance.ptr<float>(j);
    for (int i0 = 0; i0 < camera.width; i0 += 8) {
      const int n = std::min(8, camera.width - i0);
      for (int k = 0; k < n; ++k) {
        dirs[k] = (R * camera.Unproject(Eigen::Vector2d(i0 + k, j))).normalized();
      }
      caster.Intersect8(o, dirs, n, 0.05, options.max_range, hits);
      for (int k = 0; k < n; ++k) {
        IntersectBoxes(near, o, dirs[k], &hits[k]);
        row[i0 + k] = static_cast<float>(ShadeRay(scene, hits[k], o, dirs[k], sun, options));
      }
    }
  }
  if (options.blur_sigma > 0) {
    cv::GaussianBlur(radiance, radiance, cv::Size(0, 0), options.blur_sigma, options.blur_sigma,
                     cv::BORDER_REPLICATE);
  }
  cv::Mat image(camera.height, camera.width, CV_8U);
  Rng rng(noise_seed);
  const NormalTable normal;
  for (int j = 0; j < camera.height; ++j) {
    const float* in = radiance.ptr<float>(j);
    uint8_t* out = image.ptr<uint8_t>(j);
    for (int i = 0; i < camera.width; ++i) {
      const double v = in[i] * gain + options.pixel_noise * normal.Sample(rng);
      out[i] = static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L));
    }
  }
  return image;
}

}  // namespace jvl::sim
