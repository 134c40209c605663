// The numbers kitti-odom-eval prints with --align 7dof for its example_0 on KITTI 09 and 10
// (../shared/data/kitti_odom_eval_reference/README.md), reproduced with
// evaluate --align sim3 --origin-first --rpe-delta 1 --rpe-unit frames.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "eval/evaluate.h"
#include "io/eval_report_io.h"
#include "io/files.h"

namespace jvl::eval {
namespace {

const std::string kRef = std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odom_eval_reference/";

struct Published {
  const char* seq;
  double t_err_percent, r_err_deg_per_100m, ate_m, rpe_m, rpe_deg;
};

// Copied from the table of the reference README.
const Published kPublished[] = {
    {"09", 2.884112511407129, 0.24905618674615418, 8.38661922878607, 0.34341307706920193,
     0.0633886066529585},
    {"10", 3.297839536933298, 0.3045899519453301, 6.630158107185018, 0.04735256371856307,
     0.06626406473816236},
};

PoseSeries Load(const std::string& path) {
  io::PoseMatrices m = io::ReadPoseMatrices(path);
  PoseSeries s;
  s.frames = m.frames;
  s.poses = m.poses;
  return s;
}

void ExpectRel(double actual, double expected, const char* what) {
  EXPECT_LE(std::abs(actual / expected - 1.0), 1e-9)
      << what << ": got " << actual << " published " << expected;
}

TEST(Reference, KittiOdomEvalExample0) {
  if (!io::FileExists(kRef + "gt_poses/09.txt")) {
    GTEST_SKIP() << "reference data not found at " << kRef
                 << " (../shared/data beside the repository); skipping";
  }
  EvalOptions o;
  o.alignment = Alignment::kSim3;
  o.origin_first = true;
  for (const Published& p : kPublished) {
    SCOPED_TRACE(p.seq);
    const PoseSeries gt = Load(kRef + "gt_poses/" + p.seq + ".txt");
    const PoseSeries est = Load(kRef + "example_0/" + p.seq + ".txt");
    EXPECT_GT(est.frames.front(), 0);  // The estimate starts late (frame 2 / 4).
    const SequenceEval r = EvaluateSequence(gt, est, o, p.seq);
    EXPECT_EQ(r.frames_matched, static_cast<int64_t>(est.size()));
    ExpectRel(r.kitti.t_rel_percent, p.t_err_percent, "t_err (%)");
    ExpectRel(r.kitti.r_rel_deg_per_100m, p.r_err_deg_per_100m, "r_err (deg/100m)");
    ExpectRel(r.ape.translation_stats.rmse, p.ate_m, "ATE (m)");
    ExpectRel(r.rpe.translation_stats.mean, p.rpe_m, "RPE (m)");
    ExpectRel(r.rpe.rotation_stats.mean, p.rpe_deg, "RPE (deg)");
  }
}

}  // namespace
}  // namespace jvl::eval
