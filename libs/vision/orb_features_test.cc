#include "vision/orb_features.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>

#include "core/check.h"

namespace jvl::vision {
namespace {

// Blurred random blobs: corners everywhere, like a textured scene.
cv::Mat TexturedImage(int width, int height, unsigned seed) {
  cv::Mat img(height, width, CV_8UC1, cv::Scalar(128));
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> x(0, width - 1), y(0, height - 1), s(3, 25), g(0, 255);
  for (int i = 0; i < 4000; ++i) {
    const cv::Point p(x(rng), y(rng));
    cv::rectangle(img, p, p + cv::Point(s(rng), s(rng)), cv::Scalar(g(rng)), cv::FILLED);
  }
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.8);
  return img;
}

TEST(OrbFeatures, SpreadOverImageAndLevels) {
  const cv::Mat img = TexturedImage(1226, 370, 1);
  const OrbOptions options;
  const OrbFeatures f = ExtractOrb(img, options);
  ASSERT_EQ(f.keypoints.size(), f.descriptors.size());
  EXPECT_GE(f.size(), 1800u);
  EXPECT_LE(f.size(), 2000u);
  std::set<int> octaves;
  std::set<std::pair<int, int>> cells;  // 100 px cells at level 0.
  for (const OrbKeypoint& k : f.keypoints) {
    octaves.insert(k.octave);
    EXPECT_GE(k.angle, 0.f);
    EXPECT_LT(k.angle, 360.f);
    EXPECT_GE(k.uv.x(), 0.f);
    EXPECT_LT(k.uv.x(), 1226.f);
    cells.insert({static_cast<int>(k.uv.x()) / 100, static_cast<int>(k.uv.y()) / 100});
  }
  EXPECT_EQ(octaves.size(), 8u);
  EXPECT_GE(cells.size(), 13u * 4u - 4u);  // Nearly every 100 px cell has features.
  EXPECT_NEAR(LevelScales(options)[7], std::pow(1.2, 7), 1e-12);
}

TEST(OrbFeatures, DeterministicAndRotationInvariant) {
  const cv::Mat img = TexturedImage(640, 480, 2);
  const OrbFeatures a = ExtractOrb(img, OrbOptions());
  const OrbFeatures b = ExtractOrb(img, OrbOptions());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].uv, b.keypoints[i].uv);
    EXPECT_EQ(a.descriptors[i], b.descriptors[i]);
  }
  // Rotating the image by 90 deg: a keypoint found at the rotated position has its angle
  // changed by about 90 deg and a close descriptor.
  cv::Mat rotated;
  cv::rotate(img, rotated, cv::ROTATE_90_CLOCKWISE);
  const OrbFeatures r = ExtractOrb(rotated, OrbOptions());
  int compared = 0, close = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a.keypoints[i].octave != 0) continue;
    const Eigen::Vector2f expected(img.rows - 1 - a.keypoints[i].uv.y(), a.keypoints[i].uv.x());
    for (size_t j = 0; j < r.size(); ++j) {
      if (r.keypoints[j].octave != 0 || (r.keypoints[j].uv - expected).norm() > 0.5f) continue;
      ++compared;
      if (HammingDistance(a.descriptors[i], r.descriptors[j]) < 50) ++close;
      break;
    }
  }
  ASSERT_GT(compared, 100);
  EXPECT_GT(close, 0.7 * compared);
}

TEST(OrbFeatures, HammingDistance) {
  Descriptor a{}, b{};
  EXPECT_EQ(HammingDistance(a, b), 0);
  b[0] = 0xff;
  b[31] = 0x01;
  EXPECT_EQ(HammingDistance(a, b), 9);
  a.fill(0xff);
  b.fill(0x00);
  EXPECT_EQ(HammingDistance(a, b), 256);
}

TEST(OrbFeatures, RejectsBadInput) {
  EXPECT_THROW(ExtractOrb(cv::Mat(), OrbOptions()), Error);
  OrbOptions bad;
  bad.scale_factor = 1.0;
  EXPECT_THROW(bad.Check(), Error);
}

TEST(OrbFeatures, KittiImage) {
  const std::string path = std::string(JVL_SOURCE_DIR) +
                           "/../shared/data/kitti_odometry_04_f0-50/sequences/04/image_0/000000.png";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "KITTI sample not found at " << path;
  const cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  const OrbFeatures f = ExtractOrb(img, OrbOptions());
  EXPECT_GE(f.size(), 1900u);
  EXPECT_LE(f.size(), 2000u);
}

}  // namespace
}  // namespace jvl::vision
