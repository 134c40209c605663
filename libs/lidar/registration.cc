#include "lidar/registration.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/threads.h"

namespace jvl::lidar {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct Correspondence {
  bool valid = false;
  Eigen::Vector3d x, normal;  // World-frame point at the current pose; n_c.
  double distance = 0;        // I(x) = n_c . (x - y).
};

// Projects every point (Eq. 2) at pose T; slots keep the order of `points`.
std::vector<Correspondence> Associate(const std::vector<Eigen::Vector3d>& points,
                                      const ImlsModel& model, const Rigid3d& t,
                                      const RegistrationOptions& o, int threads) {
  std::vector<Correspondence> c(points.size());
  constexpr int64_t kChunk = 64;
  const int64_t chunks = (static_cast<int64_t>(points.size()) + kChunk - 1) / kChunk;
  ParallelFor(chunks, threads, [&](int64_t chunk) {
    const size_t end = std::min(points.size(), static_cast<size_t>((chunk + 1) * kChunk));
    ImlsProjection p;
    for (size_t i = static_cast<size_t>(chunk * kChunk); i < end; ++i) {
      const Eigen::Vector3d x = t * points[i];
      if (!model.Project(x, o.kernel_h, o.search_radius, &p)) continue;
      if (std::abs(p.distance) > o.max_distance) continue;
      c[i] = {true, x, p.normal, p.distance};
    }
  });
  return c;
}

}  // namespace

void RegistrationOptions::Check() const {
  JVL_CHECK(max_iterations >= 1, "--max-iterations must be >= 1, got " << max_iterations);
  JVL_CHECK(kernel_h > 0, "--imls-h must be > 0, got " << kernel_h);
  JVL_CHECK(search_radius > 0, "--imls-radius must be > 0, got " << search_radius);
  JVL_CHECK(max_distance > 0, "--max-distance must be > 0, got " << max_distance);
  JVL_CHECK(robust_scale > 0, "--robust-scale must be > 0, got " << robust_scale);
  JVL_CHECK(convergence_translation >= 0 && convergence_rotation >= 0,
            "convergence thresholds must be >= 0");
  JVL_CHECK(min_correspondences >= 6,
            "--min-correspondences must be >= 6, got " << min_correspondences);
  JVL_CHECK(degeneracy_threshold >= 0,
            "--degeneracy-threshold must be >= 0, got " << degeneracy_threshold);
}

RegistrationResult RegisterScan(const std::vector<Eigen::Vector3d>& points,
                                const ImlsModel& model, const Rigid3d& initial,
                                const RegistrationOptions& options, int threads) {
  RegistrationResult result;
  result.world_from_scan = initial;
  // Characteristic length that makes rotation columns comparable to translation ones.
  double range2 = 0;
  for (const Eigen::Vector3d& p : points) range2 += p.squaredNorm();
  const double length = points.empty() ? 1.0 : std::max(1.0, std::sqrt(range2 / points.size()));
  Rigid3d t = initial;
  for (int it = 0; it < options.max_iterations; ++it) {
    const std::vector<Correspondence> corr = Associate(points, model, t, options, threads);
    // Normal equations of sum w (I + J d)^2 with J = [n, ((x - c) x n) / L] and the rotation
    // applied about the sensor position c (keeps translation and rotation decoupled).
    Matrix6d h = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    double sum_w = 0, sum_r2 = 0;
    int count = 0;
    for (const Correspondence& c : corr) {  // Fixed order: deterministic sums.
      if (!c.valid) continue;
      Vector6d j;
      j.head<3>() = c.normal;
      j.tail<3>() = (c.x - t.translation()).cross(c.normal) / length;
      const double s = c.distance / options.robust_scale;
      const double w = 1.0 / (1.0 + s * s);  // Cauchy.
      h += w * j * j.transpose();
      g += w * c.distance * j;
      sum_w += w;
      sum_r2 += c.distance * c.distance;
      ++count;
    }
    result.iterations = it + 1;
    result.correspondences = count;
    result.residual = count > 0 ? std::sqrt(sum_r2 / count) : 0.0;
    if (count < options.min_correspondences) {
      result.ok = false;
      result.world_from_scan = initial;
      return result;
    }
    result.ok = true;
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(h / sum_w);
    result.min_eigenvalue = eig.eigenvalues()[0];
    // Solve in the eigenbasis, dropping unobservable directions (they keep the initial guess).
    Vector6d delta = Vector6d::Zero();
    const Vector6d rhs = -eig.eigenvectors().transpose() * (g / sum_w);
    int weak = 0;
    for (int k = 0; k < 6; ++k) {
      if (eig.eigenvalues()[k] < options.degeneracy_threshold) {
        ++weak;
        continue;
      }
      delta += (rhs[k] / eig.eigenvalues()[k]) * eig.eigenvectors().col(k);
    }
    result.degenerate_directions = weak;
    result.degenerate = weak > 0;
    const Eigen::Vector3d v = delta.head<3>();
    const Eigen::Vector3d omega = delta.tail<3>() / length;
    // x' = R_d (x - c) + c + v with c = t: the new pose is (R_d R, t + v).
    t = Rigid3d(ExpSO3(omega) * t.rotation(), t.translation() + v);
    if (v.norm() < options.convergence_translation && omega.norm() < options.convergence_rotation) {
      result.converged = true;
      break;
    }
  }
  result.world_from_scan = t;
  return result;
}

}  // namespace jvl::lidar
