// Golden test: the committed constructed trajectories in tests/eval/data and the metrics that
// tests/eval/make_golden.py computed for them with numpy (see docs/evaluate.md).
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "eval/evaluate.h"
#include "io/eval_report_io.h"
#include "io/files.h"

namespace jvl::eval {
namespace {

const std::string kData = std::string(JVL_SOURCE_DIR) + "/tests/eval/data/";

PoseSeries Load(const std::string& name) {
  io::PoseMatrices m = io::ReadPoseMatrices(kData + name);
  PoseSeries s;
  s.frames = m.frames;
  s.poses = m.poses;
  return s;
}

// Relative 1e-9, plus an absolute floor. Angles come from the devkit's acos((trace - 1) / 2), whose
// rounding error is a few eps / theta rad: for the smallest single angles here (~1e-4 rad) that
// is a few 1e-12 rad, so single angles (min, max, median) get an absolute floor of 1e-9 deg; the
// means and RMSEs of angles and all translations agree to 1e-9 relative.
void ExpectClose(double actual, const nlohmann::json& expected, const std::string& what,
                 double abs_floor = 1e-13) {
  const double e = expected.get<double>();
  EXPECT_LE(std::abs(actual - e), 1e-9 * std::abs(e) + abs_floor)
      << what << ": got " << actual << " expected " << e;
}

void ExpectStats(const ErrorStats& s, const nlohmann::json& e, const std::string& what,
                 bool angles = false) {
  const double single = angles ? 1e-9 : 1e-13;  // Floor for single values (see ExpectClose).
  ExpectClose(s.rmse, e["rmse"], what + ".rmse");
  ExpectClose(s.mean, e["mean"], what + ".mean");
  ExpectClose(s.median, e["median"], what + ".median", single);
  ExpectClose(s.std, e["std"], what + ".std");
  ExpectClose(s.min, e["min"], what + ".min", single);
  ExpectClose(s.max, e["max"], what + ".max", single);
  EXPECT_EQ(s.count, e["count"].get<int64_t>()) << what;
}

TEST(Golden, ConstructedTrajectoriesMatchNumpy) {
  const nlohmann::json expected = nlohmann::json::parse(io::ReadTextFile(kData + "expected.json"));
  const PoseSeries gt = Load("gt.txt");
  const PoseSeries est = Load("est.txt");
  ASSERT_EQ(expected["cases"].size(), 5u);
  for (const nlohmann::json& c : expected["cases"]) {
    const std::string name = c["name"];
    SCOPED_TRACE(name);
    EvalOptions o;
    o.alignment = ParseAlignment(c["align"]);
    o.origin_first = c["origin_first"];
    o.rpe.delta = c["rpe_delta"];
    o.rpe.unit = ParseRpeUnit(c["rpe_unit"]);
    const SequenceEval r = EvaluateSequence(gt, est, o, name);
    EXPECT_EQ(r.frames_matched, c["frames_matched"].get<int64_t>());
    EXPECT_EQ(r.gt_missing_frames, std::vector<int64_t>({517}));
    ExpectClose(r.alignment.scale, c["scale"], "scale");
    ExpectStats(r.ape.translation_stats, c["ape"]["translation_m"], "ape.translation_m");
    ExpectStats(r.ape.rotation_stats, c["ape"]["rotation_deg"], "ape.rotation_deg", true);
    ExpectStats(r.rpe.translation_stats, c["rpe"]["translation_m"], "rpe.translation_m");
    ExpectStats(r.rpe.percent_stats, c["rpe"]["translation_percent"], "rpe.translation_percent");
    ExpectStats(r.rpe.rotation_stats, c["rpe"]["rotation_deg"], "rpe.rotation_deg", true);
    ExpectClose(r.kitti.t_rel_percent, c["kitti"]["t_rel_percent"], "kitti.t_rel_percent");
    ExpectClose(r.kitti.r_rel_deg_per_100m, c["kitti"]["r_rel_deg_per_100m"], "kitti.r_rel");
    EXPECT_EQ(static_cast<int64_t>(r.kitti.segments.size()), c["kitti"]["segments"].get<int64_t>());
    ASSERT_EQ(r.kitti.per_length.size(), c["kitti"]["per_length"].size());
    for (size_t k = 0; k < r.kitti.per_length.size(); ++k) {
      const auto& row = r.kitti.per_length[k];
      const auto& e = c["kitti"]["per_length"][k];
      EXPECT_EQ(row.count, e["segments"].get<int64_t>());
      ExpectClose(row.t_rel_percent, e["t_rel_percent"], "per_length.t_rel");
      ExpectClose(row.r_rel_deg_per_100m, e["r_rel_deg_per_100m"], "per_length.r_rel");
    }
  }
}

}  // namespace
}  // namespace jvl::eval
