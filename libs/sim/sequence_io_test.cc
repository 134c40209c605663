#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/temp_dir.h"
#include "io/dataset.h"
#include "io/sim_io.h"
#include "sim/write_sequence.h"

namespace jvl::sim {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// A path that does not exist yet, in a directory of this process's own.
fs::path ScratchPath(const std::string& name) {
  static const jvl::TempDir dir("jvl_sim_test");
  const fs::path d = dir.path() / name;
  fs::remove_all(d);
  return d;
}

io::Provenance TestProvenance() {
  io::Provenance p;
  p.tool = "sim_test";
  return p;
}

SequenceOptions Small(uint64_t seed) {
  SequenceOptions opt;
  opt.frames = 4;
  opt.seed = seed;
  return opt;
}

TEST(SequenceIoTest, SameSeedGivesByteIdenticalFiles) {
  const fs::path a = ScratchPath("a"), b = ScratchPath("b"), c = ScratchPath("c");
  WriteSequence(*BuildWorld(Small(5)), io::SequenceLayout{a.string(), "00"}, 1, TestProvenance);
  WriteSequence(*BuildWorld(Small(5)), io::SequenceLayout{b.string(), "00"}, 2, TestProvenance);
  WriteSequence(*BuildWorld(Small(6)), io::SequenceLayout{c.string(), "00"}, 2, TestProvenance);
  int compared = 0, differ_c = 0;
  for (const auto& e : fs::recursive_directory_iterator(a)) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), a);
    const std::string ext = rel.extension().string();
    if (ext == ".json") {
      // JSON artifacts carry the run's provenance (time, memory); compare the rest.
      auto ja = nlohmann::json::parse(Slurp(e.path())), jb = nlohmann::json::parse(Slurp(b / rel));
      ja.erase("provenance");
      jb.erase("provenance");
      EXPECT_EQ(ja, jb) << rel;
    } else {
      EXPECT_EQ(Slurp(e.path()), Slurp(b / rel)) << rel;
      if (ext == ".bin" || ext == ".png") differ_c += Slurp(e.path()) != Slurp(c / rel) ? 1 : 0;
    }
    ++compared;
  }
  EXPECT_EQ(compared, 4 * 2 + 3 + 3);  // scans, images, calib/times/poses, sim/*.
  EXPECT_EQ(differ_c, 8);              // Another seed is another world.
  fs::remove_all(a);
  fs::remove_all(b);
  fs::remove_all(c);
}

TEST(SequenceIoTest, Kitti360LayoutReadsBackLikeTheKittiOne) {
  const fs::path root = ScratchPath("read360");
  const auto world = BuildWorld(Small(2));
  const io::SequenceLayout layout{root.string(), "07", io::SimLayout::kKitti360};
  WriteSequence(*world, layout, 2, TestProvenance);
  EXPECT_EQ(layout.SequenceDir(), (root / "data_3d_raw" / "sim_drive_0007_sync").string());
  const auto ds = io::OpenDataset(layout.SequenceDir());
  EXPECT_EQ(ds->format(), io::DatasetFormat::kKitti360);
  EXPECT_TRUE(ds->scans_motion_compensated());  // sim/scene.json: no motion distortion
  ASSERT_EQ(ds->frames().size(), 4u);
  EXPECT_NEAR(ds->timestamps()[3], 0.3, 1e-9);
  const Calibration& c = ds->calibration();
  const Calibration& truth = world->options.calibration;
  EXPECT_LT((c.P[0] - truth.P[0]).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((c.P[1] - truth.P[1]).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((c.cam0_from_velo.Matrix3x4() - truth.cam0_from_velo.Matrix3x4()).cwiseAbs().maxCoeff(),
            1e-12);
  ASSERT_TRUE(ds->ground_truth().has_value());
  ASSERT_EQ(ds->ground_truth()->frames, world->ground_truth.frames);
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_LT((ds->ground_truth()->world_from_cam[k].Matrix3x4() -
               world->ground_truth.world_from_cam[k].Matrix3x4())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12);
  }
  EXPECT_GT(ds->LoadScan(2).size(), 60000u);
  EXPECT_EQ(ds->LoadImage(2, 0).cols, 1226);
  EXPECT_TRUE(fs::exists(root / "data_poses" / "sim_drive_0007_sync" / "poses.txt"));
  fs::remove_all(root);
}

TEST(SequenceIoTest, KittiReaderReadsItBack) {
  const fs::path root = ScratchPath("read");
  const auto world = BuildWorld(Small(2));
  WriteSequence(*world, io::SequenceLayout{root.string(), "07"}, 2, TestProvenance);
  const auto ds = io::OpenDataset((root / "sequences" / "07").string());
  EXPECT_EQ(ds->format(), io::DatasetFormat::kKittiOdometry);
  ASSERT_EQ(ds->frames().size(), 4u);
  EXPECT_NEAR(ds->timestamps()[3], 0.3, 1e-9);
  const Calibration& c = ds->calibration();
  EXPECT_NEAR(c.P[0](0, 0), 707.0912, 1e-9);
  EXPECT_NEAR(c.P[0](1, 2), 183.1104, 1e-9);
  EXPECT_LT(
      (c.cam0_from_velo.translation() - world->options.calibration.cam0_from_velo.translation())
          .norm(),
      1e-9);
  ASSERT_TRUE(ds->ground_truth().has_value());
  for (size_t k = 0; k < 4; ++k) {
    const Eigen::Vector3d d = ds->ground_truth()->world_from_cam[k].translation() -
                              world->ground_truth.world_from_cam[k].translation();
    EXPECT_LT(d.norm(), 1e-6);
  }
  const PointCloud scan = ds->LoadScan(2);
  EXPECT_GT(scan.size(), 60000u);
  EXPECT_EQ(scan.intensity.size(), scan.size());
  const cv::Mat img = ds->LoadImage(2, 0);
  EXPECT_EQ(img.cols, 1226);
  EXPECT_EQ(img.rows, 370);
  EXPECT_EQ(img.type(), CV_8UC1);
  // Ground-truth VPs: CSV round trip, one road VP per frame.
  const auto rows = io::ReadGtVpsCsv((root / "sequences/07/sim/gt_vps.csv").string());
  int road = 0;
  for (const auto& r : rows) road += r.kind == "road" ? 1 : 0;
  EXPECT_EQ(road, 4);
  fs::remove_all(root);
}

// Every field the schemas require is present in what the writer produces.
void CheckRequired(const nlohmann::json& schema, const nlohmann::json& value,
                   const std::string& at) {
  if (schema.contains("required")) {
    for (const auto& key : schema["required"]) {
      EXPECT_TRUE(value.contains(key.get<std::string>())) << at << " lacks " << key;
    }
  }
  if (!schema.contains("properties")) return;
  for (auto it = schema["properties"].begin(); it != schema["properties"].end(); ++it) {
    if (!value.contains(it.key())) continue;
    const auto& sub = it.value();
    const auto& v = value[it.key()];
    const std::string type =
        sub.contains("type") && sub["type"].is_string() ? sub["type"].get<std::string>() : "";
    if (type == "array" && sub.contains("items") && v.is_array() && !v.empty()) {
      CheckRequired(sub["items"], v[0], at + "/" + it.key() + "[0]");
    } else if (type == "object") {
      CheckRequired(sub, v, at + "/" + it.key());
    }
  }
}

TEST(SequenceIoTest, OutputsMatchTheirSchemas) {
  const fs::path root = ScratchPath("schema");
  WriteSequence(*BuildWorld(Small(3)), io::SequenceLayout{root.string(), "00"}, 2, TestProvenance);
  for (const std::string name : {"sim_vps", "sim_scene"}) {
    const auto schema = nlohmann::json::parse(
        Slurp(std::string(JVL_SOURCE_DIR) + "/schemas/" + name + ".schema.json"));
    const std::string file = name == "sim_vps" ? "gt_vps.json" : "scene.json";
    const auto value = nlohmann::json::parse(Slurp(root / "sequences/00/sim" / file));
    EXPECT_EQ(value["schema"], name);
    CheckRequired(schema, value, name);
  }
  fs::remove_all(root);
}

}  // namespace
}  // namespace jvl::sim
