#include "loop/correction.h"

#include "core/check.h"

namespace jvl::loop {

void DistributeCorrection(size_t l, size_t n, const Rigid3d& corrected_n,
                          std::vector<Rigid3d>* world_from_cam) {
  JVL_CHECK(world_from_cam != nullptr, "DistributeCorrection: no poses");
  JVL_CHECK(l < n && n < world_from_cam->size(), "DistributeCorrection: need l < n < "
                                                     << world_from_cam->size() << ", got l = " << l
                                                     << ", n = " << n);
  std::vector<Rigid3d>& poses = *world_from_cam;
  // dT = T^_n T_n^-1 with T = cam_from_world, i.e. (corrected_n)^-1 * world_from_cam[n].
  const Rigid3d correction = corrected_n.Inverse() * poses[n];
  const Eigen::Vector3d phi = LogSO3(correction.rotation());
  const Eigen::Vector3d t = correction.translation();
  const double span = static_cast<double>(n - l);
  for (size_t i = l + 1; i < n; ++i) {
    const double w = static_cast<double>(i - l) / span;
    const Rigid3d part(ExpSO3(w * phi), w * t);
    // T^_i = dT_i T_i, so world_from_cam^_i = world_from_cam_i dT_i^-1.
    poses[i] = poses[i] * part.Inverse();
  }
  poses[n] = corrected_n;
}

}  // namespace jvl::loop
