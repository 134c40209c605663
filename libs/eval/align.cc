#include "eval/align.h"

#include <Eigen/LU>
#include <Eigen/SVD>

#include "core/check.h"

namespace jvl::eval {

Alignment ParseAlignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "origin") return Alignment::kOrigin;
  if (name == "se3") return Alignment::kSE3;
  if (name == "sim3") return Alignment::kSim3;
  JVL_THROW("unknown alignment '" << name << "' (expected none, origin, se3 or sim3)");
}

std::string ToString(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone:
      return "none";
    case Alignment::kOrigin:
      return "origin";
    case Alignment::kSE3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
  }
  return "?";
}

Eigen::Matrix4d Similarity::Apply(const Eigen::Matrix4d& pose) const {
  Eigen::Matrix4d scaled = pose;
  scaled.block<3, 1>(0, 3) *= scale;
  Eigen::Matrix4d a = Eigen::Matrix4d::Identity();
  a.topLeftCorner<3, 3>() = rotation;
  a.block<3, 1>(0, 3) = translation;
  return a * scaled;
}

Similarity Umeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                   bool with_scale) {
  JVL_CHECK(src.size() == dst.size(),
            "Umeyama: " << src.size() << " vs " << dst.size() << " points");
  JVL_CHECK(src.size() >= 3, "alignment needs at least 3 matched poses, got " << src.size());
  const double n = static_cast<double>(src.size());
  Eigen::Vector3d mean_src = Eigen::Vector3d::Zero(), mean_dst = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) mean_src += src[i], mean_dst += dst[i];
  mean_src /= n;
  mean_dst /= n;
  double var_src = 0;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) {
    const Eigen::Vector3d a = src[i] - mean_src;
    var_src += a.squaredNorm();
    cov += (dst[i] - mean_dst) * a.transpose();
  }
  var_src /= n;
  cov /= n;
  JVL_CHECK(var_src > 0, "alignment: all estimated positions are equal (degenerate trajectory)");
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s(2) = -1;
  Similarity sim;
  sim.rotation = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  sim.scale = with_scale ? svd.singularValues().dot(s) / var_src : 1.0;
  sim.translation = mean_dst - sim.scale * sim.rotation * mean_src;
  const Eigen::Vector3d sv = svd.singularValues();
  sim.conditioning = sv(0) > 0 ? sv(1) / sv(0) : 0.0;
  return sim;
}

}  // namespace jvl::eval
