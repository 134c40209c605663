#include "optim/joint_problem.h"

#include <ceres/loss_function.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <utility>

#include "core/check.h"
#include "core/statistics.h"
#include "optim/analytic_costs.h"
#include "optim/cost_functions.h"
#include "optim/imls_pair_cost.h"

namespace jvl::optim {
namespace {

bool Finite(const Eigen::Vector3d& v) { return v.allFinite(); }

// Weight and Huber kernel of one residual type; ScaledLoss(nullptr, w) is a plain weight.
ceres::LossFunction* MakeLoss(double weight, double huber) {
  ceres::LossFunction* robust = huber > 0 ? new ceres::HuberLoss(huber) : nullptr;
  return new ceres::ScaledLoss(robust, weight, ceres::TAKE_OWNERSHIP);
}

// Sums per ordered keyframe pair: the summed pairs first, then the correspondences in input order
// (a fixed order, so the sums are the same on every run).
std::map<std::pair<int64_t, int64_t>, ImlsPairAccumulator> SumByPair(
    const std::vector<ImlsPair>& summed, const std::vector<ImlsCorrespondence>& correspondences) {
  std::map<std::pair<int64_t, int64_t>, ImlsPairAccumulator> pairs;
  for (const ImlsPair& p : summed) pairs[{p.n, p.c}].Merge(p.sum);
  for (const ImlsCorrespondence& l : correspondences)
    pairs[{l.n, l.c}].Add(l.p_x, l.c_p_y, l.c_normal);
  return pairs;
}

void CheckKeyframe(const JointProblemInput& input, int64_t id, const char* what) {
  JVL_CHECK(input.poses.count(id), what << " refers to keyframe " << id << " which has no pose");
}

// All validation happens before anything is added to the problem (no half-built state).
void CheckResiduals(const JointProblemInput& input) {
  for (const VisualObservation& obs : input.Observations()) {
    CheckKeyframe(input, obs.keyframe, "visual observation");
    JVL_CHECK(obs.map_point >= 0 && static_cast<size_t>(obs.map_point) < input.map_points.size(),
              "observation in keyframe " << obs.keyframe << " refers to map point " << obs.map_point
                                         << " of " << input.map_points.size());
    JVL_CHECK(obs.uv.allFinite() && obs.octave >= 0,
              "observation of map point " << obs.map_point << " in keyframe " << obs.keyframe
                                          << " has a non-finite pixel or negative octave");
  }
  for (const ImlsCorrespondence& l : input.imls) {
    CheckKeyframe(input, l.n, "IMLS correspondence");
    CheckKeyframe(input, l.c, "IMLS correspondence");
    JVL_CHECK(l.n != l.c,
              "IMLS correspondence with n == c == " << l.n << " (must join two keyframes)");
    JVL_CHECK(Finite(l.p_x) && Finite(l.c_p_y) && Finite(l.c_normal) &&
                  std::abs(l.c_normal.norm() - 1.0) < 1e-3,
              "IMLS correspondence (" << l.n << ", " << l.c
                                      << ") has non-finite points or a non-unit normal");
  }
  for (const ImlsPair& p : input.imls_pairs) {
    CheckKeyframe(input, p.n, "IMLS pair");
    CheckKeyframe(input, p.c, "IMLS pair");
    JVL_CHECK(p.n != p.c, "IMLS pair with n == c == " << p.n << " (must join two keyframes)");
    JVL_CHECK(p.sum.count() > 0 && p.sum.information().allFinite(),
              "IMLS pair (" << p.n << ", " << p.c << ") is empty or not finite");
  }
  for (const DirectionConstraint& d : input.directions) {
    CheckKeyframe(input, d.keyframe, "direction constraint");
    JVL_CHECK(d.vp.allFinite() && Finite(d.direction_world) && d.direction_world.norm() > 1e-9,
              "direction constraint of keyframe " << d.keyframe
                                                  << " has a non-finite VP or a zero direction");
    JVL_CHECK(d.free_direction < static_cast<int32_t>(input.free_directions.size()),
              "direction constraint of keyframe " << d.keyframe << " refers to free direction "
                                                  << d.free_direction << " of "
                                                  << input.free_directions.size());
  }
  for (const RelativePoseConstraint& r : input.relative_poses) {
    CheckKeyframe(input, r.i, "relative pose constraint");
    CheckKeyframe(input, r.j, "relative pose constraint");
    JVL_CHECK(r.i != r.j, "relative pose constraint with i == j == " << r.i);
    JVL_CHECK(r.sigma_rad.allFinite() && r.sigma_rad.minCoeff() > 0 && r.sigma_m.allFinite() &&
                  r.sigma_m.minCoeff() > 0 && Finite(r.i_from_j.translation()) &&
                  r.i_from_j.rotation().coeffs().allFinite(),
              "relative pose constraint (" << r.i << ", " << r.j
                                           << ") has a non-finite motion or a sigma <= 0");
  }
  for (const MotionConstraint& m : input.motion) {
    CheckKeyframe(input, m.a, "motion constraint");
    CheckKeyframe(input, m.b, "motion constraint");
    CheckKeyframe(input, m.c, "motion constraint");
    JVL_CHECK(m.a != m.b && m.b != m.c && m.a != m.c, "motion constraint ("
                                                          << m.a << ", " << m.b << ", " << m.c
                                                          << ") needs three different keyframes");
    JVL_CHECK(std::isfinite(m.frames_ab) && std::isfinite(m.frames_bc) && m.frames_ab > 0 &&
                  m.frames_bc > 0 && m.sigma_m.allFinite() && m.sigma_m.minCoeff() > 0,
              "motion constraint (" << m.a << ", " << m.b << ", " << m.c
                                    << ") has a frame gap or a sigma <= 0");
  }
  for (const PointSurfaceConstraint& c : input.point_surfaces) {
    CheckKeyframe(input, c.keyframe, "surface constraint");
    JVL_CHECK(c.map_point >= 0 && static_cast<size_t>(c.map_point) < input.map_points.size(),
              "surface constraint of keyframe " << c.keyframe << " refers to map point "
                                                << c.map_point << " of "
                                                << input.map_points.size());
    JVL_CHECK(Finite(c.k_p_y) && Finite(c.k_normal) && std::abs(c.k_normal.norm() - 1.0) < 1e-3,
              "surface constraint of keyframe " << c.keyframe << " / map point " << c.map_point
                                                << " has a non-finite point or a non-unit normal");
  }
  for (size_t i = 0; i < input.free_directions.size(); ++i)
    JVL_CHECK(Finite(input.free_directions[i]) && input.free_directions[i].norm() > 1e-9,
              "free direction " << i << " is not finite or zero");
}

void CheckInput(const JointProblemInput& input) {
  input.camera.Check();
  JVL_CHECK(!input.poses.empty(), "joint problem has no keyframe poses");
  for (const auto& [id, pose] : input.poses) {
    JVL_CHECK(pose.translation().allFinite() && pose.rotation().coeffs().allFinite(),
              "pose of keyframe " << id << " is not finite");
  }
  for (int64_t id : input.fixed) {
    JVL_CHECK(input.poses.count(id), "fixed keyframe " << id << " has no pose");
  }
  for (size_t i = 0; i < input.map_points.size(); ++i) {
    JVL_CHECK(Finite(input.map_points[i]), "map point " << i << " is not finite");
  }
  CheckResiduals(input);
}

// `kept` receives the (keyframe, map point) pairs that entered the visual term, sorted.
void AddVisual(const JointProblemInput& input, const JointProblemOptions& options,
               ceres::LossFunction* loss, JointProblem& jp,
               std::vector<std::pair<int64_t, int32_t>>* kept) {
  const auto& observations = input.Observations();
  // First pass: which observations enter (in front of the camera, within the gate).
  std::vector<char> keep(observations.size(), 0);
  std::vector<int32_t> kept_per_point(input.map_points.size(), 0);
  // For max_point_sigma_ratio: each point's information sum J^T J and nearest camera distance.
  const bool check_weak = options.optimize_map_points && options.max_point_sigma_ratio > 0;
  std::vector<Eigen::Matrix3d> information(check_weak ? input.map_points.size() : 0,
                                           Eigen::Matrix3d::Zero());
  std::vector<double> nearest(check_weak ? input.map_points.size() : 0,
                              std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < observations.size(); ++k) {
    const VisualObservation& obs = observations[k];
    // Drop what is behind the camera now: the functor could not be evaluated (ORB-SLAM removes
    // such observations before BA as well).
    const Eigen::Vector3d x_c =
        input.poses.at(obs.keyframe).Inverse() * input.map_points[obs.map_point] +
        input.camera_offset;
    if (!(x_c.z() > VisualReprojectionCost::kMinDepth)) {
      ++jp.dropped_observations;
      continue;
    }
    const double sigma = std::pow(options.octave_scale_factor, obs.octave);
    if (options.visual_gate_chi2 > 0) {
      const Eigen::Vector2d error = (input.camera.Project(x_c) - obs.uv) / sigma;
      if (!(error.squaredNorm() <= options.visual_gate_chi2)) {
        ++jp.gated_observations;
        continue;
      }
    }
    keep[k] = 1;
    ++kept_per_point[obs.map_point];
    if (check_weak) {
      const Eigen::Matrix<double, 2, 3> j_w =
          PixelResidualJacobian(input.camera.fx, input.camera.fy, 1.0 / sigma, x_c) *
          input.poses.at(obs.keyframe).RotationMatrix().transpose();
      information[obs.map_point] += j_w.transpose() * j_w;
      nearest[obs.map_point] = std::min(nearest[obs.map_point], x_c.norm());
    }
  }
  // A free point with a single observation has no depth information: leave it out.
  const bool gate_points = options.visual_gate_chi2 > 0 && options.optimize_map_points;
  if (gate_points) {
    for (size_t k = 0; k < observations.size(); ++k) {
      if (!keep[k] || kept_per_point[observations[k].map_point] >= 2) continue;
      keep[k] = 0;
      ++jp.gated_observations;
    }
    jp.gated_points = std::count(kept_per_point.begin(), kept_per_point.end(), 1);
  }
  // Points whose position the kept observations do not determine well (max_point_sigma_ratio).
  std::vector<char> weak(check_weak ? input.map_points.size() : 0, 0);
  for (size_t i = 0; i < weak.size(); ++i) {
    if (kept_per_point[i] == 0 || (gate_points && kept_per_point[i] < 2)) continue;
    // lambda_min <= 0 (a single ray, or all rays parallel) means an unbounded sigma.
    const double lambda_min =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(information[i], Eigen::EigenvaluesOnly)
            .eigenvalues()(0);
    const double bound = options.max_point_sigma_ratio * nearest[i];
    if (lambda_min * bound * bound > 1.0) continue;
    weak[i] = 1;
    ++jp.weak_points;
  }
  const bool drop_weak = check_weak && options.drop_weak_points;
  std::vector<bool> used(input.map_points.size(), false);
  for (size_t k = 0; k < observations.size(); ++k) {
    if (!keep[k]) continue;
    const VisualObservation& obs = observations[k];
    if ((drop_weak || static_cast<size_t>(obs.map_point) >= input.drop_weak_from) && check_weak &&
        weak[obs.map_point]) {
      ++jp.gated_observations;
      continue;
    }
    double* pose = jp.poses.at(obs.keyframe).data();
    double* point = jp.map_points[obs.map_point].data();
    const double sigma = std::pow(options.octave_scale_factor, obs.octave);
    ceres::CostFunction* cost =
        options.analytic_jacobians
            ? static_cast<ceres::CostFunction*>(new VisualReprojectionAnalyticCost(
                  input.camera, obs.uv, 1.0 / sigma, input.camera_offset))
            : VisualReprojectionCost::Create(input.camera, obs.uv, 1.0 / sigma,
                                             input.camera_offset);
    jp.visual_blocks.push_back(jp.problem->AddResidualBlock(cost, loss, pose, point));
    kept->emplace_back(obs.keyframe, obs.map_point);
    used[obs.map_point] = true;
  }
  for (size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    if (!options.optimize_map_points || (check_weak && weak[i])) {
      jp.problem->SetParameterBlockConstant(jp.map_points[i].data());
    } else {
      jp.has_free_map_points = true;
    }
  }
}

// RMS of one pair's residuals at the problem's initial poses: sum r_i^2 = x^T H x.
double PairRms(const ImlsPairAccumulator& sum, const PoseBlock& pose_n, const PoseBlock& pose_c) {
  const Eigen::Matrix<double, 13, 1> x =
      ImlsPairCost::RelativePoseVector(pose_n.data(), pose_c.data());
  const Eigen::Matrix<double, 13, 13> h = sum.information().selfadjointView<Eigen::Lower>();
  return std::sqrt(std::max(0.0, x.dot(h * x)) / static_cast<double>(sum.count()));
}

void AddImls(const JointProblemInput& input, const JointProblemOptions& options,
             ceres::LossFunction* loss, JointProblem& jp) {
  const double sqrt_info = 1.0 / options.imls_sigma_m;
  if (options.SumsImlsPerPair()) {
    // One exact block per keyframe pair (imls_pair_cost.h).
    const auto pairs = SumByPair(input.imls_pairs, input.imls);
    // imls_pair_noise_max: each pair's sigma from its RMS residual against the median pair's.
    std::vector<double> factor(pairs.size(), 1.0);
    if (options.imls_pair_noise_max > 1.0 && !pairs.empty()) {
      std::vector<double> rms;
      rms.reserve(pairs.size());
      for (const auto& [key, sum] : pairs)
        rms.push_back(
            sum.count() > 0 ? PairRms(sum, jp.poses.at(key.first), jp.poses.at(key.second)) : 0.0);
      const double median = UpperMedian(rms);
      jp.imls_pair_median_rms_m = median;
      if (median > 0) {
        size_t i = 0;
        for (const auto& [key, sum] : pairs) {
          // The gauge's pairs keep one sigma: they are what ties the rest of the problem to the
          // gauge. Once the free poses have moved as a whole (later rounds of global mapping
          // start from the previous result), only the gauge's pairs show large residuals, and
          // widening them would let the rest turn away from the gauge further.
          const bool gauge = jp.fixed.count(key.first) || jp.fixed.count(key.second);
          if (!gauge) factor[i] = std::clamp(rms[i] / median, 1.0, options.imls_pair_noise_max);
          if (factor[i] > 1.0) ++jp.imls_pairs_inflated;
          ++i;
        }
      }
    }
    size_t i = 0;
    for (const auto& [key, sum] : pairs) {
      auto cost = std::make_unique<ImlsPairCost>(sum, sqrt_info / factor[i++]);
      if (cost->rank() == 0) continue;  // only for an all-zero sum; nothing to add
      jp.imls_blocks.push_back(jp.problem->AddResidualBlock(
          cost.release(), loss, jp.poses.at(key.first).data(), jp.poses.at(key.second).data()));
      jp.imls_block_counts.push_back(sum.count());
    }
    return;
  }
  for (const ImlsCorrespondence& l : input.imls) {
    double* pose_n = jp.poses.at(l.n).data();
    double* pose_c = jp.poses.at(l.c).data();
    ceres::CostFunction* cost =
        options.analytic_jacobians ? static_cast<ceres::CostFunction*>(new PointToImlsAnalyticCost(
                                         l.p_x, l.c_p_y, l.c_normal, sqrt_info))
                                   : PointToImlsCost::Create(l.p_x, l.c_p_y, l.c_normal, sqrt_info);
    jp.imls_blocks.push_back(jp.problem->AddResidualBlock(cost, loss, pose_n, pose_c));
    jp.imls_block_counts.push_back(1);
  }
}

void AddDirections(const JointProblemInput& input, const JointProblemOptions& options,
                   ceres::LossFunction* loss, JointProblem& jp) {
  const Eigen::Vector2d sqrt_info(
      1.0 / options.direction_sigma_px,
      1.0 / (options.direction_sigma_v_px > 0 ? options.direction_sigma_v_px
                                              : options.direction_sigma_px));
  for (const DirectionConstraint& d : input.directions) {
    double* pose = jp.poses.at(d.keyframe).data();
    const double min_z = options.direction_min_z;
    if (d.ray_form) {
      JVL_CHECK(d.free_direction >= 0, "a ray-form direction constraint needs a free direction");
      jp.direction_blocks.push_back(jp.problem->AddResidualBlock(
          new DirectionAngleFreeCost(d.ray, 1.0 / options.direction_sigma_rad), loss, pose,
          jp.free_directions[static_cast<size_t>(d.free_direction)].data()));
      continue;
    }
    if (d.free_direction >= 0) {
      jp.direction_blocks.push_back(jp.problem->AddResidualBlock(
          new DirectionProjectionFreeCost(input.camera, d.vp, sqrt_info, min_z), loss, pose,
          jp.free_directions[static_cast<size_t>(d.free_direction)].data()));
      continue;
    }
    ceres::CostFunction* cost =
        options.analytic_jacobians
            ? static_cast<ceres::CostFunction*>(new DirectionProjectionAnalyticCost(
                  input.camera, d.vp, d.direction_world, sqrt_info, min_z))
            : DirectionProjectionCost::Create(input.camera, d.vp, d.direction_world, sqrt_info,
                                              min_z);
    jp.direction_blocks.push_back(jp.problem->AddResidualBlock(cost, loss, pose));
  }
}

}  // namespace

void JointProblemOptions::Check() const {
  JVL_CHECK(std::isfinite(alpha) && alpha > 0, "alpha must be positive (got " << alpha << ")");
  JVL_CHECK(std::isfinite(beta) && std::isfinite(gamma), "beta and gamma must be finite");
  JVL_CHECK(beta_scale > 0 && gamma_scale > 0, "beta_scale and gamma_scale must be positive");
  JVL_CHECK(octave_scale_factor >= 1, "octave_scale_factor must be >= 1");
  JVL_CHECK(imls_sigma_m > 0 && direction_sigma_px > 0, "residual sigmas must be positive");
  JVL_CHECK(std::isfinite(direction_sigma_rad) && direction_sigma_rad > 0,
            "direction_sigma_rad must be positive");
  JVL_CHECK(std::isfinite(direction_sigma_v_px) && direction_sigma_v_px >= 0,
            "direction_sigma_v_px must be >= 0 (0: as direction_sigma_px)");
  JVL_CHECK(direction_min_z > 0 && direction_min_z < 1, "direction_min_z must be in (0, 1)");
  JVL_CHECK(std::isfinite(imls_pair_noise_max), "imls_pair_noise_max must be finite");
  JVL_CHECK(std::isfinite(relative_cauchy), "relative_cauchy must be finite");
  JVL_CHECK(std::isfinite(motion_cauchy), "motion_cauchy must be finite");
  JVL_CHECK(std::isfinite(surface_sigma_m) && surface_sigma_m > 0,
            "surface_sigma_m must be positive");
  JVL_CHECK(std::isfinite(surface_cauchy), "surface_cauchy must be finite");
  JVL_CHECK(std::isfinite(visual_gate_chi2), "visual_gate_chi2 must be finite");
  JVL_CHECK(std::isfinite(max_point_sigma_ratio), "max_point_sigma_ratio must be finite");
  JVL_CHECK(
      std::isfinite(visual_huber) && std::isfinite(imls_huber) && std::isfinite(direction_huber),
      "Huber thresholds must be finite");
}

std::vector<ImlsPair> AggregateImls(const std::vector<ImlsCorrespondence>& correspondences) {
  const auto pairs = SumByPair({}, correspondences);
  std::vector<ImlsPair> out;
  out.reserve(pairs.size());
  for (const auto& [key, sum] : pairs) out.push_back({key.first, key.second, sum});
  return out;
}

int64_t CountImls(const JointProblemInput& input) {
  int64_t n = static_cast<int64_t>(input.imls.size());
  for (const ImlsPair& p : input.imls_pairs) n += p.sum.count();
  return n;
}

JointWeights ResolveWeights(const JointProblemOptions& options, int64_t num_visual,
                            int64_t num_imls, int64_t num_directions) {
  const double n_ref = static_cast<double>(
      num_visual > 0 ? num_visual : std::max<int64_t>({num_imls, num_directions, 1}));
  JointWeights w;
  w.alpha = options.alpha;
  w.beta = options.beta > 0 ? options.beta
           : num_imls > 0   ? options.alpha * options.beta_scale * n_ref / num_imls
                            : options.alpha * options.beta_scale;
  w.gamma = options.gamma > 0    ? options.gamma
            : num_directions > 0 ? options.alpha * options.gamma_scale * n_ref / num_directions
                                 : options.alpha * options.gamma_scale;
  return w;
}

JointProblem BuildJointProblem(const JointProblemInput& input, const JointProblemOptions& options) {
  options.Check();
  CheckInput(input);
  JointProblem jp;
  for (const auto& [id, pose] : input.poses) jp.poses[id] = ToPoseBlock(pose);
  jp.map_points.reserve(input.map_points.size());  // addresses must stay stable
  for (const Eigen::Vector3d& p : input.map_points) jp.map_points.push_back({p.x(), p.y(), p.z()});
  jp.free_directions.reserve(input.free_directions.size());
  for (const Eigen::Vector3d& d : input.free_directions) {
    const Eigen::Vector3d u = d.normalized();
    jp.free_directions.push_back({u.x(), u.y(), u.z()});
  }

  ceres::Problem::Options problem_options;
  problem_options.enable_fast_removal = false;
  jp.problem = std::make_unique<ceres::Problem>(problem_options);
  // One shared manifold; Ceres deletes each distinct pointer once.
  ceres::Manifold* manifold = MakePoseManifold().release();
  for (auto& [id, block] : jp.poses) {
    jp.problem->AddParameterBlock(block.data(), kPoseBlockSize, manifold);
  }
  if (!jp.free_directions.empty()) {
    ceres::Manifold* sphere = new ceres::SphereManifold<3>();
    for (auto& d : jp.free_directions) jp.problem->AddParameterBlock(d.data(), 3, sphere);
  }
  // Counts for the weight rule are taken from the inputs (before dropping invalid observations).
  JVL_CHECK(input.imls_pairs.empty() || options.SumsImlsPerPair(),
            "summed IMLS pairs need the compressed e_L form (no Huber kernel on e_L)");
  jp.weights = ResolveWeights(options, static_cast<int64_t>(input.Observations().size()),
                              CountImls(input), static_cast<int64_t>(input.directions.size()));
  // The problem owns a loss only once a residual uses it; unused ones are freed here.
  std::unique_ptr<ceres::LossFunction> visual_loss(
      MakeLoss(jp.weights.alpha, options.visual_huber));
  std::unique_ptr<ceres::LossFunction> imls_loss(MakeLoss(jp.weights.beta, options.imls_huber));
  std::unique_ptr<ceres::LossFunction> direction_loss(
      MakeLoss(jp.weights.gamma, options.direction_huber));
  // Gauge: the fixed keyframes, or the first one (six degrees of freedom; LiDAR fixes scale).
  // Known before the terms are added: e_L's noise per pair treats the gauge's pairs apart.
  jp.fixed = input.fixed;
  if (jp.fixed.empty()) jp.fixed.insert(jp.poses.begin()->first);
  std::vector<std::pair<int64_t, int32_t>> visual_pairs;
  AddVisual(input, options, visual_loss.get(), jp, &visual_pairs);
  std::sort(visual_pairs.begin(), visual_pairs.end());
  AddImls(input, options, imls_loss.get(), jp);
  AddDirections(input, options, direction_loss.get(), jp);
  if (!jp.visual_blocks.empty()) visual_loss.release();
  if (!jp.imls_blocks.empty()) imls_loss.release();
  if (!jp.direction_blocks.empty()) direction_loss.release();
  // e_O: whitened, weight 1, Cauchy kernel (one shared loss; the problem deletes it once).
  if (!input.relative_poses.empty()) {
    ceres::LossFunction* relative_loss =
        options.relative_cauchy > 0 ? new ceres::CauchyLoss(options.relative_cauchy) : nullptr;
    for (const RelativePoseConstraint& r : input.relative_poses) {
      jp.relative_blocks.push_back(jp.problem->AddResidualBlock(
          RelativePoseCost::Create(r.i_from_j.rotation(), r.i_from_j.translation(),
                                   r.sigma_rad.cwiseInverse(), r.sigma_m.cwiseInverse()),
          relative_loss, jp.poses.at(r.i).data(), jp.poses.at(r.j).data()));
    }
  }

  // e_M: whitened, weight 1, Cauchy kernel.
  if (!input.motion.empty()) {
    ceres::LossFunction* motion_loss =
        options.motion_cauchy > 0 ? new ceres::CauchyLoss(options.motion_cauchy) : nullptr;
    for (const MotionConstraint& m : input.motion) {
      jp.motion_blocks.push_back(jp.problem->AddResidualBlock(
          MotionSmoothnessCost::Create(m.frames_ab, m.frames_bc, m.sigma_m.cwiseInverse()),
          motion_loss, jp.poses.at(m.a).data(), jp.poses.at(m.b).data(), jp.poses.at(m.c).data()));
    }
  }

  // e_S: whitened, weight 1, Cauchy kernel; only on observations that entered the visual term
  // and on free points (a point alone with its surface distance would be free along the
  // surface; a point held constant, as weak or by optimize_map_points = false, would pull the
  // pose towards the place it was put).
  if (!input.point_surfaces.empty()) {
    std::unique_ptr<ceres::LossFunction> surface_loss(
        options.surface_cauchy > 0 ? new ceres::CauchyLoss(options.surface_cauchy) : nullptr);
    for (const PointSurfaceConstraint& c : input.point_surfaces) {
      double* point = jp.map_points[static_cast<size_t>(c.map_point)].data();
      if (!std::binary_search(visual_pairs.begin(), visual_pairs.end(),
                              std::make_pair(c.keyframe, c.map_point)) ||
          jp.problem->IsParameterBlockConstant(point))
        continue;
      jp.surface_blocks.push_back(jp.problem->AddResidualBlock(
          PointToSurfaceCost::Create(c.k_p_y, c.k_normal, 1.0 / options.surface_sigma_m),
          surface_loss.get(), jp.poses.at(c.keyframe).data(), point));
    }
    if (!jp.surface_blocks.empty()) surface_loss.release();
  }

  for (int64_t id : jp.fixed) jp.problem->SetParameterBlockConstant(jp.poses.at(id).data());
  return jp;
}

}  // namespace jvl::optim
