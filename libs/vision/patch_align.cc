#include "vision/patch_align.h"

#include <Eigen/Cholesky>
#include <cmath>

namespace jvl::vision {
namespace {

// Bilinear sample and gradient; false outside [0, cols - 1) x [0, rows - 1).
bool Sample(const cv::Mat& img, double x, double y, float* value, float* gx, float* gy) {
  if (!(x >= 0 && y >= 0 && x < img.cols - 1 && y < img.rows - 1)) return false;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const uint8_t* r0 = img.ptr<uint8_t>(y0) + x0;
  const uint8_t* r1 = img.ptr<uint8_t>(y0 + 1) + x0;
  const float a = r0[0], b = r0[1], c = r1[0], d = r1[1];
  *value = (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
  if (gx) *gx = (1 - fy) * (b - a) + fy * (d - c);
  if (gy) *gy = (1 - fx) * (c - a) + fx * (d - b);
  return true;
}

double Ncc(const float* a, const float* b, int n) {
  double ma = 0, mb = 0;
  for (int i = 0; i < n; ++i) ma += a[i], mb += b[i];
  ma /= n, mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (int i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 1e-9 && sbb > 1e-9 ? sab / std::sqrt(saa * sbb) : 0.0;
}

}  // namespace

Eigen::Vector2d LevelToImage(const Eigen::Vector2d& level_xy, const cv::Size& level,
                             const cv::Size& image) {
  return {(level_xy.x() + 0.5) * image.width / level.width - 0.5,
          (level_xy.y() + 0.5) * image.height / level.height - 0.5};
}

Eigen::Vector2d ImageToLevel(const Eigen::Vector2d& uv, const cv::Size& level,
                             const cv::Size& image) {
  return {(uv.x() + 0.5) * level.width / image.width - 0.5,
          (uv.y() + 0.5) * level.height / image.height - 0.5};
}

PatchTemplate MakePatchTemplate(const cv::Mat& level, const Eigen::Vector2d& level_xy) {
  PatchTemplate t;
  int i = 0;
  for (int dy = -kPatchRadius; dy <= kPatchRadius; ++dy) {
    for (int dx = -kPatchRadius; dx <= kPatchRadius; ++dx, ++i) {
      if (!Sample(level, level_xy.x() + dx, level_xy.y() + dy, &t.values[i], nullptr, nullptr)) {
        return t;
      }
    }
  }
  t.valid = true;
  return t;
}

PatchAlignment AlignPatch(const cv::Mat& level, const PatchTemplate& patch,
                          const Eigen::Vector2d& start, double scale,
                          const PatchAlignOptions& options) {
  PatchAlignment out;
  if (!patch.valid) return out;
  constexpr int n = kPatchSize * kPatchSize;
  Eigen::Vector2d c = start;
  double a = 1, b = 0;
  std::array<float, n> current{};
  for (int it = 0; it <= options.iterations; ++it) {
    Eigen::Matrix4d h = Eigen::Matrix4d::Zero();
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    int i = 0;
    for (int dy = -kPatchRadius; dy <= kPatchRadius; ++dy) {
      for (int dx = -kPatchRadius; dx <= kPatchRadius; ++dx, ++i) {
        float v, gx, gy;
        if (!Sample(level, c.x() + scale * dx, c.y() + scale * dy, &v, &gx, &gy)) return out;
        current[i] = v;
        const double t = patch.values[i];
        const double r = v - a * t - b;
        const Eigen::Vector4d j(gx, gy, -t, -1.0);
        h += j * j.transpose();
        g += j * r;
      }
    }
    if (it == 0) {
      // Start from the brightness change that matches means and spreads.
      double mt = 0, mv = 0, st = 0, sv = 0;
      for (int k = 0; k < n; ++k) mt += patch.values[k], mv += current[k];
      mt /= n, mv /= n;
      for (int k = 0; k < n; ++k) {
        st += (patch.values[k] - mt) * (patch.values[k] - mt);
        sv += (current[k] - mv) * (current[k] - mv);
      }
      if (st < 1e-6) return out;
      a = std::sqrt(sv / st), b = mv - a * mt;
      continue;
    }
    if (it == options.iterations) break;
    Eigen::LDLT<Eigen::Matrix4d> ldlt(h);
    if (ldlt.info() != Eigen::Success) return out;
    const Eigen::Vector4d d = -ldlt.solve(g);
    if (!d.allFinite()) return out;
    c += d.head<2>();
    a += d(2), b += d(3);
    if ((c - start).norm() > options.max_shift) return out;
    if (d.head<2>().squaredNorm() < 1e-6) {
      // Converged: resample at the final position for the correlation.
      int k = 0;
      for (int yy = -kPatchRadius; yy <= kPatchRadius; ++yy) {
        for (int xx = -kPatchRadius; xx <= kPatchRadius; ++xx, ++k) {
          if (!Sample(level, c.x() + scale * xx, c.y() + scale * yy, &current[k], nullptr,
                      nullptr)) {
            return out;
          }
        }
      }
      break;
    }
  }
  out.ncc = Ncc(current.data(), patch.values.data(), n);
  out.level_xy = c;
  out.ok = out.ncc >= options.min_ncc;
  return out;
}

}  // namespace jvl::vision
