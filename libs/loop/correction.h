// Spreading a loop's pose correction over the keyframes it closes (supplement 1.3, Algorithm 1).
#pragma once

#include <cstddef>
#include <vector>

#include "geometry/rigid3.h"

namespace jvl::loop {

// Algorithm 1 of the paper's supplement, in this project's pose convention (world_from_cam).
// Keyframe n's pose is corrected to `corrected_n` (world_from_cam of n after the loop's
// relative pose is applied); keyframe l, the loop's other end, stays. With T_i = cam_from_world
// of keyframe i, the correction of n is dT = T^_n T_n^-1, split into its rotation vector
// phi = Log(R(dT)) and translation t(dT); keyframe i in (l, n) gets the fraction
// w = (i - l) / (n - l) of both, dT_i = (Exp(w phi), w t(dT)), and T^_i = dT_i T_i. Rotation on
// the Lie algebra, translation linearly, as the paper writes it.
//
// Applies it to world_from_cam[l .. n] in place (keyframe l unchanged, n set to corrected_n
// exactly); other keyframes are left as they are. Requires l < n < size.
void DistributeCorrection(size_t l, size_t n, const Rigid3d& corrected_n,
                          std::vector<Rigid3d>* world_from_cam);

}  // namespace jvl::loop
