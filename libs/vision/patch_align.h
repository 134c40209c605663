// Sub-pixel alignment of a keypoint to the image patch of a map point's reference observation.
// FAST corners are whole pixels of their pyramid level and move with the apparent size of the
// texture around them, so the keypoints of one surface point in several keyframes disagree by
// about half the level scale. Aligning every observation to one reference patch (translation,
// a predicted scale and an affine brightness change, Gauss-Newton as Lucas & Kanade 1981) makes
// the observations of a point consistent with each other.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

namespace jvl::vision {

constexpr int kPatchRadius = 4;  // 9 x 9 samples.
constexpr int kPatchSize = 2 * kPatchRadius + 1;

struct PatchTemplate {
  std::array<float, kPatchSize * kPatchSize> values{};
  bool valid = false;
};

// Level-0 pixel coordinates of a level pixel position and back, for a level of size `level`
// resized (bilinear, pixel centres at +0.5) from an image of size `image`.
Eigen::Vector2d LevelToImage(const Eigen::Vector2d& level_xy, const cv::Size& level,
                             const cv::Size& image);
Eigen::Vector2d ImageToLevel(const Eigen::Vector2d& uv, const cv::Size& level,
                             const cv::Size& image);

// Samples the patch centred at a level position (bilinear); invalid near the border.
PatchTemplate MakePatchTemplate(const cv::Mat& level, const Eigen::Vector2d& level_xy);

struct PatchAlignOptions {
  int iterations = 10;
  double max_shift = 1.5;    // Level pixels from the start position.
  double min_ncc = 0.8;      // Normalised cross-correlation required at the solution.
  bool affine = true;        // After the translation, also fit a 2 x 2 warp of the patch.
  double warp_prior = 0.01;  // Weight of the warp's pull towards the predicted scale.
};

struct PatchAlignment {
  bool ok = false;
  Eigen::Vector2d level_xy = Eigen::Vector2d::Zero();
  Eigen::Matrix2d warp = Eigen::Matrix2d::Identity();  // Level pixels per patch pixel.
  double ncc = 0;
};

// Finds c near `start` (level pixels) with level(c + scale * x) ~ a * patch(x) + b, where
// `scale` is the size of a patch pixel in level pixels (apparent scale change).
PatchAlignment AlignPatch(const cv::Mat& level, const PatchTemplate& patch,
                          const Eigen::Vector2d& start, double scale,
                          const PatchAlignOptions& options = {});

}  // namespace jvl::vision
