#include "vision/patch_align.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
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
  // Target position of patch offset x: c + W x, W = scale * I at the start.
  Eigen::Vector2d c = start;
  Eigen::Matrix2d w = scale * Eigen::Matrix2d::Identity();
  double a = 1, b = 0;
  std::array<float, n> current{};
  // Stage 0: translation and brightness; stage 1 (options.affine): also the 2 x 2 warp.
  const int stages = options.affine ? 2 : 1;
  for (int stage = 0; stage < stages; ++stage) {
    const int np = stage == 0 ? 4 : 8;
    for (int it = 0; it <= options.iterations; ++it) {
      Eigen::Matrix<double, 8, 8> h = Eigen::Matrix<double, 8, 8>::Zero();
      Eigen::Matrix<double, 8, 1> g = Eigen::Matrix<double, 8, 1>::Zero();
      int i = 0;
      for (int dy = -kPatchRadius; dy <= kPatchRadius; ++dy) {
        for (int dx = -kPatchRadius; dx <= kPatchRadius; ++dx, ++i) {
          const Eigen::Vector2d q = c + w * Eigen::Vector2d(dx, dy);
          float v, gx, gy;
          if (!Sample(level, q.x(), q.y(), &v, &gx, &gy)) return out;
          current[i] = v;
          const double t = patch.values[i];
          const double r = v - a * t - b;
          Eigen::Matrix<double, 8, 1> j;
          j << gx, gy, -t, -1.0, gx * dx, gx * dy, gy * dx, gy * dy;
          if (np == 4) {  // The warp's rows and columns are not used in this stage.
            h.topLeftCorner<4, 4>() += j.head<4>() * j.head<4>().transpose();
            g.head<4>() += j.head<4>() * r;
          } else {
            h += j * j.transpose();
            g += j * r;
          }
        }
      }
      if (stage == 0 && it == 0) {
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
      Eigen::VectorXd d;
      if (np == 4) {
        Eigen::LDLT<Eigen::Matrix4d> ldlt(h.topLeftCorner<4, 4>());
        if (ldlt.info() != Eigen::Success) return out;
        d = -ldlt.solve(g.head<4>());
      } else {
        // A weak pull of the warp towards its prediction keeps it defined on edge-like patches.
        Eigen::Matrix<double, 8, 8> hr = h;
        const double lambda = options.warp_prior * h.topLeftCorner<2, 2>().trace();
        Eigen::Matrix<double, 8, 1> gr = g;
        const Eigen::Matrix2d dw = w - scale * Eigen::Matrix2d::Identity();
        const double prior[4] = {dw(0, 0), dw(0, 1), dw(1, 0), dw(1, 1)};
        for (int k = 0; k < 4; ++k) hr(4 + k, 4 + k) += lambda, gr(4 + k) += lambda * prior[k];
        Eigen::LDLT<Eigen::Matrix<double, 8, 8>> ldlt(hr);
        if (ldlt.info() != Eigen::Success) return out;
        d = -ldlt.solve(gr);
      }
      if (!d.allFinite()) return out;
      c += d.head<2>();
      a += d(2), b += d(3);
      if (np == 8) {
        w(0, 0) += d(4), w(0, 1) += d(5), w(1, 0) += d(6), w(1, 1) += d(7);
        const double det = w.determinant() / (scale * scale);
        if (!(det > 0.25 && det < 4) || (w / scale - Eigen::Matrix2d::Identity()).norm() > 1.0) {
          return out;
        }
      }
      if ((c - start).norm() > options.max_shift) return out;
      // Converged when no patch sample moves by more than ~1e-3 level pixels.
      const double move = d.head<2>().squaredNorm() +
                          (np == 8 ? kPatchRadius * kPatchRadius * d.tail<4>().squaredNorm() : 0.0);
      if (move < 1e-6) break;
    }
  }
  // Resample at the final position for the correlation.
  int k = 0;
  for (int yy = -kPatchRadius; yy <= kPatchRadius; ++yy) {
    for (int xx = -kPatchRadius; xx <= kPatchRadius; ++xx, ++k) {
      const Eigen::Vector2d q = c + w * Eigen::Vector2d(xx, yy);
      if (!Sample(level, q.x(), q.y(), &current[k], nullptr, nullptr)) return out;
    }
  }
  out.ncc = Ncc(current.data(), patch.values.data(), n);
  out.level_xy = c;
  out.warp = w;
  out.ok = out.ncc >= options.min_ncc;
  return out;
}

}  // namespace jvl::vision
