#include "sim/render.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "core/check.h"
#include "sim/random.h"
#include "sim/shading.h"

namespace jvl::sim {

void CameraOptions::Check() const {
  JVL_CHECK(pixel_noise >= 0, "pixel_noise must be >= 0, got " << pixel_noise);
  JVL_CHECK(exposure_variation >= 0 && exposure_variation < 0.5,
            "exposure_variation must be in [0, 0.5), got " << exposure_variation);
  JVL_CHECK(blur_sigma >= 0 && blur_sigma < 5, "blur_sigma must be in [0, 5), got " << blur_sigma);
  JVL_CHECK(max_range > 1, "max_range must exceed 1 m, got " << max_range);
  JVL_CHECK(sun_direction.norm() > 0, "sun_direction must be non-zero");
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

// Radiance (grey level 0..255 before gain) along one ray through a pixel that subtends
// pixel_angle (rad).
double ShadeRay(const Scene& scene, const Hit& hit, const Eigen::Vector3d& o,
                const Eigen::Vector3d& d, const Eigen::Vector3d& sun, double pixel_angle,
                const CameraOptions& opt) {
  // Sky: brighter towards the horizon.
  const double sky = 255.0 * (0.93 - 0.12 * std::clamp(d.z(), 0.0, 1.0));
  if (!hit.valid()) return sky;
  const Eigen::Vector3d p = o + hit.t * d;
  // The pixel's footprint on the surface: t * pixel_angle across the ray, stretched by
  // 1 / cos(incidence) along it; the side of a square of the same area.
  const double incidence = std::max(std::abs(hit.normal.dot(d)), 1e-3);
  const Surface s = ShadeSurface(scene, hit, p, hit.t * pixel_angle / std::sqrt(incidence));
  const double light = 0.5 + 0.55 * std::max(0.0, hit.normal.dot(sun));
  const double value = 255.0 * s.albedo * light;
  if (hit.t <= opt.haze_start) return value;
  const double w = 1.0 - std::exp(-(hit.t - opt.haze_start) / 250.0);
  return value + w * (sky - value);
}

// Unit world direction of the ray through image point (u, v).
Eigen::Vector3d RayThrough(const Eigen::Matrix3d& R, const PinholeCamera& camera, double u,
                           double v) {
  return (R * camera.Unproject(Eigen::Vector2d(u, v))).normalized();
}

// What a centre ray hit: face, -2 - moving box, or -1 (sky).
int32_t SurfaceId(const Hit& hit) { return hit.dynamic >= 0 ? -2 - hit.dynamic : hit.face; }

// A pixel whose neighbourhood sees one surface: its sub-pixel rays (offsets from the pixel
// (i, j)) meet the plane of the centre ray's hit, planar at the scale of a pixel, and are shaded
// there without a ray cast. *value = base + weight x the sum of their radiances. Returns false,
// *value untouched, when a ray runs (nearly) parallel to the plane or meets it behind the
// camera or beyond max_range: the caller casts the rays then.
bool ShadeOnPlane(const Scene& scene, const Hit& centre, const Eigen::Vector3d& o,
                  const Eigen::Matrix3d& R, const PinholeCamera& camera, int i, int j,
                  const std::vector<Eigen::Vector2d>& offsets, const Eigen::Vector3d& sun,
                  double pixel_angle, const CameraOptions& options, float base, float weight,
                  float* value) {
  // n . (p - o) for the hit p (< 0: the normal faces the camera).
  const double plane = centre.normal.dot(RayThrough(R, camera, i, j)) * centre.t;
  float sum = base;
  for (const Eigen::Vector2d& offset : offsets) {
    const Eigen::Vector3d d = RayThrough(R, camera, i + offset.x(), j + offset.y());
    const double cos_n = centre.normal.dot(d);
    if (cos_n > -1e-6) return false;
    Hit sub = centre;
    sub.t = plane / cos_n;
    if (!(sub.t > 0.0 && sub.t <= options.max_range)) return false;
    sum += weight * static_cast<float>(ShadeRay(scene, sub, o, d, sun, pixel_angle, options));
  }
  *value = sum;
  return true;
}

// Separable Gaussian blur of a CV_32F image (radius ceil(4 sigma), edges replicated), written
// out in scalar double arithmetic: the same bytes on every CPU (a library filter picks its SIMD
// kernel by the CPU it runs on).
void BlurRadiance(double sigma, cv::Mat* image) {
  const int radius = std::max(1, static_cast<int>(std::ceil(4.0 * sigma)));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) {
    kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
    sum += kernel[k + radius];
  }
  for (double& k : kernel) k /= sum;
  const int w = image->cols, h = image->rows;
  cv::Mat tmp(h, w, CV_32F);
  for (int j = 0; j < h; ++j) {
    const float* in = image->ptr<float>(j);
    float* out = tmp.ptr<float>(j);
    for (int i = 0; i < w; ++i) {
      double acc = 0;
      for (int k = -radius; k <= radius; ++k) {
        acc += kernel[k + radius] * in[std::clamp(i + k, 0, w - 1)];
      }
      out[i] = static_cast<float>(acc);
    }
  }
  std::vector<const float*> rows(2 * radius + 1);
  for (int j = 0; j < h; ++j) {
    for (int k = -radius; k <= radius; ++k)
      rows[k + radius] = tmp.ptr<float>(std::clamp(j + k, 0, h - 1));
    float* out = image->ptr<float>(j);
    for (int i = 0; i < w; ++i) {
      double acc = 0;
      for (int k = 0; k <= 2 * radius; ++k) acc += kernel[k] * rows[k][i];
      out[i] = static_cast<float>(acc);
    }
  }
}

}  // namespace

cv::Mat RenderImage(const Scene& scene, const RayCaster& caster, const PinholeCamera& camera,
                    const Rigid3d& world_from_cam, const std::vector<Box>& moving, double gain,
                    uint64_t noise_seed, const CameraOptions& options) {
  camera.Check();
  const Eigen::Matrix3d R = world_from_cam.RotationMatrix();
  const Eigen::Vector3d o = world_from_cam.translation();
  const Eigen::Vector3d sun = options.sun_direction.normalized();
  const double pixel_angle = 1.0 / camera.fx;
  std::vector<Box> near;
  for (const Box& b : moving) {
    if (b.size.x() > 0 && (b.center - o).norm() < 200) near.push_back(b);
  }
  // Pass 1: one ray through every pixel centre.
  const int w = camera.width, h = camera.height;
  cv::Mat radiance(h, w, CV_32F);
  std::vector<Hit> centre_hits(static_cast<size_t>(w) * static_cast<size_t>(h));
  Eigen::Vector3d dirs[8];
  Hit hits[8];
  for (int j = 0; j < h; ++j) {
    float* row = radiance.ptr<float>(j);
    // The last triangle hit, the hint of the next ray (the caster's answer does not depend on it).
    int32_t hint = -1;
    for (int i0 = 0; i0 < w; i0 += 8) {
      const int n = std::min(8, w - i0);
      for (int k = 0; k < n; ++k) {
        dirs[k] = RayThrough(R, camera, i0 + k, j);
      }
      caster.Intersect8(o, dirs, n, 0.05, options.max_range, hits, hint);
      for (int k = 0; k < n; ++k) {
        if (hits[k].triangle >= 0) hint = hits[k].triangle;
        IntersectBoxes(near, o, dirs[k], &hits[k]);
        row[i0 + k] =
            static_cast<float>(ShadeRay(scene, hits[k], o, dirs[k], sun, pixel_angle, options));
        centre_hits[static_cast<size_t>(j) * w + i0 + k] = hits[k];
      }
    }
  }
  const int ss = options.supersample;
  if (ss > 1) {
    // Pass 2: a pixel whose 3 x 3 neighbourhood sees another surface, or whose centre-ray
    // radiance is not locally linear (a second difference along a row, column or diagonal above
    // supersample_contrast grey levels: a texture edge, not a smooth shading gradient), is
    // replaced by the mean of ss x ss rays spread over its area (the pixel integrates the light
    // falling on it). Elsewhere the centre ray is the pixel's mean. Where the whole neighbourhood
    // sees one surface, only its texture changes within the pixel: the sub-pixel rays meet the
    // plane of the centre ray's hit (the surfaces are planar at the scale of a pixel) and are
    // shaded there, without a ray cast.
    const cv::Mat centre = radiance.clone();
    const float contrast = static_cast<float>(options.supersample_contrast);
    const float weight = 1.0f / static_cast<float>(ss * ss);
    // Sub-pixel offsets on a rotated grid: the ss x ss lattice turned by atan(1 / ss) puts every
    // sample at its own column and row of an ss^2 x ss^2 sub-grid, so a near-vertical or
    // near-horizontal edge (the common case) moves the pixel's mean in ss^2 steps instead of ss
    // (for ss = 2 the rotated-grid pattern of graphics hardware). With an odd ss the middle
    // sample is the centre ray, whose value is reused.
    std::vector<Eigen::Vector2d> offsets;
    const double cells = static_cast<double>(ss * ss);
    for (int sy = 0; sy < ss; ++sy) {
      for (int sx = 0; sx < ss; ++sx) {
        if (ss % 2 == 1 && 2 * sx + 1 == ss && 2 * sy + 1 == ss) continue;
        offsets.emplace_back((ss * sx + sy + 0.5) / cells - 0.5,
                             (ss * sy - sx + ss - 1 + 0.5) / cells - 0.5);
      }
    }
    const int rays = static_cast<int>(offsets.size());
    const float centre_weight = ss % 2 == 1 ? weight : 0.0f;
    std::vector<int> cast;  // Pixels of the row whose sub-pixel rays are cast.
    for (int j = 0; j < h; ++j) {
      cast.clear();
      float* row = radiance.ptr<float>(j);
      for (int i = 0; i < w; ++i) {
        const float c = centre.at<float>(j, i);
        const Hit& hit = centre_hits[static_cast<size_t>(j) * w + i];
        const int32_t f = SurfaceId(hit);
        bool other_surface = false;
        for (int y = std::max(0, j - 1); y <= std::min(h - 1, j + 1); ++y) {
          const Hit* hits_row = &centre_hits[static_cast<size_t>(y) * w];
          for (int x = std::max(0, i - 1); x <= std::min(w - 1, i + 1); ++x) {
            other_surface = other_surface || SurfaceId(hits_row[x]) != f;
          }
        }
        // Second differences (borders replicate the edge pixel).
        const int up = std::max(0, j - 1), down = std::min(h - 1, j + 1);
        const int left = std::max(0, i - 1), right = std::min(w - 1, i + 1);
        const float* ru = centre.ptr<float>(up);
        const float* rc = centre.ptr<float>(j);
        const float* rd = centre.ptr<float>(down);
        const float curvature = std::max(
            std::max(std::abs(rc[left] + rc[right] - 2 * c), std::abs(ru[i] + rd[i] - 2 * c)),
            std::max(std::abs(ru[left] + rd[right] - 2 * c),
                     std::abs(ru[right] + rd[left] - 2 * c)));
        const bool edge = curvature > contrast;
        if (other_surface || (edge && f < 0)) {
          cast.push_back(i);
        } else if (edge && !ShadeOnPlane(scene, hit, o, R, camera, i, j, offsets, sun, pixel_angle,
                                         options, centre_weight * c, weight, &row[i])) {
          cast.push_back(i);  // A sub-pixel ray misses the plane (grazing view): cast them all.
        }
      }
      // Sub-pixel rays of the pixels at a surface boundary, eight at a time.
      for (int i : cast) row[i] = centre_weight * centre.at<float>(j, i);
      const int64_t total = static_cast<int64_t>(cast.size()) * rays;
      int pixel[8];
      for (int64_t r0 = 0; r0 < total; r0 += 8) {
        const int n = static_cast<int>(std::min<int64_t>(8, total - r0));
        for (int k = 0; k < n; ++k) {
          const int64_t r = r0 + k;
          pixel[k] = cast[static_cast<size_t>(r / rays)];
          const Eigen::Vector2d& d = offsets[static_cast<size_t>(r % rays)];
          dirs[k] = RayThrough(R, camera, pixel[k] + d.x(), j + d.y());
        }
        caster.Intersect8(o, dirs, n, 0.05, options.max_range, hits,
                          centre_hits[static_cast<size_t>(j) * w + pixel[0]].triangle);
        for (int k = 0; k < n; ++k) {
          IntersectBoxes(near, o, dirs[k], &hits[k]);
          row[pixel[k]] += weight * static_cast<float>(ShadeRay(scene, hits[k], o, dirs[k], sun,
                                                                pixel_angle, options));
        }
      }
    }
  }
  if (options.blur_sigma > 0) BlurRadiance(options.blur_sigma, &radiance);
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
