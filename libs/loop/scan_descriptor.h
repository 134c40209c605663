// A LiDAR place descriptor: the polar grid of a scan's largest heights (the Scan Context of Kim
// and Kim, IROS 2018), with a rotation-invariant ring key for candidate search and a distance
// that searches the yaw between two scans. An independent second detector for loop closing,
// beside the visual bag of words.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace jvl::loop {

struct ScanDescriptorOptions {
  int rings = 20;               // Radial bins over (0, max_range].
  int sectors = 60;             // Azimuth bins over 360 degrees (6 degrees each).
  double max_range = 80.0;      // Horizontal distance (m); farther returns are left out.
  double sensor_height = 1.73;  // Heights are measured from the road: z + sensor_height.
  void Check() const;
};

// cells(r, s): the largest height above the road (m, >= 0) of the returns in ring r, sector s;
// 0 where there are none. Sector s covers azimuths [s, s + 1) * 360 / sectors degrees from the
// sensor's +x axis, counter-clockwise. ring_key(r): the share of ring r's sectors with returns,
// the same whatever the sensor's yaw.
struct ScanDescriptor {
  Eigen::MatrixXf cells;
  Eigen::VectorXf ring_key;
};

// The sector of azimuth atan2(y, x) (taken in [0, 2 pi)) among `sectors`: the same as
// min(sectors - 1, floor(azimuth / (2 pi) x sectors)) with atan2, always, at less cost (a
// polynomial, with atan2 only next to a sector boundary). x and y must be finite.
int AzimuthSector(double x, double y, int sectors);

// points: sensor frame (x forward, y left, z up).
ScanDescriptor ComputeScanDescriptor(const std::vector<Eigen::Vector3d>& points,
                                     const ScanDescriptorOptions& options);

struct DescriptorMatch {
  double distance = 1;  // In [0, 1]: 0 = the same cells at the best shift.
  int shift = 0;        // Sectors: b's sector (s + shift) matches a's sector s.
  double yaw = 0;       // shift in radians, in (-pi, pi]: b's sensor is turned by -yaw from a's.
};

// The mean over the sector columns with returns in both of (1 - cosine similarity of the
// columns), minimised over the column shifts of b. Columns empty in one of the two count as
// dissimilar (1) unless empty in both; two empty descriptors are at distance 1. Ties go to the
// shift nearest 0 (BestShiftNear).
DescriptorMatch CompareDescriptors(const ScanDescriptor& a, const ScanDescriptor& b);
// The same distance at every shift 0 .. sectors - 1.
std::vector<double> ShiftDistances(const ScanDescriptor& a, const ScanDescriptor& b);
// The best shift within `window` sectors of `centre` (either side, wrapping round).
DescriptorMatch BestShiftNear(const std::vector<double>& distances, int centre, int window);

// Distance of the ring keys (Euclidean): the first, rotation-invariant filter of candidates.
double RingKeyDistance(const ScanDescriptor& a, const ScanDescriptor& b);

}  // namespace jvl::loop
