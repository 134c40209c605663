#include "lidar/imls.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"

namespace jvl::lidar {

ImlsModel::ImlsModel(double cell_size) : cell_size_(cell_size), inv_cell_(1.0 / cell_size) {
  JVL_CHECK(cell_size > 0, "IMLS model cell size must be > 0, got " << cell_size);
}

void ImlsModel::AddScan(int64_t scan_id, const std::vector<Eigen::Vector3d>& world_points,
                        const std::vector<Eigen::Vector3d>& world_normals) {
  JVL_CHECK(world_points.size() == world_normals.size(),
            "scan " << scan_id << ": " << world_points.size() << " points but "
                    << world_normals.size() << " normals");
  std::vector<uint64_t> touched;
  for (size_t i = 0; i < world_points.size(); ++i) {
    const Eigen::Vector3i c = CellOf(world_points[i], inv_cell_);
    const uint64_t key = PackCell(c.x(), c.y(), c.z());
    const size_t index = static_cast<size_t>(index_.Insert(key, static_cast<int>(cells_.size())));
    const bool fresh = index == cells_.size();
    if (fresh) cells_.emplace_back();
    std::vector<Entry>& cell = cells_[index];
    if (cell.empty() && !fresh) --empty_cells_;  // A cell emptied by RemoveScan, filled again.
    if (cell.empty() || cell.back().scan != scan_id) touched.push_back(key);
    cell.push_back({world_points[i].cast<float>(), world_normals[i].cast<float>(), scan_id});
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  num_points_ += world_points.size();
  scans_.emplace_back(scan_id, std::move(touched));
}

void ImlsModel::RemoveScan(int64_t scan_id) {
  const auto it =
      std::find_if(scans_.begin(), scans_.end(), [&](const auto& s) { return s.first == scan_id; });
  if (it == scans_.end()) return;
  for (const uint64_t key : it->second) {
    const int index = index_.Find(key);
    if (index < 0) continue;
    std::vector<Entry>& v = cells_[static_cast<size_t>(index)];
    const size_t before = v.size();
    v.erase(std::remove_if(v.begin(), v.end(), [&](const Entry& e) { return e.scan == scan_id; }),
            v.end());
    num_points_ -= before - v.size();
    if (before > 0 && v.empty()) {
      std::vector<Entry>().swap(v);
      ++empty_cells_;
    }
  }
  scans_.erase(it);
  CompactIfSparse();
}

void ImlsModel::CompactIfSparse() {
  if (empty_cells_ < 4096 || 2 * empty_cells_ < cells_.size()) return;
  // The non-empty cells again, in their order (a cell's entries keep theirs, so every query
  // sums in the same order as before).
  std::vector<std::vector<Entry>> kept;
  kept.reserve(cells_.size() - empty_cells_);
  CellMap index(cells_.size() - empty_cells_);
  for (const auto& [id, keys] : scans_) {
    for (const uint64_t key : keys) {
      std::vector<Entry>& v = cells_[static_cast<size_t>(index_.Find(key))];
      if (v.empty()) continue;  // Moved already (a cell shared by several scans).
      index.Insert(key, static_cast<int>(kept.size()));
      kept.push_back(std::move(v));
    }
  }
  cells_ = std::move(kept);
  index_ = std::move(index);
  empty_cells_ = 0;
}

void ImlsModel::Clear() {
  index_ = CellMap();
  cells_.clear();
  empty_cells_ = 0;
  scans_.clear();
  num_points_ = 0;
}

std::vector<int64_t> ImlsModel::scan_ids() const {
  std::vector<int64_t> ids;
  for (const auto& s : scans_) ids.push_back(s.first);
  return ids;
}

int ImlsModel::Span(double radius) const {
  return std::max(1, static_cast<int>(std::ceil(radius * inv_cell_ - 1e-9)));
}

bool ImlsModel::HasNeighbor(const Eigen::Vector3d& x, double radius) const {
  const double r2 = radius * radius;
  const Eigen::Vector3i c = CellOf(x, inv_cell_);
  const int span = Span(radius);
  for (int dx = -span; dx <= span; ++dx) {
    for (int dy = -span; dy <= span; ++dy) {
      for (int dz = -span; dz <= span; ++dz) {
        const std::vector<Entry>* cell = Cell(PackCell(c.x() + dx, c.y() + dy, c.z() + dz));
        if (cell == nullptr) continue;
        for (const Entry& e : *cell) {
          if ((e.point.cast<double>() - x).squaredNorm() <= r2) return true;
        }
      }
    }
  }
  return false;
}

bool ImlsModel::Project(const Eigen::Vector3d& x, double h, double radius,
                        ImlsProjection* out) const {
  const double r2 = radius * radius;
  const double inv_h2 = 1.0 / (h * h);
  const Eigen::Vector3i c = CellOf(x, inv_cell_);
  // One pass: the nearest point (for n_c) and the weighted sums of Eq. (2), which are linear
  // in n_c: sum W (x - p_i).n_c = (sum W (x - p_i)).n_c.
  double best = std::numeric_limits<double>::infinity();
  const Entry* nearest = nullptr;
  double sum_w = 0;
  Eigen::Vector3d sum_wd = Eigen::Vector3d::Zero();
  int count = 0;
  const int span = Span(radius);
  for (int dx = -span; dx <= span; ++dx) {
    for (int dy = -span; dy <= span; ++dy) {
      for (int dz = -span; dz <= span; ++dz) {
        const std::vector<Entry>* cell = Cell(PackCell(c.x() + dx, c.y() + dy, c.z() + dz));
        if (cell == nullptr) continue;
        for (const Entry& e : *cell) {
          const Eigen::Vector3d d = x - e.point.cast<double>();
          const double d2 = d.squaredNorm();
          if (d2 > r2) continue;
          const double w = std::exp(-d2 * inv_h2);
          sum_w += w;
          sum_wd += w * d;
          ++count;
          if (d2 < best) {
            best = d2;
            nearest = &e;
          }
        }
      }
    }
  }
  if (nearest == nullptr) return false;
  out->normal = nearest->normal.cast<double>().normalized();
  out->nearest = nearest->point.cast<double>();
  out->nearest_scan = nearest->scan;
  out->neighbors = count;
  // Far from every point relative to h all weights underflow: the nearest point alone
  // defines the surface (the limit of Eq. 2 as h -> 0).
  const Eigen::Vector3d mean_d = sum_w > std::numeric_limits<double>::min()
                                     ? Eigen::Vector3d(sum_wd / sum_w)
                                     : Eigen::Vector3d(x - out->nearest);
  out->distance = mean_d.dot(out->normal);
  out->projection = x - out->distance * out->normal;
  return true;
}

}  // namespace jvl::lidar
