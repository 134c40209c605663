// Spreading pose corrections along a trajectory.
//
// DistributeCorrection: Algorithm 1 of the supplement (1.3), used after a loop correction: the
// SE(3) correction of the last keyframe is spread linearly over the keyframes l..n.
// InterpolateFullRate: after the keyframe optimisation, every frame of the full-rate prior is
// moved by the SE(3) interpolation of the corrections of its two neighbouring keyframes
// (Sec. 4.3 / issue "full-rate trajectory", in the spirit of Algorithm 1).
#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "geometry/rigid3.h"
#include "geometry/trajectory.h"

namespace jvl::optim {

// Algorithm 1. `world_from_cam` holds the poses of keyframes l..n (>= 2, in order);
// `corrected_world_from_cam_n` is the corrected pose of the last one. The paper works with
// T_i = T_iw = (world_from_cam_i)^-1: Delta T_n = T^_n T_n^-1 (line 1), Delta phi = Log(Delta R)
// (line 3), keyframe i gets Delta T^i = (Exp(f Delta phi), f Delta t) with
// f = (i - l) / (n - l) (lines 6-9) and T^_i = Delta T^i T_i (line 10). `positions` (optional,
// same size, increasing, e.g. frame indices or timestamps) replaces the index i in f.
// Returns world_from_cam of all keyframes l..n: the first unchanged, the last = corrected.
std::vector<Rigid3d> DistributeCorrection(const std::vector<Rigid3d>& world_from_cam,
                                          const Rigid3d& corrected_world_from_cam_n,
                                          const std::vector<double>& positions = {});

// World-frame correction of one keyframe: correction_k = T_opt_k * T_prior_k^-1 (world_from_cam
// poses), so that T_opt_k = correction_k * T_prior_k. Applying correction_k to the frames next to
// k keeps their prior motion relative to k.
Rigid3d KeyframeCorrection(const Rigid3d& prior_world_from_cam,
                           const Rigid3d& optimized_world_from_cam);

// Full-rate trajectory: a frame f between keyframes a < f < b gets
//   T_opt_f = Interpolate(correction_a, correction_b, s) * T_prior_f
// with the geodesic SE(3) Interpolate and s the time fraction (timestamps if the prior has them,
// else frame indices). Frames before the first / after the last keyframe take its correction;
// keyframes get their optimised pose exactly. Every keyframe must be a frame of `prior`.
//
// A registration step of the prior between two keyframes would survive that interpolation
// (it keeps the prior's motion relative to the keyframes). So each interval between
// consecutive keyframes a < b is compared: d = |translation of (O_a^-1 O_b)^-1 (P_a^-1 P_b)| /
// (b - a) frames (O optimised, P prior). Where d exceeds step_factor x the median d of all
// intervals and the interval has frames between its keyframes, those frames get the geodesic
// SE(3) interpolation of the two optimised poses instead (constant twist between them).
// step_factor <= 0 turns this off; `bridged` (optional) receives the number of such intervals.
Trajectory InterpolateFullRate(const Trajectory& prior,
                               const std::map<int64_t, Rigid3d>& optimized_keyframes,
                               double step_factor = 5.0, int64_t* bridged = nullptr);

}  // namespace jvl::optim
