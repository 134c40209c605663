#include "optim/schur_lm.h"

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "core/check.h"
#include "core/timer.h"

namespace jvl::optim {
namespace {

// The trust-region defaults of Ceres' Solver::Options.
constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr int kMaxInvalidSteps = 5;

enum class Kind : int8_t { kConstant, kCamera, kPoint };

struct Camera {
  double* values = nullptr;
  int size = 0, tangent = 0;
  int offset = 0;                             // first column in the reduced system
  const ceres::Manifold* manifold = nullptr;  // nullptr: Euclidean
};

struct Slot {  // one parameter block of one residual block
  Kind kind = Kind::kConstant;
  int index = -1;     // camera or point
  int jacobian = -1;  // offset of its rows x tangent Jacobian (row-major) in jacobians_
  int entry = -1;     // a camera slot of a residual with a point: the (point, camera) entry of W
};

struct Residual {
  const ceres::CostFunction* cost = nullptr;
  const ceres::LossFunction* loss = nullptr;
  int first_slot = 0, num_slots = 0;
  int rows = 0, row = 0;  // residual count, first row in f_
  int point = -1;         // the point slot's index among the slots, -1 if none
  bool free = false;      // has a free parameter block
  // A 2-row residual on one free 6-dimensional camera and one free point (the visual term):
  // the slot of that camera, accumulated with fixed-size kernels. -1 otherwise.
  int visual_camera = -1;
};

struct Entry {  // W block of one point and one camera: tangent x 3, row-major
  int camera = 0;
  int offset = 0;
};

// c (a_cols x b_cols, row stride ldc) += a^T b for row-major a (m x a_cols), b (m x b_cols).
inline void AddAtB(const double* a, const double* b, int m, int a_cols, int b_cols, double* c,
                   int ldc) {
  for (int r = 0; r < m; ++r) {
    const double* ar = a + r * a_cols;
    const double* br = b + r * b_cols;
    for (int i = 0; i < a_cols; ++i) {
      const double ai = ar[i];
      double* ci = c + i * ldc;
      for (int j = 0; j < b_cols; ++j) ci[j] += ai * br[j];
    }
  }
}

class SchurLm {
 public:
  SchurLm(ceres::Problem& problem, const std::vector<double*>& eliminate,
          const SchurLmOptions& options)
      : problem_(problem), options_(options) {
    Setup(eliminate);
  }

  SchurLmSummary Run();

 private:
  void Setup(const std::vector<double*>& eliminate);
  // Cost (free part, fixed part) at the values in the parameter blocks; with `jacobians` also the
  // corrected residuals and tangent Jacobians (scaled once the scale is known). False if a cost
  // function fails or returns a non-finite value.
  bool Evaluate(bool jacobians, double* cost_free, double* cost_fixed);
  void BuildNormalEquations();
  // The scaled LM step for the current radius; false if a factorisation fails.
  bool ComputeStep(double radius, Eigen::VectorXd* step);
  double ModelCostChange(const Eigen::VectorXd& step) const;
  void SaveValues();
  void RestoreValues();
  // Writes x + delta into the parameter blocks; returns |x_new - x| (ambient).
  double ApplyStep(const Eigen::VectorXd& delta);
  double GradientMaxNorm() const;
  int PointColumn(int p) const { return reduced_ + 3 * p; }
  // Multiplies r's Jacobian columns by the Jacobi scaling scale_.
  void ScaleColumns(const Residual& r);
  // Calls fn(tangent, column, jacobian) for each non-constant parameter block of r in slot order:
  // its tangent size, its first column in the step and its Jacobian's offset in jacobians_
  // (row-major, r.rows x tangent).
  template <typename Fn>
  void ForEachFreeBlock(const Residual& r, Fn&& fn) const {
    for (int k = 0; k < r.num_slots; ++k) {
      const Slot& s = slots_[r.first_slot + k];
      if (s.kind == Kind::kConstant) continue;
      if (s.kind == Kind::kPoint)
        fn(3, PointColumn(s.index), s.jacobian);
      else
        fn(cameras_[s.index].tangent, cameras_[s.index].offset, s.jacobian);
    }
  }

  ceres::Problem& problem_;
  const SchurLmOptions options_;
  std::vector<Camera> cameras_;
  std::vector<double*> points_;
  std::vector<Residual> residuals_;
  std::vector<Slot> slots_;
  std::vector<double*> slot_values_;  // parameter pointers, slot order (Evaluate's argument)
  std::vector<int> ambient_offset_;   // per slot: its ambient Jacobian in scratch_ (-1: none)
  std::vector<Entry> entries_;
  std::vector<int> point_entries_;  // point p's entries: [point_entries_[p], [p + 1])
  int reduced_ = 0;                 // tangent dimensions of the cameras
  int max_slots_ = 1;  // parameter blocks of the largest residual block

  Eigen::VectorXd f_;            // corrected residuals at the current values
  Eigen::VectorXd candidate_f_;  // residuals of a cost-only evaluation
  std::vector<double> jacobians_;
  std::vector<double> scratch_;   // ambient Jacobians of one residual block
  std::vector<double> plus_jacobians_;  // per camera with a manifold: size x tangent
  std::vector<int> plus_offset_;
  Eigen::VectorXd scale_;  // Jacobi scaling per tangent column (empty until the first Jacobian)
  Eigen::VectorXd col_norm_;
  Eigen::VectorXd gradient_;  // scaled J^T f (cameras, then points)
  Eigen::VectorXd diagonal_;  // clamped diag(J^T J) of the scaled Jacobian
  Eigen::MatrixXd u_;         // cameras' block of J^T J (lower triangle filled)
  std::vector<Eigen::Matrix3d> v_;
  std::vector<Eigen::Matrix3d> v_inverse_;
  std::vector<double> w_;
  std::vector<double> saved_;  // ambient values of the free blocks: cameras, then points
  std::vector<double> y_;      // W V^-1 of one point's entries
};

void SchurLm::Setup(const std::vector<double*>& eliminate) {
  const std::unordered_set<double*> eliminated(eliminate.begin(), eliminate.end());
  std::unordered_map<double*, int> camera_of, point_of;
  std::vector<ceres::ResidualBlockId> ids;
  problem_.GetResidualBlocks(&ids);
  std::vector<double*> params;
  std::vector<std::vector<int>> point_cameras;  // point -> cameras in first-seen order
  int rows = 0, jacobian_size = 0, scratch_size = 0;
  for (const ceres::ResidualBlockId id : ids) {
    Residual r;
    r.cost = problem_.GetCostFunctionForResidualBlock(id);
    r.loss = problem_.GetLossFunctionForResidualBlock(id);
    r.rows = r.cost->num_residuals();
    r.row = rows;
    rows += r.rows;
    r.first_slot = static_cast<int>(slots_.size());
    problem_.GetParameterBlocksForResidualBlock(id, &params);
    r.num_slots = static_cast<int>(params.size());
    max_slots_ = std::max(max_slots_, r.num_slots);
    int scratch = 0;
    for (size_t k = 0; k < params.size(); ++k) {
      double* p = params[k];
      Slot s;
      if (problem_.IsParameterBlockConstant(p)) {
        s.kind = Kind::kConstant;
      } else if (eliminated.count(p)) {
        s.kind = Kind::kPoint;
        const auto [it, added] = point_of.emplace(p, static_cast<int>(points_.size()));
        if (added) {
          points_.push_back(p);
          point_cameras.emplace_back();
        }
        s.index = it->second;
        JVL_CHECK(r.point < 0, "residual block with two eliminated blocks");
        r.point = static_cast<int>(k);
      } else {
        s.kind = Kind::kCamera;
        const auto [it, added] = camera_of.emplace(p, static_cast<int>(cameras_.size()));
        if (added) {
          Camera c;
          c.values = p;
          c.size = problem_.ParameterBlockSize(p);
          c.tangent = problem_.ParameterBlockTangentSize(p);
          c.manifold = problem_.GetManifold(p);
          JVL_CHECK(c.tangent <= 8 && c.size <= 16,
                    "parameter block of tangent size " << c.tangent << " in the reduced system");
          c.offset = reduced_;
          reduced_ += c.tangent;
          cameras_.push_back(c);
        }
        s.index = it->second;
      }
      if (s.kind != Kind::kConstant) {
        const int tangent = s.kind == Kind::kPoint ? 3 : cameras_[s.index].tangent;
        const int size = s.kind == Kind::kPoint ? 3 : cameras_[s.index].size;
        s.jacobian = jacobian_size;
        jacobian_size += r.rows * tangent;
        ambient_offset_.push_back(scratch);
        scratch += r.rows * size;
        r.free = true;
      } else {
        ambient_offset_.push_back(-1);
      }
      slots_.push_back(s);
      slot_values_.push_back(p);
    }
    scratch_size = std::max(scratch_size, scratch);
    residuals_.push_back(r);
  }
  // The W entries: one per (point, camera) pair that shares a residual block.
  for (const Residual& r : residuals_) {
    if (r.point < 0) continue;
    const int p = slots_[r.first_slot + r.point].index;
    for (int k = 0; k < r.num_slots; ++k) {
      const Slot& s = slots_[r.first_slot + k];
      if (s.kind != Kind::kCamera) continue;
      auto& cams = point_cameras[p];
      if (std::find(cams.begin(), cams.end(), s.index) == cams.end()) cams.push_back(s.index);
    }
  }
  point_entries_.assign(points_.size() + 1, 0);
  int w_size = 0;
  for (size_t p = 0; p < points_.size(); ++p) {
    point_entries_[p] = static_cast<int>(entries_.size());
    for (const int c : point_cameras[p]) {
      entries_.push_back({c, w_size});
      w_size += cameras_[c].tangent * 3;
    }
  }
  point_entries_[points_.size()] = static_cast<int>(entries_.size());
  for (Residual& r : residuals_) {
    if (r.point < 0) continue;
    const int p = slots_[r.first_slot + r.point].index;
    for (int k = 0; k < r.num_slots; ++k) {
      Slot& s = slots_[r.first_slot + k];
      if (s.kind != Kind::kCamera) continue;
      for (int e = point_entries_[p]; e < point_entries_[p + 1]; ++e) {
        if (entries_[e].camera == s.index) s.entry = e;
      }
    }
  }
  for (Residual& r : residuals_) {
    if (r.rows != 2 || r.point < 0) continue;
    int cameras = 0, camera = -1;
    for (int k = 0; k < r.num_slots; ++k) {
      const Slot& s = slots_[r.first_slot + k];
      if (s.kind != Kind::kCamera) continue;
      ++cameras;
      if (cameras_[s.index].tangent == 6 && s.entry >= 0) camera = k;
    }
    if (cameras == 1) r.visual_camera = camera;
  }
  f_.resize(rows);
  candidate_f_.resize(rows);
  jacobians_.assign(jacobian_size, 0.0);
  scratch_.assign(scratch_size, 0.0);
  plus_offset_.assign(cameras_.size(), -1);
  int plus_size = 0;
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (cameras_[c].manifold == nullptr) continue;
    plus_offset_[c] = plus_size;
    plus_size += cameras_[c].size * cameras_[c].tangent;
  }
  plus_jacobians_.assign(plus_size, 0.0);
  const int columns = reduced_ + 3 * static_cast<int>(points_.size());
  col_norm_.resize(columns);
  gradient_.resize(columns);
  diagonal_.resize(columns);
  u_.resize(reduced_, reduced_);
  v_.resize(points_.size());
  v_inverse_.resize(points_.size());
  w_.assign(w_size, 0.0);
}

bool SchurLm::Evaluate(bool jacobians, double* cost_free, double* cost_fixed) {
  *cost_free = 0.0;
  *cost_fixed = 0.0;
  if (jacobians) {
    for (size_t c = 0; c < cameras_.size(); ++c) {
      if (plus_offset_[c] < 0) continue;
      if (!cameras_[c].manifold->PlusJacobian(cameras_[c].values,
                                              plus_jacobians_.data() + plus_offset_[c]))
        return false;
    }
  }
  std::vector<double*> ambient(static_cast<size_t>(max_slots_));
  for (const Residual& r : residuals_) {
    // A cost-only evaluation (a candidate step) must keep f_: the model of a rejected step's
    // successor is built from it.
    double* f = (jacobians ? f_.data() : candidate_f_.data()) + r.row;
    for (int k = 0; k < r.num_slots; ++k) {
      const int off = ambient_offset_[r.first_slot + k];
      ambient[k] = off >= 0 ? scratch_.data() + off : nullptr;
    }
    if (!r.cost->Evaluate(slot_values_.data() + r.first_slot, f,
                          jacobians && r.free ? ambient.data() : nullptr))
      return false;
    double sq = 0.0;
    for (int i = 0; i < r.rows; ++i) sq += f[i] * f[i];
    if (!std::isfinite(sq)) return false;
    double rho[3] = {sq, 1.0, 0.0};
    if (r.loss != nullptr) r.loss->Evaluate(sq, rho);
    (r.free ? *cost_free : *cost_fixed) += 0.5 * rho[0];
    if (!jacobians || !r.free) continue;
    // Tangent Jacobians: ambient x PlusJacobian (cameras with a manifold), else a copy.
    double check = 0.0;  // sum of all entries: not finite if any entry is not
    for (int k = 0; k < r.num_slots; ++k) {
      const Slot& s = slots_[r.first_slot + k];
      if (s.kind == Kind::kConstant) continue;
      const double* a = ambient[k];
      double* j = jacobians_.data() + s.jacobian;
      const bool plus = s.kind == Kind::kCamera && plus_offset_[s.index] >= 0;
      const int tangent = s.kind == Kind::kPoint ? 3 : cameras_[s.index].tangent;
      if (!plus) {
        std::copy(a, a + r.rows * tangent, j);
      } else if (r.rows == 2 && cameras_[s.index].size == 7 && tangent == 6) {
        // The visual residual on a pose block: (2 x 7) (7 x 6).
        using Ambient = Eigen::Matrix<double, 2, 7, Eigen::RowMajor>;
        using Plus = Eigen::Matrix<double, 7, 6, Eigen::RowMajor>;
        using Tangent = Eigen::Matrix<double, 2, 6, Eigen::RowMajor>;
        Eigen::Map<Tangent>(j).noalias() =
            Eigen::Map<const Ambient>(a) *
            Eigen::Map<const Plus>(plus_jacobians_.data() + plus_offset_[s.index]);
      } else {
        const int size = cameras_[s.index].size;
        const double* pj = plus_jacobians_.data() + plus_offset_[s.index];
        std::fill(j, j + r.rows * tangent, 0.0);
        for (int row = 0; row < r.rows; ++row) {
          for (int i = 0; i < size; ++i) {
            const double ai = a[row * size + i];
            for (int t = 0; t < tangent; ++t) j[row * tangent + t] += ai * pj[i * tangent + t];
          }
        }
      }
      for (int i = 0; i < r.rows * tangent; ++i) check += j[i];
    }
    if (!std::isfinite(check)) return false;
    if (r.loss != nullptr) {
      // Triggs' correction (Triggs et al., "Bundle Adjustment - A Modern Synthesis", 2000; as
      // Ceres applies it): the Gauss-Newton model of rho(|f|^2) from corrected f and J.
      const double sqrt_rho1 = std::sqrt(rho[1]);
      double residual_scaling = sqrt_rho1, alpha_sq_norm = 0.0;
      if (sq > 0.0 && rho[2] > 0.0) {
        const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq * rho[2] / rho[1]);
        residual_scaling = sqrt_rho1 / (1.0 - alpha);
        alpha_sq_norm = alpha / sq;
      }
      ForEachFreeBlock(r, [&](int tangent, int /*col*/, int offset) {
        double* j = jacobians_.data() + offset;
        if (alpha_sq_norm != 0.0) {
          for (int t = 0; t < tangent; ++t) {
            double ftj = 0.0;
            for (int row = 0; row < r.rows; ++row) ftj += f[row] * j[row * tangent + t];
            for (int row = 0; row < r.rows; ++row)
              j[row * tangent + t] -= alpha_sq_norm * f[row] * ftj;
          }
        }
        for (int i = 0; i < r.rows * tangent; ++i) j[i] *= sqrt_rho1;
      });
      for (int i = 0; i < r.rows; ++i) f[i] *= residual_scaling;
    }
    // Jacobi scaling (known after the first Jacobian): columns times scale_.
    if (scale_.size() > 0) ScaleColumns(r);
  }
  if (!jacobians || scale_.size() > 0) return true;
  // Jacobi scaling, fixed at the first Jacobian (as Ceres does): columns divided by 1 + norm.
  col_norm_.setZero();
  for (const Residual& r : residuals_) {
    if (!r.free) continue;
    ForEachFreeBlock(r, [&](int tangent, int col, int offset) {
      const double* j = jacobians_.data() + offset;
      for (int row = 0; row < r.rows; ++row)
        for (int t = 0; t < tangent; ++t)
          col_norm_[col + t] += j[row * tangent + t] * j[row * tangent + t];
    });
  }
  scale_ = (1.0 + col_norm_.array().sqrt()).inverse().matrix();
  for (const Residual& r : residuals_)
    if (r.free) ScaleColumns(r);
  return true;
}

void SchurLm::ScaleColumns(const Residual& r) {
  ForEachFreeBlock(r, [&](int tangent, int col, int offset) {
    double* j = jacobians_.data() + offset;
    const double* sc = scale_.data() + col;
    for (int row = 0; row < r.rows; ++row)
      for (int t = 0; t < tangent; ++t) j[row * tangent + t] *= sc[t];
  });
}

void SchurLm::BuildNormalEquations() {
  u_.setZero();
  gradient_.setZero();
  for (auto& v : v_) v.setZero();
  std::fill(w_.begin(), w_.end(), 0.0);
  for (const Residual& r : residuals_) {
    if (!r.free) continue;
    const double* f = f_.data() + r.row;
    const Slot* point = r.point >= 0 ? &slots_[r.first_slot + r.point] : nullptr;
    if (r.visual_camera >= 0) {
      const Slot& sc = slots_[r.first_slot + r.visual_camera];
      const int c = cameras_[sc.index].offset;
      const int pc = PointColumn(point->index);
      const Eigen::Map<const Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> jc(jacobians_.data() +
                                                                             sc.jacobian);
      const Eigen::Map<const Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jp(jacobians_.data() +
                                                                             point->jacobian);
      const Eigen::Map<const Eigen::Vector2d> fv(f);
      gradient_.segment<6>(c).noalias() += jc.transpose() * fv;
      gradient_.segment<3>(pc).noalias() += jp.transpose() * fv;
      u_.block<6, 6>(c, c).noalias() += jc.transpose() * jc;
      v_[point->index].noalias() += jp.transpose() * jp;
      Eigen::Map<Eigen::Matrix<double, 6, 3>>(w_.data() +
                                                                entries_[sc.entry].offset)
          .noalias() += jc.transpose() * jp;
      continue;
    }
    for (int a = 0; a < r.num_slots; ++a) {
      const Slot& sa = slots_[r.first_slot + a];
      if (sa.kind == Kind::kConstant) continue;
      const double* ja = jacobians_.data() + sa.jacobian;
      if (sa.kind == Kind::kPoint) {
        const int col = PointColumn(sa.index);
        AddAtB(ja, f, r.rows, 3, 1, gradient_.data() + col, 1);
        AddAtB(ja, ja, r.rows, 3, 3, v_[sa.index].data(), 3);  // symmetric: storage order moot
        continue;
      }
      const Camera& ca = cameras_[sa.index];
      AddAtB(ja, f, r.rows, ca.tangent, 1, gradient_.data() + ca.offset, 1);
      for (int b = 0; b < r.num_slots; ++b) {
        const Slot& sb = slots_[r.first_slot + b];
        if (sb.kind != Kind::kCamera) continue;
        const Camera& cb = cameras_[sb.index];
        if (cb.offset > ca.offset) continue;  // the lower triangle: rows of a >= rows of b
        // u_(ca.offset + i, cb.offset + j) += sum_rows J_a(row, i) J_b(row, j) (column-major).
        for (int row = 0; row < r.rows; ++row) {
          const double* ar = ja + row * ca.tangent;
          const double* br = jacobians_.data() + sb.jacobian + row * cb.tangent;
          for (int j = 0; j < cb.tangent; ++j) {
            double* column =
                u_.data() + static_cast<ptrdiff_t>(cb.offset + j) * reduced_ + ca.offset;
            const double bj = br[j];
            for (int i = 0; i < ca.tangent; ++i) column[i] += ar[i] * bj;
          }
        }
      }
      if (point != nullptr && sa.entry >= 0) {
        const double* jp = jacobians_.data() + point->jacobian;
        // W is column-major (tangent x 3): w[k * tangent + i] += sum_rows J_a(row, i) J_p(row, k).
        double* w = w_.data() + entries_[sa.entry].offset;
        for (int row = 0; row < r.rows; ++row)
          for (int k = 0; k < 3; ++k)
            for (int i = 0; i < ca.tangent; ++i)
              w[k * ca.tangent + i] += ja[row * ca.tangent + i] * jp[row * 3 + k];
      }
    }
  }
  // The diagonal of J^T J, clamped as Ceres' LM strategy does.
  for (const Camera& c : cameras_)
    for (int t = 0; t < c.tangent; ++t) diagonal_[c.offset + t] = u_(c.offset + t, c.offset + t);
  for (size_t p = 0; p < points_.size(); ++p)
    for (int t = 0; t < 3; ++t) diagonal_[PointColumn(static_cast<int>(p)) + t] = v_[p](t, t);
  diagonal_ = diagonal_.cwiseMax(kMinDiagonal).cwiseMin(kMaxDiagonal);
}

bool SchurLm::ComputeStep(double radius, Eigen::VectorXd* step) {
  const double inv_radius = 1.0 / radius;
  Eigen::MatrixXd s = u_;
  for (int i = 0; i < reduced_; ++i) s(i, i) += diagonal_[i] * inv_radius;
  Eigen::VectorXd rhs = -gradient_.head(reduced_);
  for (size_t p = 0; p < points_.size(); ++p) {
    const int col = PointColumn(static_cast<int>(p));
    Eigen::Matrix3d v = v_[p];
    for (int t = 0; t < 3; ++t) v(t, t) += diagonal_[col + t] * inv_radius;
    const Eigen::LLT<Eigen::Matrix3d> llt(v);
    if (llt.info() != Eigen::Success) return false;
    v_inverse_[p] = llt.solve(Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d& vi = v_inverse_[p];
    const Eigen::Vector3d y = vi * gradient_.segment<3>(col);
    const int begin = point_entries_[p], end = point_entries_[p + 1];
    y_.resize(static_cast<size_t>(std::max(0, (end - begin))) * 3 * 8);
    // W and Y = W V^-1 are column-major (tangent x 3), so that the 6 x 6 products below run
    // down contiguous columns.
    using W6 = Eigen::Matrix<double, 6, 3>;
    for (int e = begin; e < end; ++e) {
      const Camera& c = cameras_[entries_[e].camera];
      const double* w = w_.data() + entries_[e].offset;  // tangent x 3, column-major
      double* ye = y_.data() + static_cast<size_t>(e - begin) * 3 * 8;
      if (c.tangent == 6) {
        const Eigen::Map<const W6> wm(w);
        rhs.segment<6>(c.offset).noalias() += wm * y;
        Eigen::Map<W6>(ye).noalias() = wm * vi;
        continue;
      }
      for (int i = 0; i < c.tangent; ++i) {
        const int t = c.tangent;
        const Eigen::Vector3d wi(w[i], w[t + i], w[2 * t + i]);
        rhs[c.offset + i] += wi.dot(y);
        const Eigen::Vector3d yi = vi * wi;  // vi symmetric: row i of W V^-1
        ye[i] = yi[0];
        ye[t + i] = yi[1];
        ye[2 * t + i] = yi[2];
      }
    }
    for (int a = begin; a < end; ++a) {
      const Camera& ca = cameras_[entries_[a].camera];
      const double* ya = y_.data() + static_cast<size_t>(a - begin) * 3 * 8;
      for (int b = begin; b < end; ++b) {
        const Camera& cb = cameras_[entries_[b].camera];
        if (cb.offset > ca.offset) continue;  // lower triangle
        const double* wb = w_.data() + entries_[b].offset;
        if (ca.tangent == 6 && cb.tangent == 6) {
          const Eigen::Matrix<double, 6, 6> product =
              Eigen::Map<const W6>(ya).lazyProduct(Eigen::Map<const W6>(wb).transpose());
          s.block<6, 6>(ca.offset, cb.offset) -= product;
          continue;
        }
        for (int j = 0; j < cb.tangent; ++j) {
          double* column = s.data() + static_cast<ptrdiff_t>(cb.offset + j) * reduced_ + ca.offset;
          const int ta = ca.tangent, tb = cb.tangent;
          for (int i = 0; i < ta; ++i) {
            column[i] -= ya[i] * wb[j] + ya[ta + i] * wb[tb + j] + ya[2 * ta + i] * wb[2 * tb + j];
          }
        }
      }
    }
  }
  step->resize(gradient_.size());
  if (reduced_ > 0) {
    const Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(s);
    if (llt.info() != Eigen::Success) return false;
    step->head(reduced_) = llt.solve(rhs);
  }
  for (size_t p = 0; p < points_.size(); ++p) {
    const int col = PointColumn(static_cast<int>(p));
    Eigen::Vector3d t = -gradient_.segment<3>(col);
    for (int e = point_entries_[p]; e < point_entries_[p + 1]; ++e) {
      const Camera& c = cameras_[entries_[e].camera];
      const double* w = w_.data() + entries_[e].offset;
      for (int i = 0; i < c.tangent; ++i) {
        const double dc = (*step)[c.offset + i];
        t[0] -= w[i] * dc;
        t[1] -= w[c.tangent + i] * dc;
        t[2] -= w[2 * c.tangent + i] * dc;
      }
    }
    step->segment<3>(col) = v_inverse_[p] * t;
  }
  return step->allFinite();
}

double SchurLm::ModelCostChange(const Eigen::VectorXd& step) const {
  double change = 0.0;
  double jd[64];
  for (const Residual& r : residuals_) {
    if (!r.free) continue;
    JVL_CHECK(r.rows <= 64, "residual block with more than 64 residuals");
    std::fill(jd, jd + r.rows, 0.0);
    ForEachFreeBlock(r, [&](int tangent, int col, int offset) {
      const double* j = jacobians_.data() + offset;
      for (int row = 0; row < r.rows; ++row)
        for (int t = 0; t < tangent; ++t) jd[row] += j[row * tangent + t] * step[col + t];
    });
    const double* f = f_.data() + r.row;
    for (int row = 0; row < r.rows; ++row) change -= jd[row] * (f[row] + 0.5 * jd[row]);
  }
  return change;
}

void SchurLm::SaveValues() {
  saved_.clear();
  for (const Camera& c : cameras_) saved_.insert(saved_.end(), c.values, c.values + c.size);
  for (double* p : points_) saved_.insert(saved_.end(), p, p + 3);
}

void SchurLm::RestoreValues() {
  size_t i = 0;
  for (const Camera& c : cameras_) {
    std::copy(saved_.begin() + i, saved_.begin() + i + c.size, c.values);
    i += c.size;
  }
  for (double* p : points_) {
    std::copy(saved_.begin() + i, saved_.begin() + i + 3, p);
    i += 3;
  }
}

double SchurLm::ApplyStep(const Eigen::VectorXd& delta) {
  double sq = 0.0;
  size_t i = 0;
  for (const Camera& c : cameras_) {
    const double* x = saved_.data() + i;
    if (c.manifold != nullptr) {
      c.manifold->Plus(x, delta.data() + c.offset, c.values);
    } else {
      for (int k = 0; k < c.size; ++k) c.values[k] = x[k] + delta[c.offset + k];
    }
    for (int k = 0; k < c.size; ++k) sq += (c.values[k] - x[k]) * (c.values[k] - x[k]);
    i += c.size;
  }
  for (size_t p = 0; p < points_.size(); ++p) {
    const double* x = saved_.data() + i;
    const int col = PointColumn(static_cast<int>(p));
    for (int k = 0; k < 3; ++k) {
      points_[p][k] = x[k] + delta[col + k];
      sq += delta[col + k] * delta[col + k];
    }
    i += 3;
  }
  return std::sqrt(sq);
}

// max |x - Plus(x, -g)| with the unscaled gradient g (Ceres' gradient test).
double SchurLm::GradientMaxNorm() const {
  double m = 0.0;
  std::vector<double> minus, moved;
  for (const Camera& c : cameras_) {
    minus.resize(c.tangent);
    for (int t = 0; t < c.tangent; ++t)
      minus[t] = -gradient_[c.offset + t] / scale_[c.offset + t];
    if (c.manifold == nullptr) {
      for (const double v : minus) m = std::max(m, std::abs(v));
      continue;
    }
    moved.resize(c.size);
    c.manifold->Plus(c.values, minus.data(), moved.data());
    for (int k = 0; k < c.size; ++k) m = std::max(m, std::abs(c.values[k] - moved[k]));
  }
  for (int col = reduced_; col < gradient_.size(); ++col)
    m = std::max(m, std::abs(gradient_[col] / scale_[col]));
  return m;
}

SchurLmSummary SchurLm::Run() {
  const Timer timer;
  SchurLmSummary summary;
  const char* termination = "";
  double cost = 0.0, fixed = 0.0;
  const auto finish = [&](const char* why) {
    termination = why;
    summary.final_cost = cost + fixed;
    char line[256];
    std::snprintf(line, sizeof(line),
                  "Schur LM: %s, iterations %d (%d successful), cost %.6g -> %.6g", termination,
                  summary.iterations, summary.successful_steps, summary.initial_cost,
                  summary.final_cost);
    summary.report = line;
    return summary;
  };
  SaveValues();
  if (!Evaluate(true, &cost, &fixed)) {
    RestoreValues();
    summary.initial_cost = summary.final_cost = std::numeric_limits<double>::infinity();
    summary.report = "Schur LM: FAILURE, the initial evaluation failed";
    return summary;
  }
  summary.initial_cost = cost + fixed;
  BuildNormalEquations();
  summary.usable = true;
  if (GradientMaxNorm() <= options_.gradient_tolerance) {
    summary.converged = true;
    return finish("CONVERGENCE (gradient tolerance)");
  }
  double radius = kInitialRadius, decrease_factor = 2.0;
  int invalid = 0;
  Eigen::VectorXd step, delta;
  while (true) {
    if (summary.iterations >= options_.max_iterations) return finish("NO_CONVERGENCE (iterations)");
    if (timer.ElapsedSeconds() >= options_.max_time_s) return finish("NO_CONVERGENCE (time)");
    if (radius < kMinRadius) {
      summary.converged = true;
      return finish("CONVERGENCE (minimum trust region radius)");
    }
    ++summary.iterations;
    const bool solved = ComputeStep(radius, &step);
    const double model_change = solved ? ModelCostChange(step) : 0.0;
    if (!(model_change > 0.0)) {
      if (++invalid >= kMaxInvalidSteps) {
        summary.usable = false;
        RestoreValues();
        return finish("FAILURE (consecutive invalid steps)");
      }
      radius /= decrease_factor;
      decrease_factor *= 2.0;
      continue;
    }
    invalid = 0;
    delta = step.cwiseProduct(scale_);
    double x_sq = 0.0;
    for (const double v : saved_) x_sq += v * v;
    const double step_norm = ApplyStep(delta);
    if (step_norm <= options_.parameter_tolerance *
                         (std::sqrt(x_sq) + options_.parameter_tolerance)) {
      RestoreValues();
      summary.converged = true;
      --summary.iterations;  // as Ceres counts: the iteration that stops is not recorded
      return finish("CONVERGENCE (parameter tolerance)");
    }
    double candidate = 0.0, candidate_fixed = 0.0;
    if (!Evaluate(false, &candidate, &candidate_fixed))
      candidate = std::numeric_limits<double>::max();
    const double change = cost - candidate;
    if (std::abs(change) <= options_.function_tolerance * cost) {
      RestoreValues();
      summary.converged = true;
      --summary.iterations;  // as Ceres counts: the iteration that stops is not recorded
      return finish("CONVERGENCE (function tolerance)");
    }
    const double relative_decrease = change / model_change;
    if (relative_decrease > kMinRelativeDecrease) {
      ++summary.successful_steps;
      const double shrink = 1.0 - std::pow(2.0 * relative_decrease - 1.0, 3);
      radius = std::min(kMaxRadius, radius / std::max(1.0 / 3.0, shrink));
      decrease_factor = 2.0;
      SaveValues();
      if (!Evaluate(true, &cost, &fixed)) {
        summary.usable = false;
        return finish("FAILURE (evaluation at an accepted step)");
      }
      BuildNormalEquations();
      if (!options_.progress_label.empty())
        spdlog::info("{} iteration {}: cost {:.6g}, {:.1f} s", options_.progress_label,
                     summary.iterations, cost + fixed, timer.ElapsedSeconds());
      if (GradientMaxNorm() <= options_.gradient_tolerance) {
        summary.converged = true;
        return finish("CONVERGENCE (gradient tolerance)");
      }
    } else {
      RestoreValues();
      radius /= decrease_factor;
      decrease_factor *= 2.0;
      if (!options_.progress_label.empty())
        spdlog::info("{} iteration {}: cost {:.6g} (step rejected), {:.1f} s",
                     options_.progress_label, summary.iterations, cost + fixed,
                     timer.ElapsedSeconds());
    }
  }
}

}  // namespace

bool SchurLmApplies(const ceres::Problem& problem, const std::vector<double*>& eliminate,
                    int max_reduced) {
  const std::unordered_set<double*> eliminated(eliminate.begin(), eliminate.end());
  for (double* p : eliminate) {
    if (!problem.HasParameterBlock(p)) continue;
    if (problem.ParameterBlockSize(p) != 3 || problem.GetManifold(p) != nullptr) return false;
  }
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  std::unordered_set<double*> cameras;
  int reduced = 0;
  std::vector<double*> params;
  for (const ceres::ResidualBlockId id : ids) {
    problem.GetParameterBlocksForResidualBlock(id, &params);
    if (problem.GetCostFunctionForResidualBlock(id)->num_residuals() > 64) return false;
    int points = 0;
    for (double* p : params) {
      if (eliminated.count(p)) {
        ++points;
      } else if (!problem.IsParameterBlockConstant(p) && cameras.insert(p).second) {
        reduced += problem.ParameterBlockTangentSize(p);
        if (problem.ParameterBlockTangentSize(p) > 8) return false;
      }
    }
    if (points > 1 || reduced > max_reduced) return false;
  }
  return true;
}

SchurLmSummary SolveSchurLm(ceres::Problem& problem, const std::vector<double*>& eliminate,
                            const SchurLmOptions& options) {
  JVL_CHECK(options.max_iterations > 0, "max_iterations must be positive");
  SchurLm solver(problem, eliminate, options);
  return solver.Run();
}

}  // namespace jvl::optim
