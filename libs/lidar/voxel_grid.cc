#include "lidar/voxel_grid.h"

#include <algorithm>
#include <numeric>

#include "core/check.h"
#include "core/threads.h"

namespace jvl::lidar {

std::vector<size_t> VoxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                    double voxel_size) {
  std::vector<size_t> kept;
  if (voxel_size <= 0) {
    kept.resize(points.size());
    std::iota(kept.begin(), kept.end(), size_t{0});
    return kept;
  }
  // Open-addressing set of occupied voxel keys (linear probing, power-of-two table): several
  // times faster than std::unordered_set on 100k+ points.
  const double inv = 1.0 / voxel_size;
  size_t capacity = 16;
  while (capacity < 2 * points.size()) capacity *= 2;
  constexpr uint64_t kEmpty = ~uint64_t{0};
  std::vector<uint64_t> table(capacity, kEmpty);
  const CellHash hash;
  kept.reserve(points.size() / 2);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3i c = CellOf(points[i], inv);
    const uint64_t key = PackCell(c.x(), c.y(), c.z());
    size_t slot = hash(key) & (capacity - 1);
    while (table[slot] != kEmpty && table[slot] != key) slot = (slot + 1) & (capacity - 1);
    if (table[slot] == kEmpty) {
      table[slot] = key;
      kept.push_back(i);
    }
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
    cell_keys_.push_back(keys[order_[i]]);
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

void PointGrid::ForEachCell(
    int threads,
    const std::function<void(const std::vector<int>&, const std::vector<int>&)>& fn) const {
  constexpr int64_t kChunk = 64;
  const int64_t n = static_cast<int64_t>(cell_keys_.size());
  ParallelFor((n + kChunk - 1) / kChunk, threads, [&](int64_t chunk) {
    std::vector<int> members, candidates;
    for (int64_t c = chunk * kChunk; c < std::min(n, (chunk + 1) * kChunk); ++c) {
      const uint64_t key = cell_keys_[c];
      const auto range = cells_.at(key);
      members.assign(order_.begin() + range.first, order_.begin() + range.second);
      // Decode the cell from one member (cheaper than unpacking the key).
      const Eigen::Vector3i cell = CellOf(points_[members.front()], inv_cell_);
      candidates.clear();
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = cells_.find(PackCell(cell.x() + dx, cell.y() + dy, cell.z() + dz));
            if (it == cells_.end()) continue;
            candidates.insert(candidates.end(), order_.begin() + it->second.first,
                              order_.begin() + it->second.second);
          }
        }
      }
      fn(members, candidates);
    }
  });
}

}  // namespace jvl::lidar
