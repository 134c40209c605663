#include "vision/patch_align.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>

namespace jvl::vision {
namespace {

// A smooth texture (a few blobs and a ramp), values within [20, 235].
double Texture(double x, double y) {
  double v = 120 + 0.3 * x - 0.2 * y;
  const double blobs[][3] = {{50, 40, 3.0}, {57, 44, 2.0}, {46, 49, 2.5}, {53, 36, 1.8}};
  for (const auto& b : blobs) {
    const double d2 = (x - b[0]) * (x - b[0]) + (y - b[1]) * (y - b[1]);
    v += 70 * std::exp(-d2 / (2 * b[2] * b[2])) * (b[2] > 2.2 ? 1 : -1);
  }
  return std::clamp(v, 20.0, 235.0);
}

// Renders level(q) = a * Texture(origin + (q - centre) / scale) + b, pixel centres at integers.
cv::Mat Render(const Eigen::Vector2d& origin, const Eigen::Vector2d& centre, double scale,
               double a = 1.0, double b = 0.0) {
  cv::Mat img(100, 110, CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const Eigen::Vector2d p = origin + (Eigen::Vector2d(x, y) - centre) / scale;
      img.at<uint8_t>(y, x) =
          static_cast<uint8_t>(std::clamp(std::lround(a * Texture(p.x(), p.y()) + b), 0L, 255L));
    }
  return img;
}

TEST(PatchAlign, LevelAndImageCoordinatesRoundTrip) {
  const cv::Size image(1241, 376), level(620, 188);
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0, 0), Eigen::Vector2d(310.25, 90.5),
                                   Eigen::Vector2d(619, 187)}) {
    const Eigen::Vector2d uv = LevelToImage(p, level, image);
    EXPECT_LT((ImageToLevel(uv, level, image) - p).norm(), 1e-9);
  }
  // Pixel centres at +0.5: level pixel 0 of a half-size level covers image pixels 0 and 1.
  const Eigen::Vector2d first = LevelToImage({0, 0}, cv::Size(50, 50), cv::Size(100, 100));
  EXPECT_NEAR(first.x(), 0.5, 1e-12);
  EXPECT_NEAR(first.y(), 0.5, 1e-12);
  // Same size: the identity.
  EXPECT_LT((LevelToImage({12.3, 4.5}, image, image) - Eigen::Vector2d(12.3, 4.5)).norm(), 1e-12);
}

TEST(PatchAlign, RecoversASubPixelShiftUnderABrightnessChange) {
  const Eigen::Vector2d p0(51, 42);
  const cv::Mat reference = Render(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), 1.0);
  const PatchTemplate patch = MakePatchTemplate(reference, p0);
  ASSERT_TRUE(patch.valid);
  for (const Eigen::Vector2d& d : {Eigen::Vector2d(0.3, -0.45), Eigen::Vector2d(-0.7, 0.2),
                                   Eigen::Vector2d(0.0, 0.0)}) {
    // target(q) = 1.2 * T(q - d) + 10: the patch sits at p0 + d.
    const cv::Mat target = Render(Eigen::Vector2d::Zero(), d, 1.0, 1.2, 10.0);
    const PatchAlignment r = AlignPatch(target, patch, p0, 1.0);
    ASSERT_TRUE(r.ok) << d.transpose();
    EXPECT_LT((r.level_xy - (p0 + d)).norm(), 0.05) << d.transpose() << " -> "
                                                      << r.level_xy.transpose();
    EXPECT_GT(r.ncc, 0.99);
  }
}

TEST(PatchAlign, UsesThePredictedScale) {
  // The target shows the texture 1.3 x larger, centred at c0: with the predicted scale the
  // patch is found at c0; without it the alignment is off or rejected.
  const Eigen::Vector2d p0(51, 42), c0(55.4, 47.7);
  const cv::Mat reference = Render(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), 1.0);
  const PatchTemplate patch = MakePatchTemplate(reference, p0);
  const cv::Mat target = Render(p0, c0, 1.3);
  const PatchAlignment scaled = AlignPatch(target, patch, c0.array().round(), 1.3);
  ASSERT_TRUE(scaled.ok);
  EXPECT_LT((scaled.level_xy - c0).norm(), 0.08);
  const PatchAlignment unscaled = AlignPatch(target, patch, c0.array().round(), 1.0);
  EXPECT_TRUE(!unscaled.ok || unscaled.ncc < scaled.ncc);
}

// Blurred window corners: a bright frame around a dark pane, as on the simulator's facades.
double Corner(double x, double y) {
  const auto step = [](double d) { return 1.0 / (1.0 + std::exp(-d / 1.0)); };
  const double frame = step(x - 49) * step(y - 39);
  const double pane = step(x - 52) * step(y - 43);
  return 70 + 140 * frame - 110 * pane;
}

// Renders level(q) = Corner(origin + A^-1 (q - centre)): the corner under the affine map A.
cv::Mat RenderAffine(const Eigen::Vector2d& origin, const Eigen::Vector2d& centre,
                     const Eigen::Matrix2d& a) {
  const Eigen::Matrix2d inv = a.inverse();
  cv::Mat img(100, 110, CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const Eigen::Vector2d p = origin + inv * (Eigen::Vector2d(x, y) - centre);
      img.at<uint8_t>(y, x) =
          static_cast<uint8_t>(std::clamp(std::lround(Corner(p.x(), p.y())), 0L, 255L));
    }
  return img;
}

TEST(PatchAlign, AffineWarpRemovesTheBiasOfAnObliqueView) {
  // A surface seen more obliquely in the target: compressed to 0.7 horizontally and sheared, as
  // a facade along the road as the camera moves. The translation-only model (isotropic scale)
  // settles 0.65 px off the true centre; the affine model finds it to < 0.1 px (what is left is
  // the bilinear interpolation of the target's edges, sharpened by the compression).
  const Eigen::Vector2d p0(51, 42), c0(54.3, 45.6);
  Eigen::Matrix2d a;
  a << 0.7, 0.25, 0.05, 1.05;
  const cv::Mat reference =
      RenderAffine(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity());
  const PatchTemplate patch = MakePatchTemplate(reference, p0);
  const cv::Mat target = RenderAffine(p0, c0, a);
  PatchAlignOptions options;
  options.min_ncc = 0.5;
  options.affine = false;
  const PatchAlignment translation = AlignPatch(target, patch, c0.array().round(), 1.0, options);
  options.affine = true;
  const PatchAlignment affine = AlignPatch(target, patch, c0.array().round(), 1.0, options);
  ASSERT_TRUE(affine.ok);
  EXPECT_LT((affine.level_xy - c0).norm(), 0.1) << affine.level_xy.transpose();
  EXPECT_LT((affine.warp - a).norm(), 0.06) << affine.warp;
  EXPECT_GT(affine.ncc, 0.99);
  ASSERT_TRUE(translation.ok);
  EXPECT_GT((translation.level_xy - c0).norm(), 0.4) << translation.level_xy.transpose();
  EXPECT_LT(translation.ncc, affine.ncc);
}

TEST(PatchAlign, RejectsUnrelatedTextureFarShiftsAndBorders) {
  const Eigen::Vector2d p0(51, 42);
  const cv::Mat reference = Render(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), 1.0);
  const PatchTemplate patch = MakePatchTemplate(reference, p0);
  cv::Mat noise(100, 110, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  EXPECT_FALSE(AlignPatch(noise, patch, p0, 1.0).ok);
  // The patch is 3 px away from the start: beyond max_shift (1.5 level pixels).
  const cv::Mat far = Render(Eigen::Vector2d::Zero(), Eigen::Vector2d(3.0, 0.0), 1.0);
  EXPECT_FALSE(AlignPatch(far, patch, p0, 1.0).ok);
  // No template or no alignment at the image border.
  EXPECT_FALSE(MakePatchTemplate(reference, Eigen::Vector2d(2, 50)).valid);
  EXPECT_FALSE(AlignPatch(reference, patch, Eigen::Vector2d(1, 1), 1.0).ok);
}

}  // namespace
}  // namespace jvl::vision
