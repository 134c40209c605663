#include "lidar/voxel_grid.h"

#include <algorithm>
#include <numeric>
#include <unordered_set>

#include "core/check.h"

namespace jvl::lidar {

std::vector<size_t> VoxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                    double voxel_size) {
  std::vector<size_t> kept;
  if (voxel_size <= 0) {
    kept.resize(points.size());
    std::iota(kept.begin(), kept.end(), size_t{0});
    return kept;
  }
  const double inv = 1.0 / voxel_size;
  std::unordered_set<uint64_t, CellHash> seen;
  seen.reserve(points.size());
  kept.reserve(points.size() / 2);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3i c = CellOf(points[i], inv);
    if (seen.insert(PackCell(c.x(), c.y(), c.z())).second) kept.push_back(i);
  }
  return kept;
}

PointGrid::PointGrid(const std::vector<Eigen::Vector3d>& points, double cell_size)
    : points_(points), cell_size_(cell_size), inv_cell_(1.0 / cell_size) {
  JVL_CHECK(cell_size > 0, "grid cell size must be > 0, got " << cell_size);
  std::vector<uint64_t> keys(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3i c = CellOf(points[i], inv_cell_);
    keys[i] = PackCell(c.x(), c.y(), c.z());
  }
  order_.resize(points.size());
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return keys[a] < keys[b]; });
  cells_.reserve(points.size() / 2 + 1);
  for (size_t i = 0; i < order_.size();) {
    size_t j = i + 1;
    while (j < order_.size() && keys[order_[j]] == keys[order_[i]]) ++j;
    cells_.emplace(keys[order_[i]], std::make_pair(static_cast<int>(i), static_cast<int>(j)));
    i = j;
  }
}

template <typename Fn>
void PointGrid::ForEachNear(const Eigen::Vector3d& q, Fn&& fn) const {
  const Eigen::Vector3i c = CellOf(q, inv_cell_);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = cells_.find(PackCell(c.x() + dx, c.y() + dy, c.z() + dz));
        if (it == cells_.end()) continue;
        for (int k = it->second.first; k < it->second.second; ++k) {
          if (!fn(order_[k])) return;
        }
      }
    }
  }
}

void PointGrid::RadiusSearch(const Eigen::Vector3d& q, double radius, size_t max_count,
                             std::vector<std::pair<double, int>>* out) const {
  out->clear();
  const double r2 = radius * radius;
  ForEachNear(q, [&](int i) {
    const double d2 = (points_[i] - q).squaredNorm();
    if (d2 <= r2) out->emplace_back(d2, i);
    return true;
  });
  // Ties broken by index so that the result does not depend on the cell visiting order.
  if (max_count > 0 && out->size() > max_count) {
    std::partial_sort(out->begin(), out->begin() + max_count, out->end());
    out->resize(max_count);
  } else {
    std::sort(out->begin(), out->end());
  }
}

int PointGrid::CountWithin(const Eigen::Vector3d& q, double radius, int stop_at) const {
  const double r2 = radius * radius;
  int count = 0;
  ForEachNear(q, [&](int i) {
    if ((points_[i] - q).squaredNorm() <= r2) ++count;
    return stop_at <= 0 || count < stop_at;
  });
  return count;
}

}  // namespace jvl::lidar
