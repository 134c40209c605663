#include "loop/scan_descriptor.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace jvl::loop {
namespace {

constexpr double kPi = 3.14159265358979323846;

// atan(t) for t in [0, 1] within 1.2e-5 rad (Abramowitz and Stegun, Handbook of Mathematical
// Functions, 4.4.47; the largest error is at t = 1).
double AtanUnit(double t) {
  const double t2 = t * t;
  return t *
         (0.9998660 + t2 * (-0.3302995 + t2 * (0.1801410 + t2 * (-0.0851330 + t2 * 0.0208351))));
}

}  // namespace

int AzimuthSector(double x, double y, int sectors) {
  // The polynomial's azimuth in [0, 2 pi], in sectors; where it lies farther than 1e-4 rad (eight
  // times its error) from a sector boundary, its sector is atan2's. Within that margin (2e-4 x
  // sectors / (2 pi) of the returns, 0.2 % at 60 sectors) atan2 decides.
  const double ax = std::abs(x), ay = std::abs(y);
  double a = ax >= ay ? AtanUnit(ay / ax) : kPi / 2 - AtanUnit(ax / ay);
  if (x < 0) a = kPi - a;
  if (y < 0) a = 2 * kPi - a;
  const double per_radian = sectors / (2 * kPi);
  const double u = a * per_radian, margin = 1e-4 * per_radian;
  const double lo = std::floor(u - margin);
  if (lo == std::floor(u + margin) && lo >= 0 && lo < sectors) return static_cast<int>(lo);
  double azimuth = std::atan2(y, x);
  if (azimuth < 0) azimuth += 2 * kPi;
  return std::min(sectors - 1, static_cast<int>(azimuth / (2 * kPi) * sectors));
}

void ScanDescriptorOptions::Check() const {
  JVL_CHECK(rings >= 1 && rings <= 1000,
            "scan descriptor: rings must be in [1, 1000], got " << rings);
  JVL_CHECK(sectors >= 4 && sectors <= 3600,
            "scan descriptor: sectors must be in [4, 3600], got " << sectors);
  JVL_CHECK(std::isfinite(max_range) && max_range > 0,
            "scan descriptor: max_range must be > 0, got " << max_range);
  JVL_CHECK(std::isfinite(sensor_height), "scan descriptor: sensor_height must be finite");
}

ScanDescriptor ComputeScanDescriptor(const std::vector<Eigen::Vector3d>& points,
                                     const ScanDescriptorOptions& o) {
  o.Check();
  ScanDescriptor d;
  d.cells = Eigen::MatrixXf::Zero(o.rings, o.sectors);
  Eigen::MatrixXi hit = Eigen::MatrixXi::Zero(o.rings, o.sectors);
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    const double range = p.head<2>().norm();
    if (range <= 0 || range > o.max_range) continue;
    const int r = std::min(o.rings - 1, static_cast<int>(range / o.max_range * o.rings));
    const int s = AzimuthSector(p.x(), p.y(), o.sectors);
    const float height = static_cast<float>(std::max(0.0, p.z() + o.sensor_height));
    hit(r, s) = 1;
    d.cells(r, s) = std::max(d.cells(r, s), height);
  }
  d.ring_key = hit.cast<float>().rowwise().mean();
  return d;
}

std::vector<double> ShiftDistances(const ScanDescriptor& a, const ScanDescriptor& b) {
  JVL_CHECK(
      a.cells.rows() == b.cells.rows() && a.cells.cols() == b.cells.cols() && a.cells.size() > 0,
      "scan descriptors of different or empty shapes: " << a.cells.rows() << " x " << a.cells.cols()
                                                        << " and " << b.cells.rows() << " x "
                                                        << b.cells.cols());
  const int sectors = static_cast<int>(a.cells.cols());
  const Eigen::MatrixXd cells_a = a.cells.cast<double>(), cells_b = b.cells.cast<double>();
  const Eigen::VectorXd norm_a = cells_a.colwise().norm();
  const Eigen::VectorXd norm_b = cells_b.colwise().norm();
  std::vector<double> out(static_cast<size_t>(sectors));
  for (int shift = 0; shift < sectors; ++shift) {
    double sum = 0;
    int counted = 0;
    for (int s = 0; s < sectors; ++s) {
      const int t = (s + shift) % sectors;
      const bool in_a = norm_a(s) > 0, in_b = norm_b(t) > 0;
      if (!in_a && !in_b) continue;
      ++counted;
      if (in_a && in_b) {
        const double cosine = cells_a.col(s).dot(cells_b.col(t)) / (norm_a(s) * norm_b(t));
        sum += std::max(0.0, 1.0 - cosine);
      } else {
        sum += 1.0;
      }
    }
    out[static_cast<size_t>(shift)] = counted > 0 ? sum / counted : 1.0;
  }
  return out;
}

DescriptorMatch BestShiftNear(const std::vector<double>& distances, int centre, int window) {
  const int sectors = static_cast<int>(distances.size());
  JVL_CHECK(sectors > 0 && window >= 0, "BestShiftNear: no distances or a negative window");
  DescriptorMatch best;
  best.distance = 2;
  // From centre outwards (centre, +1, -1, +2, ...): ties go to the shift nearest the centre.
  for (int k = 0; k <= std::min(window, sectors / 2); ++k) {
    for (int sign : {1, -1}) {
      if (k == 0 && sign < 0) continue;
      const int shift = (((centre + sign * k) % sectors) + sectors) % sectors;
      if (distances[static_cast<size_t>(shift)] < best.distance) {
        best.distance = distances[static_cast<size_t>(shift)];
        best.shift = shift;
      }
    }
  }
  const int signed_shift = best.shift > sectors / 2 ? best.shift - sectors : best.shift;
  best.yaw = 2 * kPi * signed_shift / sectors;
  return best;
}

DescriptorMatch CompareDescriptors(const ScanDescriptor& a, const ScanDescriptor& b) {
  const std::vector<double> distances = ShiftDistances(a, b);
  const int sectors = static_cast<int>(distances.size());
  return BestShiftNear(distances, 0, sectors / 2);
}

double RingKeyDistance(const ScanDescriptor& a, const ScanDescriptor& b) {
  JVL_CHECK(
      a.ring_key.size() == b.ring_key.size(),
      "ring keys of different lengths: " << a.ring_key.size() << " and " << b.ring_key.size());
  return (a.ring_key - b.ring_key).norm();
}

}  // namespace jvl::loop
