// metrics.json must match schemas/metrics.schema.json: a structural check of the subset of JSON
// Schema the file uses (type, required, properties, items, enum, const, $ref to #/$defs).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "eval/report.h"
#include "io/eval_report_io.h"
#include "io/files.h"

namespace jvl::eval {
namespace {

const std::string kSource = std::string(JVL_SOURCE_DIR);

bool HasType(const nlohmann::json& v, const nlohmann::json& types) {
  if (types.is_array()) {
    for (const auto& t : types)
      if (HasType(v, t)) return true;
    return false;
  }
  const std::string type = types;
  if (type == "null") return v.is_null();  // an undefined KITTI score
  if (type == "object") return v.is_object();
  if (type == "array") return v.is_array();
  if (type == "string") return v.is_string();
  if (type == "boolean") return v.is_boolean();
  if (type == "integer") return v.is_number_integer();
  if (type == "number") return v.is_number();
  return false;
}

void Validate(const nlohmann::json& v, const nlohmann::json& s, const nlohmann::json& root,
              const std::string& where) {
  if (s.contains("$ref")) {
    const std::string ref = s["$ref"];
    ASSERT_EQ(ref.rfind("#/$defs/", 0), 0u) << ref;
    return Validate(v, root["$defs"][ref.substr(8)], root, where);
  }
  if (s.contains("type")) {
    ASSERT_TRUE(HasType(v, s["type"])) << where << ": expected " << s["type"] << ", got " << v;
  }
  if (s.contains("const")) {
    EXPECT_EQ(v, s["const"]) << where;
  }
  if (s.contains("enum")) {
    EXPECT_NE(std::find(s["enum"].begin(), s["enum"].end(), v), s["enum"].end()) << where << v;
  }
  if (s.contains("minimum")) {
    EXPECT_GE(v.get<double>(), s["minimum"].get<double>()) << where;
  }
  if (s.contains("required")) {
    for (const auto& key : s["required"]) {
      EXPECT_TRUE(v.contains(key.get<std::string>())) << where << ": missing " << key;
    }
  }
  if (s.contains("properties")) {
    for (auto it = s["properties"].begin(); it != s["properties"].end(); ++it) {
      if (v.contains(it.key())) Validate(v[it.key()], it.value(), root, where + "." + it.key());
    }
  }
  if (s.contains("items")) {
    for (size_t i = 0; i < v.size(); ++i) {
      Validate(v[i], s["items"], root, where + "[" + std::to_string(i) + "]");
    }
  }
}

nlohmann::json Schema() {
  return nlohmann::json::parse(io::ReadTextFile(kSource + "/schemas/metrics.schema.json"));
}

TEST(MetricsSchema, ReportWrittenByTheLibraryValidates) {
  io::PoseMatrices m = io::ReadPoseMatrices(kSource + "/tests/eval/data/gt.txt");
  PoseSeries gt;
  gt.frames = m.frames;
  gt.poses = m.poses;
  PoseSeries est = gt;
  for (auto& p : est.poses) p(0, 3) += 1.0;
  EvalOptions o;
  o.alignment = Alignment::kSE3;
  std::vector<SequenceEval> seqs = {EvaluateSequence(gt, est, o, "a"),
                                    EvaluateSequence(gt, gt, o, "b")};
  const std::vector<EstimateEval> estimates = {CombineSequences("two", seqs, o.kitti),
                                               CombineSequences("one", {seqs[0]}, o.kitti)};
  const std::string path = std::string(JVL_BINARY_DIR) + "/tests/eval/library_metrics.json";
  io::Provenance provenance;
  provenance.tool = "schema_test";
  io::WriteMetricsReport(path, ReportToJson(estimates, o), provenance);
  const nlohmann::json report = io::ReadMetricsReport(path);
  const nlohmann::json schema = Schema();
  Validate(report, schema, schema, "$");
  EXPECT_EQ(report["estimates"][1]["alignment"]["scale"], 1.0);
  EXPECT_EQ(report["estimates"][0]["sequences"].size(), 2u);
}

TEST(MetricsSchema, ReportWrittenByTheToolValidates) {
  const std::string path = std::string(JVL_BINARY_DIR) + "/tests/eval/cli_metrics.json";
  if (!io::FileExists(path)) GTEST_SKIP() << path << " not written (run ctest -R evaluate_cli)";
  const nlohmann::json report = io::ReadMetricsReport(path);
  const nlohmann::json schema = Schema();
  Validate(report, schema, schema, "$");
  ASSERT_EQ(report["estimates"].size(), 2u);
  EXPECT_EQ(report["estimates"][0]["label"], "mono");
  EXPECT_LT(report["estimates"][1]["ape"]["translation_m"]["max"].get<double>(), 1e-9);
}

}  // namespace
}  // namespace jvl::eval
