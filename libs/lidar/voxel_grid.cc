#include "lidar/voxel_grid.h"

#include <algorithm>
#include <array>
#include <numeric>

#include "core/check.h"
#include "core/threads.h"

namespace jvl::lidar {

void CellMap::Reserve(size_t expected) {
  size_t capacity = 16;
  while (capacity < 2 * expected) capacity *= 2;
  if (capacity <= slots_.size()) return;
  std::vector<Slot> old = std::move(slots_);
  slots_.assign(capacity, Slot());
  mask_ = capacity - 1;
  size_ = 0;
  for (const Slot& s : old) {
    if (s.value >= 0) Insert(s.key, s.value);
  }
}

void CellMap::Clear(size_t expected) {
  size_t capacity = 16;
  while (capacity < 2 * expected) capacity *= 2;
  if (capacity == slots_.size()) {
    std::fill(slots_.begin(), slots_.end(), Slot());
  } else {
    slots_.assign(capacity, Slot());
  }
  mask_ = capacity - 1;
  size_ = 0;
}

int CellMap::Insert(uint64_t key, int value) {
  if (2 * (size_ + 1) > slots_.size()) Reserve(size_ + 1);
  size_t slot = CellHash()(key) & mask_;
  while (slots_[slot].value >= 0) {
    if (slots_[slot].key == key) return slots_[slot].value;
    slot = (slot + 1) & mask_;
  }
  slots_[slot] = {key, value};
  ++size_;
  return value;
}

std::vector<size_t> VoxelDownsample(const std::vector<Eigen::Vector3d>& points, double voxel_size) {
  std::vector<size_t> kept;
  if (voxel_size <= 0) {
    kept.resize(points.size());
    std::iota(kept.begin(), kept.end(), size_t{0});
    return kept;
  }
  const double inv = 1.0 / voxel_size;
  // Kept per thread: scans of one drive need tables of the same size, which are then cleared
  // instead of allocated (and page-faulted in) again for every scan. A thread keeps the table of
  // its latest call (about 32 bytes per input point) until it ends.
  thread_local CellMap seen;
  seen.Clear(points.size());
  kept.reserve(points.size() / 2);
  // Consecutive points of a scan (neighbours along a ring) mostly share a voxel: a point in the
  // previous point's voxel is not the first in it and needs no lookup.
  uint64_t previous = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3i c = CellOf(points[i], inv);
    const uint64_t key = PackCell(c.x(), c.y(), c.z());
    if (i > 0 && key == previous) continue;
    previous = key;
    const size_t before = seen.size();
    seen.Insert(key, 0);
    if (seen.size() > before) kept.push_back(i);
  }
  return kept;
}

namespace {

// The 27 cell offsets around a cell, the cell itself first, then by the number of non-zero
// coordinates (face, edge, corner neighbours), each group in (x, y, z) order.
const std::array<Eigen::Vector3i, 27>& Offsets() {
  static const std::array<Eigen::Vector3i, 27> offsets = [] {
    std::array<Eigen::Vector3i, 27> o;
    int n = 0;
    for (int nonzero = 0; nonzero <= 3; ++nonzero) {
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            if ((dx != 0) + (dy != 0) + (dz != 0) == nonzero) o[n++] = {dx, dy, dz};
          }
        }
      }
    }
    return o;
  }();
  return offsets;
}

}  // namespace

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
  cells_.Reserve(points.size() / 2 + 1);
  for (size_t i = 0; i < order_.size();) {
    size_t j = i + 1;
    while (j < order_.size() && keys[order_[j]] == keys[order_[i]]) ++j;
    cells_.Insert(keys[order_[i]], static_cast<int>(cell_keys_.size()));
    cell_keys_.push_back(keys[order_[i]]);
    cell_begin_.push_back(static_cast<int>(i));
    i = j;
  }
  cell_begin_.push_back(static_cast<int>(order_.size()));
}

template <typename Fn>
void PointGrid::ForEachNear(const Eigen::Vector3d& q, Fn&& fn) const {
  const Eigen::Vector3i c = CellOf(q, inv_cell_);
  for (const Eigen::Vector3i& d : Offsets()) {
    const int cell = cells_.Find(PackCell(c.x() + d.x(), c.y() + d.y(), c.z() + d.z()));
    if (cell < 0) continue;
    for (int k = cell_begin_[cell]; k < cell_begin_[cell + 1]; ++k) {
      if (!fn(order_[k])) return;
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
  const std::array<Eigen::Vector3i, 27>& offsets = Offsets();
  constexpr int64_t kChunk = 64;
  const int64_t n = static_cast<int64_t>(cell_keys_.size());
  ParallelFor((n + kChunk - 1) / kChunk, threads, [&](int64_t chunk) {
    std::vector<int> members, candidates;
    for (int64_t c = chunk * kChunk; c < std::min(n, (chunk + 1) * kChunk); ++c) {
      members.assign(order_.begin() + cell_begin_[c], order_.begin() + cell_begin_[c + 1]);
      // Decode the cell from one member (cheaper than unpacking the key).
      const Eigen::Vector3i cell = CellOf(points_[members.front()], inv_cell_);
      candidates.clear();
      for (const Eigen::Vector3i& d : offsets) {
        const int m = cells_.Find(PackCell(cell.x() + d.x(), cell.y() + d.y(), cell.z() + d.z()));
        if (m < 0) continue;
        candidates.insert(candidates.end(), order_.begin() + cell_begin_[m],
                          order_.begin() + cell_begin_[m + 1]);
      }
      fn(members, candidates);
    }
  });
}

}  // namespace jvl::lidar
