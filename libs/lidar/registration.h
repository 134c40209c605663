// Scan-to-model registration on the IMLS surface (IMLS-SLAM Sec. V, paper Eq. 2): every
// iteration projects the sampled scan points onto the implicit surface of the model and solves
// a robust (Cauchy-weighted) linearised point-to-plane problem, until the update is below the
// convergence thresholds or the iteration cap is reached.
//
// Degeneracy: the 6x6 normal matrix (rotation columns scaled by the mean sample range so both
// blocks are unitless, each point weighted by its planarity a2D^2, divided by the total
// weight) is eigen-decomposed; directions whose
// eigenvalue is below `degeneracy_threshold` are unobservable (a corridor along its axis). The
// update is then restricted to the observable directions, so the pose keeps the initial guess
// (the constant-velocity motion model) along the degenerate ones, and the result is flagged.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "geometry/rigid3.h"
#include "lidar/association.h"
#include "lidar/imls.h"
#include "lidar/surface.h"

namespace jvl::lidar {

struct RegistrationOptions {
  int max_iterations = 20;                // IMLS-SLAM uses 20.
  double robust_scale = 0.1;              // m, Cauchy scale on I(x).
  double convergence_translation = 5e-4;  // m per iteration.
  double convergence_rotation = 5e-5;     // rad per iteration.
  int min_correspondences = 30;           // fewer: no update, result.ok = false.
  double degeneracy_threshold = 2e-3;     // On the normalised eigenvalues.
  void Check() const;
};

struct RegistrationResult {
  Rigid3d world_from_scan;
  bool ok = false;         // Enough correspondences for an estimate.
  bool converged = false;  // Stopped on the thresholds, not on the iteration cap.
  int iterations = 0;
  int correspondences = 0;  // At the last iteration.
  double residual = 0;      // RMS of I(x) over the correspondences, m.
  bool degenerate = false;  // Some direction fell back to the initial guess.
  int degenerate_directions = 0;
  double min_eigenvalue = 0;  // Smallest normalised eigenvalue (last iteration).
};

// points: sampled scan points in the scan frame. initial: predicted world_from_scan. The points
// are projected on the model's surface with `association` (Eq. 2) at every iteration.
// planarity (optional, a2D per point) weights the observability test by a2D^2.
RegistrationResult RegisterScan(const std::vector<Eigen::Vector3d>& points, const ImlsModel& model,
                                const Rigid3d& initial, const AssociationOptions& association,
                                const RegistrationOptions& options, int threads,
                                const std::vector<double>* planarity = nullptr);

// IMLS-SLAM sampling and registration of a scan's surface on `model` from `start`: s points per
// sampling list with a model neighbour within r at `start` (SampleSurface, SelectSamples), each
// weighted by its planarity in the observability test. `samples` (optional) receives how many
// points were registered.
RegistrationResult RegisterSurface(const ScanSurface& surface, const ImlsModel& model,
                                   const Rigid3d& start, const AssociationOptions& association,
                                   const RegistrationOptions& options, int threads,
                                   int* samples = nullptr);

// The same from a scan already sampled (SampleSurface), for a scan registered several times.
RegistrationResult RegisterSampled(const SampledScan& scan, const ImlsModel& model,
                                   const Rigid3d& start, const AssociationOptions& association,
                                   const RegistrationOptions& options, int threads,
                                   int* samples = nullptr);

// The neighbourhoods of a coarse registration without a motion estimate: search radius,
// kernel h, max distance and robust scale multiplied by k (samples per list unchanged).
void ScaleNeighbourhoods(double k, AssociationOptions* association, RegistrationOptions* options);

}  // namespace jvl::lidar
