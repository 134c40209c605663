// ORB features spread over the image, in the manner of ORB-SLAM2 (Mur-Artal & Tardos 2017):
// an 8-level pyramid with scale 1.2, FAST corners detected per grid cell (threshold 20, 7 where a
// cell has none), the strongest corners kept per cell round-robin so that every cell contributes,
// orientation by the intensity centroid and rotated BRIEF descriptors computed with cv::ORB.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

namespace jvl::vision {

using Descriptor = std::array<uint8_t, 32>;

// Hamming distance of two 256-bit descriptors (inline: the matchers' innermost loop).
inline int HammingDistance(const Descriptor& a, const Descriptor& b) {
  int d = 0;
  for (int i = 0; i < 32; i += 8) {
    uint64_t x, y;
    std::memcpy(&x, a.data() + i, 8);
    std::memcpy(&y, b.data() + i, 8);
    // Bit count without relying on a hardware popcount instruction (SWAR reduction).
    uint64_t v = x ^ y;
    v = v - ((v >> 1) & 0x5555555555555555ULL);
    v = (v & 0x3333333333333333ULL) + ((v >> 2) & 0x3333333333333333ULL);
    v = (v + (v >> 4)) & 0x0f0f0f0f0f0f0f0fULL;
    d += static_cast<int>((v * 0x0101010101010101ULL) >> 56);
  }
  return d;
}

struct OrbOptions {
  int num_features = 2000;     // Total over all levels (ORB-SLAM2 KITTI setting).
  int num_levels = 8;          // Pyramid levels.
  double scale_factor = 1.2;   // Scale between consecutive levels.
  int fast_threshold = 20;     // FAST threshold tried first in every cell.
  int fast_min_threshold = 7;  // Retried in cells where the first threshold finds nothing.
  int cell_size = 30;          // Grid cell size in pixels of each level.
  int edge_threshold = 19;     // Border (level pixels) without features (BRIEF patch 31).
  bool keep_pyramid = false;   // Return the pyramid levels (for patch alignment).
  void Check() const;
};

struct OrbKeypoint {
  // Level-0 pixel coordinates of the level pixel (pixel centres mapped through the resizing,
  // patch_align.h LevelToImage).
  Eigen::Vector2f uv;
  int octave = 0;      // Pyramid level.
  float angle = 0;     // Orientation in degrees [0, 360), as cv::KeyPoint.
  float response = 0;  // FAST score.
};

struct OrbFeatures {
  std::vector<OrbKeypoint> keypoints;
  std::vector<Descriptor> descriptors;  // Same length as keypoints.
  std::vector<cv::Mat> pyramid;         // Level images (level 0 = the grey image) if kept.
  size_t size() const { return keypoints.size(); }
};

// Scale of each level: scale_factor^level (level 0 = 1).
std::vector<double> LevelScales(const OrbOptions& options);

// Detects and describes ORB features in a greyscale (or colour, converted) image. Deterministic.
// Keypoints are ordered by octave, then by row-major grid cell, then by decreasing response.
OrbFeatures ExtractOrb(const cv::Mat& image, const OrbOptions& options);

}  // namespace jvl::vision
