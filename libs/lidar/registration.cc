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
                                      const AssociationOptions& o, int threads) {
  std::vector<Correspondence> c(points.size());
  constexpr int64_t kChunk = 64;
  const int64_t chunks = (static_cast<int64_t>(points.size()) + kChunk - 1) / kChunk;
  ParallelFor(chunks, threads, [&](int64_t chunk) {
    const size_t end = std::min(points.size(), static_cast<size_t>((chunk + 1) * kChunk));
    ImlsProjection p;
    for (size_t i = static_cast<size_t>(chunk * kChunk); i < end; ++i) {
      const Eigen::Vector3d x = t * points[i];
      if (!ProjectPoint(model, x, o, &p)) continue;
      c[i] = {true, x, p.normal, p.distance};
    }
  });
  return c;
}

}  // namespace

void RegistrationOptions::Check() const {
  JVL_CHECK(max_iterations >= 1, "max_iterations must be >= 1, got " << max_iterations);
  JVL_CHECK(robust_scale > 0, "robust_scale must be > 0, got " << robust_scale);
  JVL_CHECK(convergence_translation >= 0,
            "convergence_translation must be >= 0, got " << convergence_translation);
  JVL_CHECK(convergence_rotation >= 0,
            "convergence_rotation must be >= 0, got " << convergence_rotation);
  JVL_CHECK(min_correspondences >= 6,
            "min_correspondences must be >= 6, got " << min_correspondences);
  JVL_CHECK(degeneracy_threshold >= 0,
            "degeneracy_threshold must be >= 0, got " << degeneracy_threshold);
}

RegistrationResult RegisterScan(const std::vector<Eigen::Vector3d>& points, const ImlsModel& model,
                                const Rigid3d& initial, const AssociationOptions& association,
                                const RegistrationOptions& options, int threads,
                                const std::vector<double>* planarity) {
  JVL_CHECK(planarity == nullptr || planarity->size() == points.size(),
            "planarity has " << planarity->size() << " entries for " << points.size() << " points");
  RegistrationResult result;
  result.world_from_scan = initial;
  // Characteristic length that makes rotation columns comparable to translation ones.
  double range2 = 0;
  for (const Eigen::Vector3d& p : points) range2 += p.squaredNorm();
  const double length = points.empty() ? 1.0 : std::max(1.0, std::sqrt(range2 / points.size()));
  Rigid3d t = initial;
  Eigen::Matrix<double, 6, Eigen::Dynamic> weak_directions;  // Of the last iteration.
  for (int it = 0; it < options.max_iterations; ++it) {
    const std::vector<Correspondence> corr = Associate(points, model, t, association, threads);
    // Normal equations of sum w (I + J d)^2 with J = [n, ((x - c) x n) / L] and the rotation
    // applied about the sensor position c (keeps translation and rotation decoupled).
    Matrix6d h = Matrix6d::Zero(), h_obs = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    double sum_w = 0, sum_obs = 0, sum_r2 = 0;
    int count = 0;
    for (size_t i = 0; i < corr.size(); ++i) {  // Fixed order: deterministic sums.
      const Correspondence& c = corr[i];
      if (!c.valid) continue;
      Vector6d j;
      j.head<3>() = c.normal;
      j.tail<3>() = (c.x - t.translation()).cross(c.normal) / length;
      const double s = c.distance / options.robust_scale;
      const double w = 1.0 / (1.0 + s * s);  // Cauchy.
      h += w * j * j.transpose();
      g += w * c.distance * j;
      sum_w += w;
      // Observability counts planar evidence: corners and edges (low a2D) have biased normals.
      const double a2 = planarity ? (*planarity)[i] * (*planarity)[i] : 1.0;
      h_obs += w * a2 * j * j.transpose();
      sum_obs += w * a2;
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
    // Unobservable directions: eigenvectors of the (planarity-weighted) normal matrix with a
    // small eigenvalue. The update is solved in the complementary subspace.
    const Eigen::SelfAdjointEigenSolver<Matrix6d> obs(h_obs / std::max(sum_obs, 1e-300));
    result.min_eigenvalue = obs.eigenvalues()[0];
    int weak = 0;
    weak_directions.resize(6, 0);
    for (int k = 0; k < 6; ++k) {
      if (obs.eigenvalues()[k] >= options.degeneracy_threshold) continue;
      ++weak;
      weak_directions.conservativeResize(6, weak);
      weak_directions.col(weak - 1) = obs.eigenvectors().col(k);
    }
    Matrix6d project = Matrix6d::Identity();
    for (int k = 0; k < weak; ++k) {
      project -= weak_directions.col(k) * weak_directions.col(k).transpose();
    }
    // Minimise over d = P z: (P H P + (I - P)) z = -P g keeps d in the observable subspace.
    const Matrix6d a = project * (h / sum_w) * project + (Matrix6d::Identity() - project);
    const Vector6d delta = project * a.ldlt().solve(-project * (g / sum_w));
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
  if (result.degenerate) {
    // Earlier iterations may have moved along a direction found unobservable at the end (the
    // solution slides along a corridor): remove that component of the total change so the
    // pose keeps the initial guess (motion model) along it.
    Vector6d total;
    total.head<3>() = t.translation() - initial.translation();
    total.tail<3>() = LogSO3(t.rotation() * initial.rotation().inverse()) * length;
    for (int k = 0; k < weak_directions.cols(); ++k) {
      total -= weak_directions.col(k).dot(total) * weak_directions.col(k);
    }
    t = Rigid3d(ExpSO3(total.tail<3>() / length) * initial.rotation(),
                initial.translation() + total.head<3>());
  }
  result.world_from_scan = t;
  return result;
}

RegistrationResult RegisterSurface(const ScanSurface& surface, const ImlsModel& model,
                                   const Rigid3d& start, const AssociationOptions& association,
                                   const RegistrationOptions& options, int threads, int* samples) {
  return RegisterSampled(SampleSurface(surface, association.samples_per_list), model, start,
                         association, options, threads, samples);
}

RegistrationResult RegisterSampled(const SampledScan& scan, const ImlsModel& model,
                                   const Rigid3d& start, const AssociationOptions& association,
                                   const RegistrationOptions& options, int threads, int* samples) {
  const std::vector<int> picked = SelectSamples(scan, start, model, association);
  std::vector<Eigen::Vector3d> points;
  std::vector<double> planarity;
  points.reserve(picked.size());
  planarity.reserve(picked.size());
  for (const int i : picked) {
    points.push_back(scan.points[i]);
    planarity.push_back(scan.planarity[i]);
  }
  if (samples) *samples = static_cast<int>(points.size());
  return RegisterScan(points, model, start, association, options, threads, &planarity);
}

void ScaleNeighbourhoods(double k, AssociationOptions* association, RegistrationOptions* options) {
  association->search_radius *= k;
  association->kernel_h *= k;
  association->max_distance *= k;
  options->robust_scale *= k;
}

}  // namespace jvl::lidar
