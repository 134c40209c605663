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
  // Pass 1: one ray through every pixel centre.
  cv::Mat radiance(camera.height, camera.width, CV_32F);
  cv::Mat surface(camera.height, camera.width, CV_32S);  // What the centre ray hits.
  Eigen::Vector3d dirs[8];
  Hit hits[8];
  for (int j = 0; j < camera.height; ++j) {
    float* row = radiance.ptr<float>(j);
    int32_t* id = surface.ptr<int32_t>(j);
    for (int i0 = 0; i0 < camera.width; i0 += 8) {
      const int n = std::min(8, camera.width - i0);
      for (int k = 0; k < n; ++k) {
        dirs[k] = (R * camera.Unproject(Eigen::Vector2d(i0 + k, j))).normalized();
      }
      caster.Intersect8(o, dirs, n, 0.05, options.max_range, hits);
      for (int k = 0; k < n; ++k) {
        IntersectBoxes(near, o, dirs[k], &hits[k]);
        row[i0 + k] = static_cast<float>(ShadeRay(scene, hits[k], o, dirs[k], sun, options));
        id[i0 + k] = hits[k].dynamic >= 0 ? -2 - hits[k].dynamic : hits[k].face;
      }
    }
  }
  const int ss = options.supersample;
  if (ss > 1) {
    // Pass 2: a pixel whose 3 x 3 neighbourhood sees another surface or differs by more than
    // supersample_contrast grey levels is replaced by the mean of ss x ss rays spread over its
    // area (the pixel integrates the light falling on it); elsewhere the centre ray stands for
    // the pixel.
    const cv::Mat centre = radiance.clone();
    const float contrast = static_cast<float>(options.supersample_contrast);
    const float weight = 1.0f / static_cast<float>(ss * ss);
    std::vector<int> columns;
    std::vector<Eigen::Vector2d> offsets;
    for (int sy = 0; sy < ss; ++sy) {
      for (int sx = 0; sx < ss; ++sx) {
        offsets.emplace_back((sx + 0.5) / ss - 0.5, (sy + 0.5) / ss - 0.5);
      }
    }
    for (int j = 0; j < camera.height; ++j) {
      columns.clear();
      for (int i = 0; i < camera.width; ++i) {
        const float c = centre.at<float>(j, i);
        const int32_t f = surface.at<int32_t>(j, i);
        bool refine = false;
        for (int y = std::max(0, j - 1); y <= std::min(camera.height - 1, j + 1) && !refine; ++y) {
          const float* cr = centre.ptr<float>(y);
          const int32_t* sr = surface.ptr<int32_t>(y);
          for (int x = std::max(0, i - 1); x <= std::min(camera.width - 1, i + 1); ++x) {
            if (sr[x] != f || std::abs(cr[x] - c) > contrast) {
              refine = true;
              break;
            }
          }
        }
        if (refine) columns.push_back(i);
      }
      // Sub-pixel rays of the marked pixels, eight at a time.
      float* row = radiance.ptr<float>(j);
      for (int i : columns) row[i] = 0;
      const int64_t total = static_cast<int64_t>(columns.size()) * ss * ss;
      int pixel[8];
      for (int64_t r0 = 0; r0 < total; r0 += 8) {
        const int n = static_cast<int>(std::min<int64_t>(8, total - r0));
        for (int k = 0; k < n; ++k) {
          const int64_t r = r0 + k;
          pixel[k] = columns[static_cast<size_t>(r / (ss * ss))];
          const Eigen::Vector2d& d = offsets[static_cast<size_t>(r % (ss * ss))];
          dirs[k] =
              (R * camera.Unproject(Eigen::Vector2d(pixel[k] + d.x(), j + d.y()))).normalized();
        }
        caster.Intersect8(o, dirs, n, 0.05, options.max_range, hits);
        for (int k = 0; k < n; ++k) {
          IntersectBoxes(near, o, dirs[k], &hits[k]);
          row[pixel[k]] +=
              weight * static_cast<float>(ShadeRay(scene, hits[k], o, dirs[k], sun, options));
        }
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
