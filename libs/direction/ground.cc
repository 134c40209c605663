#include "direction/ground.h"

#include <cmath>

#include "core/check.h"

namespace jvl::direction {

GroundFrame MakeGroundFrame(const Trajectory& prior, const Eigen::Vector3d& up) {
  JVL_CHECK(!prior.empty(), "direction: the prior trajectory is empty");
  const Eigen::Matrix3d r0 = prior.world_from_cam.front().RotationMatrix();
  GroundFrame g;
  g.up = up.norm() > 1e-12 ? up.normalized() : Eigen::Vector3d(-r0.col(1));
  // The first camera's x axis, or the world axis least parallel to up if that is degenerate.
  Eigen::Vector3d x = r0.col(0) - r0.col(0).dot(g.up) * g.up;
  if (x.norm() < 0.1) {
    Eigen::Index i = 0;
    g.up.cwiseAbs().minCoeff(&i);
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(i);
    x = axis - axis.dot(g.up) * g.up;
  }
  g.e1 = x.normalized();
  g.e2 = g.up.cross(g.e1);
  return g;
}

std::vector<Eigen::Vector2d> ForwardDirections(const Trajectory& prior, const GroundFrame& ground,
                                               double baseline) {
  const size_t n = prior.size();
  const double half = baseline / 2.0;
  std::vector<Eigen::Vector2d> fd(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& ti = prior.world_from_cam[i].translation();
    size_t j = i, k = i;
    while (j + 1 < n && (prior.world_from_cam[j].translation() - ti).norm() < half) ++j;
    while (k > 0 && (prior.world_from_cam[k].translation() - ti).norm() < half) --k;
    const Eigen::Vector3d motion =
        prior.world_from_cam[j].translation() - prior.world_from_cam[k].translation();
    Eigen::Vector2d g = ground.Project(motion);
    if (motion.norm() < half || g.norm() < 1e-9) {
      g = ground.Project(prior.world_from_cam[i].rotation() * Eigen::Vector3d::UnitZ());
    }
    fd[i] = g.norm() > 1e-12 ? g.normalized() : Eigen::Vector2d::UnitY();
  }
  return fd;
}

double SlopeDeg(const GroundFrame& ground, const Eigen::Vector3d& direction) {
  const Eigen::Vector2d g = ground.Project(direction);
  double a = std::atan2(g.y(), g.x()) * 180.0 / M_PI;
  if (a < 0) a += 180.0;
  if (a >= 180.0) a -= 180.0;
  return a;
}

}  // namespace jvl::direction
