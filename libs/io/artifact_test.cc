#include "io/artifact.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <fstream>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/files.h"
#include "io/local_io.h"
#include "io/schema_check.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "io/vps_io.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;
const std::string kSchemas = std::string(JVL_SOURCE_DIR) + "/schemas";

class ArtifactTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return dir_.Path(name); }
  std::string ErrorOf(const std::function<void()>& fn) {
    try {
      fn();
    } catch (const Error& e) {
      return e.message();
    }
    return "<no error>";
  }
  Trajectory Small() const {
    Trajectory t;
    for (int i = 0; i < 5; ++i)
      t.Append(i, Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 1.0 * i}));
    return t;
  }
  TempDir dir_{"jvl_artifact"};
};

TEST_F(ArtifactTest, ArraysAttributesAndProvenanceRoundTrip) {
  {
    H5Writer w(Path("a.h5"), "demo", 3);
    w.WriteArray<double>("group/sub/values", {1.5, 2.5, 3.5, 4.5, 5.5, 6.5}, {2, 3});
    w.WriteArray<uint8_t>("bytes", {1, 2, 255});
    w.WriteArray<int64_t>("empty", {});
    w.WriteString("group/note", "hello");
    w.WriteJson("meta", {{"k", 1}});
    Provenance p;
    p.tool = "demo_tool";
    p.options = {{"alpha", "1.0"}};
    p.inputs.push_back({"in.txt", 12, "fnv1a64:0"});
    w.Commit(p);
  }
  H5Reader r(Path("a.h5"), "demo", 3);
  EXPECT_EQ(r.Dims("group/sub/values"), (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(r.ReadArray<double>("group/sub/values", 3)[4], 5.5);
  EXPECT_EQ(r.ReadArray<int32_t>("bytes")[2], 255);  // Converted on read.
  EXPECT_TRUE(r.ReadArray<int64_t>("empty").empty());
  EXPECT_EQ(r.DatasetType("bytes"), "uint8");
  EXPECT_EQ(r.ReadString("group/note"), "hello");
  EXPECT_EQ(r.ReadJson("meta")["k"], 1);
  EXPECT_EQ(r.provenance()["tool"], "demo_tool");
  EXPECT_EQ(r.provenance()["inputs"][0]["size"], 12);
  EXPECT_FALSE(r.Has("nope"));
  EXPECT_FALSE(r.Has("group/nope/deeper"));
  EXPECT_EQ(r.ListDatasets(), (std::vector<std::string>{"bytes", "empty", "group/sub/values"}));
  EXPECT_EQ(r.ListAttributes(), (std::vector<std::string>{"group/note", "meta", "provenance",
                                                          "schema", "schema_version"}));
  EXPECT_THROW(r.ReadArray<double>("group/sub/values", 4), Error);
}

// Rows of a chunked (compressed) and of a contiguous array read range by range equal the same
// rows of the whole array; ranges out of order or beyond the array are refused.
TEST_F(ArtifactTest, ReadRowsReadsTheRangesOfChunkedAndContiguousArrays) {
  std::vector<int32_t> big(3 * 100000), small(3 * 10);
  for (size_t i = 0; i < big.size(); ++i) big[i] = static_cast<int32_t>(7 * i + 1);
  for (size_t i = 0; i < small.size(); ++i) small[i] = static_cast<int32_t>(i);
  {
    H5Writer w(Path("rows.h5"), "demo", 1);
    w.WriteArray("big", big, {100000, 3});  // Chunked: five chunks of 21845 rows.
    w.WriteArray("small", small, {10, 3});  // Contiguous.
    w.Commit(Provenance{});
  }
  H5Reader r(Path("rows.h5"), "demo", 1);
  auto expected = [](const std::vector<int32_t>& all,
                     const std::vector<std::pair<int64_t, int64_t>>& ranges) {
    std::vector<int32_t> out;
    for (const auto& [first, last] : ranges)
      out.insert(out.end(), all.begin() + 3 * first, all.begin() + 3 * last);
    return out;
  };
  const std::vector<std::pair<int64_t, int64_t>> ranges = {
      {0, 2}, {5, 5}, {21830, 21870}, {60000, 60001}, {99990, 100000}};
  EXPECT_EQ(r.ReadRows<int32_t>("big", ranges, 3), expected(big, ranges));
  EXPECT_EQ(r.ReadRows<int32_t>("small", {{1, 3}, {9, 10}}, 3), expected(small, {{1, 3}, {9, 10}}));
  EXPECT_TRUE(r.ReadRows<int32_t>("big", {}, 3).empty());
  EXPECT_NE(ErrorOf([&] {
              r.ReadRows<int32_t>("big", {{5, 9}, {2, 3}}, 3);
            }).find("out of order or out of range"),
            std::string::npos);
  EXPECT_THROW(r.ReadRows<int32_t>("big", {{99999, 100001}}, 3), Error);
  EXPECT_THROW(r.ReadRows<int32_t>("big", {{3, 2}}, 3), Error);
  EXPECT_THROW(r.ReadRows<int32_t>("big", {{0, 1}}, 4), Error);
}

TEST_F(ArtifactTest, SchemaMismatchNamesFileExpectedAndFound) {
  WriteTrajectoryArtifact(Path("t.h5"), Small(), Provenance{});
  const std::string msg = ErrorOf([&] { H5Reader(Path("t.h5"), "vps", 1); });
  EXPECT_NE(msg.find("t.h5: expected schema 'vps' version 1, found 'trajectory' version 1"),
            std::string::npos)
      << msg;
  EXPECT_NE(ErrorOf([&] { H5Reader(Path("t.h5"), "trajectory", 2); }).find("version 2"),
            std::string::npos);
}

TEST_F(ArtifactTest, NotHdf5AndTruncatedFilesAreRejected) {
  std::ofstream(Path("text.h5")) << "hello";
  EXPECT_NE(ErrorOf([&] { H5Reader(Path("text.h5"), "trajectory", 1); }).find("not an HDF5"),
            std::string::npos);
  WriteTrajectoryArtifact(Path("full.h5"), Small(), Provenance{});
  const std::string bytes = ReadTextFile(Path("full.h5"));
  std::ofstream(Path("cut.h5"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_THROW(ReadTrajectory(Path("cut.h5")), Error);
  EXPECT_NE(ErrorOf([&] { H5Reader(Path("none.h5"), "x", 1); }).find("not found"),
            std::string::npos);
}

TEST_F(ArtifactTest, RejectedFileIsClosed) {
  // A reader whose constructor throws (wrong schema) must not leave the file open.
  WriteTrajectoryArtifact(Path("a.h5"), Small(), Provenance{});
  EXPECT_THROW(H5Reader(Path("a.h5"), "visual", 1), Error);
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_FILE), 0);
  {
    H5Reader r(Path("a.h5"), "trajectory", 1);
    EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_FILE), 1);
  }
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_FILE), 0);
}

TEST_F(ArtifactTest, DamagedFilesFoundByFuzzingRaiseErrors) {
  // Inputs of tests/fuzz/corpus/artifact that once crashed: a NaN image size (undefined
  // conversion to int), metadata libhdf5 crashes on (caught by the metadata probe, or by the
  // readers' checks where the library survives), a dataset shape of ~40 GB.
  const std::string dir = std::string(JVL_SOURCE_DIR) + "/tests/fuzz/corpus/artifact/";
  EXPECT_THROW(ReadVpsArtifact(dir + "regression_nan_image_size.h5"), Error);
  EXPECT_THROW(ReadLocalMap(dir + "regression_hdf5_crash_local.h5"), Error);
  EXPECT_THROW(ReadVpsArtifact(dir + "regression_hdf5_huge_alloc.h5"), Error);
  // A visual map whose 'orb' attribute lost scale_factor (was a JSON exception, not an Error).
  EXPECT_THROW(ReadVisualMap(dir + "regression_visual_orb_json.h5"), Error);
}

TEST_F(ArtifactTest, UncommittedWriterLeavesPreviousArtifactIntact) {
  WriteTrajectoryArtifact(Path("t.h5"), Small(), Provenance{});
  const std::string before = ReadTextFile(Path("t.h5"));
  {
    H5Writer w(Path("t.h5"), "trajectory", 1);
    w.WriteArray<int64_t>("trajectory/frames", {1, 2});
    // Destroyed without Commit(), as when an exception unwinds a tool.
  }
  EXPECT_EQ(ReadTextFile(Path("t.h5")), before);
  for (const auto& entry : fs::directory_iterator(dir_.path()))
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos) << entry.path();
}

TEST_F(ArtifactTest, AtomicWriteKeepsOldFileWhenWriterFails) {
  WriteTextFileAtomic(Path("x.txt"), "old");
  EXPECT_THROW(AtomicWrite(Path("x.txt"),
                           [](const std::string& tmp) {
                             std::ofstream(tmp) << "partial";
                             JVL_THROW("disk full");
                           }),
               Error);
  EXPECT_EQ(ReadTextFile(Path("x.txt")), "old");
}

TEST_F(ArtifactTest, AtomicWriteNamesWhyTheRenameFailed) {
  fs::create_directories(Path("taken/child"));  // A non-empty folder under the final name.
  const std::string message = ErrorOf([&] { WriteTextFileAtomic(Path("taken"), "new"); });
  EXPECT_NE(message.find("cannot move the finished file into place"), std::string::npos);
  EXPECT_EQ(message.find("Success"), std::string::npos) << message;
  for (const auto& entry : fs::directory_iterator(dir_.path()))
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos) << entry.path();
}

TEST_F(ArtifactTest, DatasetIdOfArtifactsAndOtherFiles) {
  Provenance p;
  p.dataset_id = "kitti:04:abcd";
  WriteTrajectoryArtifact(Path("t.h5"), Small(), p);
  WriteJsonArtifact(Path("m.json"), "demo", 1, {{"x", 1}}, p);
  WriteTrajectoryKitti(Path("t.txt"), Small());
  EXPECT_EQ(ReadArtifactDatasetId(Path("t.h5")), "kitti:04:abcd");
  EXPECT_EQ(ReadArtifactDatasetId(Path("m.json")), "kitti:04:abcd");
  EXPECT_EQ(ReadArtifactDatasetId(Path("t.txt")), "");
  WriteTextFileAtomic(Path("bad.json"), "{not json");
  EXPECT_EQ(ReadArtifactDatasetId(Path("bad.json")), "");
}

TEST_F(ArtifactTest, SameContentGivesSameBytesApartFromProvenance) {
  Provenance p;
  p.tool = "t";
  WriteTrajectoryArtifact(Path("a.h5"), Small(), p);
  WriteTrajectoryArtifact(Path("b.h5"), Small(), p);
  H5Reader a(Path("a.h5"), "trajectory", 1), b(Path("b.h5"), "trajectory", 1);
  EXPECT_EQ(a.ReadArray<double>("trajectory/poses"), b.ReadArray<double>("trajectory/poses"));
  // Byte identity: with equal provenance strings the files are equal byte for byte.
  const std::string ba = ReadTextFile(Path("a.h5")), bb = ReadTextFile(Path("b.h5"));
  EXPECT_EQ(ba.size(), bb.size());
}

TEST_F(ArtifactTest, JsonArtifactRoundTripAndSchemaCheck) {
  Provenance p;
  p.tool = "t";
  WriteJsonArtifact(Path("m.json"), "metrics", 1, {{"value", 2.5}}, p);
  const auto j = ReadJsonArtifact(Path("m.json"), "metrics", 1);
  EXPECT_EQ(j["value"], 2.5);
  EXPECT_TRUE(
      CheckJsonAgainstSchema(j["provenance"], kSchemas + "/provenance.schema.json").empty());
  EXPECT_NE(ErrorOf([&] { ReadJsonArtifact(Path("m.json"), "vps", 1); }).find("found 'metrics'"),
            std::string::npos);
  std::ofstream(Path("broken.json")) << "{\"schema\": ";
  EXPECT_NE(
      ErrorOf([&] { ReadJsonArtifact(Path("broken.json"), "metrics", 1); }).find("not valid JSON"),
      std::string::npos);
}

TEST_F(ArtifactTest, TrajectoryArtifactMatchesItsSchema) {
  Trajectory t = Small();
  t.timestamps = {0, 0.1, 0.2, 0.3, 0.4};
  Provenance p;
  p.tool = "test";
  WriteTrajectoryArtifact(Path("t.h5"), t, p);
  const auto problems = CheckH5AgainstSchema(Path("t.h5"), kSchemas + "/trajectory.schema.json");
  EXPECT_TRUE(problems.empty()) << problems.front();
  // And the checker does catch a wrong layout.
  {
    H5Writer w(Path("bad.h5"), "trajectory", 1);
    w.WriteArray<int64_t>("trajectory/frames", {0, 1});
    w.WriteArray<double>("trajectory/poses", std::vector<double>(3 * 7), {3, 7});
    w.WriteArray<float>("extra", {1.0f});
    w.Commit(p);
  }
  EXPECT_EQ(CheckH5AgainstSchema(Path("bad.h5"), kSchemas + "/trajectory.schema.json").size(), 2u);
}

}  // namespace
}  // namespace jvl::io
