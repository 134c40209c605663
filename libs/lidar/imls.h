// The IMLS surface of a model point set (paper Eq. 2, IMLS-SLAM Sec. III):
//
//   I(x) = sum_i W_i(x) ((x - p_i) . n_c) / sum_i W_i(x),   W_i(x) = exp(-|x - p_i|^2 / h^2),
//
// over the model points p_i within radius r of x, where n_c is the normal of the model point
// p_c nearest to x. The projection of x onto the implicit surface is y = x - I(x) n_c.
// The model is a hashed grid of world-frame points with normals, grouped by scan so that the
// odometry (and local mapping) can add the newest scan and drop the oldest one incrementally.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "lidar/voxel_grid.h"

namespace jvl::lidar {

struct ImlsProjection {
  double distance = 0;                                   // I(x), signed along n_c.
  Eigen::Vector3d projection = Eigen::Vector3d::Zero();  // y = x - I(x) n_c.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();      // n_c.
  Eigen::Vector3d nearest = Eigen::Vector3d::Zero();     // p_c.
  int64_t nearest_scan = -1;                             // Scan id p_c belongs to.
  int neighbors = 0;
};

class ImlsModel {
 public:
  // Queries visit the 27 cells around x when radius <= cell_size (the common case; choose
  // cell_size = the registration radius), more for larger radii.
  explicit ImlsModel(double cell_size);

  // Adds the world-frame points (with unit normals) of scan `scan_id`.
  void AddScan(int64_t scan_id, const std::vector<Eigen::Vector3d>& world_points,
               const std::vector<Eigen::Vector3d>& world_normals);
  // Removes every point of scan_id (no-op if absent).
  void RemoveScan(int64_t scan_id);
  void Clear();

  // Scan ids in insertion order.
  std::vector<int64_t> scan_ids() const;
  size_t num_scans() const { return scans_.size(); }
  size_t size() const { return num_points_; }
  double cell_size() const { return cell_size_; }

  // True if a model point lies within radius of x.
  bool HasNeighbor(const Eigen::Vector3d& x, double radius) const;
  // Eq. (2) and the projection. False (out untouched) when no model point is within radius.
  bool Project(const Eigen::Vector3d& x, double h, double radius, ImlsProjection* out) const;

 private:
  int Span(double radius) const;  // Cells to visit on each side.
  // Single precision halves the memory streamed by Project (the hot loop); at 2 km from the
  // world origin a float still resolves 0.12 mm.
  struct Entry {
    Eigen::Vector3f point, normal;
    int64_t scan;
  };
  // The entries of a cell (nullptr when the model has none).
  const std::vector<Entry>* Cell(uint64_t key) const {
    const int index = index_.Find(key);
    return index < 0 ? nullptr : &cells_[static_cast<size_t>(index)];
  }
  // Drops the cells left empty by RemoveScan from the index once they outnumber the others.
  void CompactIfSparse();
  double cell_size_, inv_cell_;
  size_t num_points_ = 0;
  // Cell key -> index into cells_ (open addressing: the 27 lookups of a query cost less than
  // the points they find). RemoveScan leaves emptied cells in place until CompactIfSparse.
  CellMap index_;
  std::vector<std::vector<Entry>> cells_;
  size_t empty_cells_ = 0;
  std::deque<std::pair<int64_t, std::vector<uint64_t>>> scans_;  // id, cells it touched.
};

}  // namespace jvl::lidar
