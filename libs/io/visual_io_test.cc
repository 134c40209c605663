#include "io/visual_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/schema_check.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

// Two keyframes with three keypoints each, two map points seen by both.
VisualMapData MakeMap() {
  VisualMapData d;
  d.camera = {718.856, 718.856, 607.1928, 185.2157, 1226, 370};
  d.keyframes.Append(3, Rigid3d());
  d.keyframes.Append(5, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.5)));
  d.prior = d.keyframes;
  d.prior.Append(6, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 2.5)));
  for (int k = 0; k < 2; ++k) {
    for (int i = 0; i < 3; ++i) {
      d.keypoint_keyframe.push_back(k);
      d.keypoint_uv.insert(d.keypoint_uv.end(), {100.5f + 10 * i, 50.25f + k});
      d.keypoint_octave.push_back(i);
      d.keypoint_angle.push_back(12.5f * i);
      for (int b = 0; b < 32; ++b) d.keypoint_descriptor.push_back(static_cast<uint8_t>(b + i + k));
    }
  }
  for (int m = 0; m < 2; ++m) {
    d.mappoint_position.insert(d.mappoint_position.end(), {1.0 * m, -0.5, 10.0 + m});
    for (int b = 0; b < 32; ++b) d.mappoint_descriptor.push_back(static_cast<uint8_t>(7 * b + m));
    d.mappoint_normal.insert(d.mappoint_normal.end(), {0.0, 0.0, 1.0});
    for (int k = 0; k < 2; ++k) {
      d.observation_keyframe.push_back(k);
      d.observation_keypoint.push_back(3 * k + m);
      d.observation_mappoint.push_back(m);
    }
  }
  d.covisibility_edges = {0, 1};
  d.covisibility_weight = {2};
  d.summary = {{"keyframes", 2}};
  return d;
}

fs::path TempPath(const std::string& name) {
  static const TempDir dir("jvl_visual_io_test");
  return dir.path() / name;
}

TEST(VisualIo, RoundTrip) {
  const VisualMapData d = MakeMap();
  const std::string path = TempPath("rt.h5").string();
  WriteVisualMap(path, d, Provenance{});
  const VisualMapData r = ReadVisualMap(path);
  EXPECT_EQ(r.camera.fx, d.camera.fx);
  EXPECT_EQ(r.camera.width, 1226);
  EXPECT_EQ(r.keyframes.frames, d.keyframes.frames);
  EXPECT_EQ(r.prior.frames, d.prior.frames);
  EXPECT_NEAR(r.keyframes.world_from_cam[1].translation().z(), 1.5, 1e-15);
  EXPECT_EQ(r.keypoint_keyframe, d.keypoint_keyframe);
  EXPECT_EQ(r.keypoint_uv, d.keypoint_uv);
  EXPECT_EQ(r.keypoint_octave, d.keypoint_octave);
  EXPECT_EQ(r.keypoint_angle, d.keypoint_angle);
  EXPECT_EQ(r.keypoint_descriptor, d.keypoint_descriptor);
  EXPECT_EQ(r.mappoint_position, d.mappoint_position);
  EXPECT_EQ(r.mappoint_descriptor, d.mappoint_descriptor);
  EXPECT_EQ(r.observation_keypoint, d.observation_keypoint);
  EXPECT_EQ(r.covisibility_edges, d.covisibility_edges);
  EXPECT_EQ(r.covisibility_weight, d.covisibility_weight);
  EXPECT_EQ(r.scale_factor, 1.2);
  EXPECT_EQ(r.num_levels, 8);
  EXPECT_EQ(r.summary.at("keyframes").get<int>(), 2);
  fs::remove(path);
}

// Without descriptors: everything else as in the whole map, both descriptor arrays empty.
TEST(VisualIo, ReadsWithoutDescriptors) {
  const VisualMapData d = MakeMap();
  const std::string path = TempPath("nodesc.h5").string();
  WriteVisualMap(path, d, Provenance{});
  const VisualMapData r = ReadVisualMap(path, VisualMapParts::kWithoutDescriptors);
  EXPECT_TRUE(r.keypoint_descriptor.empty());
  EXPECT_TRUE(r.mappoint_descriptor.empty());
  EXPECT_FALSE(d.keypoint_descriptor.empty());
  EXPECT_EQ(r.keypoint_keyframe, d.keypoint_keyframe);
  EXPECT_EQ(r.keypoint_uv, d.keypoint_uv);
  EXPECT_EQ(r.keypoint_octave, d.keypoint_octave);
  EXPECT_EQ(r.mappoint_position, d.mappoint_position);
  EXPECT_EQ(r.mappoint_normal, d.mappoint_normal);
  EXPECT_EQ(r.observation_keyframe, d.observation_keyframe);
  EXPECT_EQ(r.observation_keypoint, d.observation_keypoint);
  EXPECT_EQ(r.observation_mappoint, d.observation_mappoint);
  EXPECT_EQ(r.covisibility_edges, d.covisibility_edges);
  EXPECT_EQ(r.prior.frames, d.prior.frames);
  // A map read so cannot be written back (the writer wants the descriptors).
  EXPECT_THROW(WriteVisualMap(TempPath("nodesc2.h5").string(), r, Provenance{}), Error);
  fs::remove(path);
}

// The header holds the same camera choice, pyramid and keyframes as the whole map, and nothing
// else.
TEST(VisualIo, HeaderIsTheMapsHead) {
  VisualMapData d = MakeMap();
  d.camera_choice = {2, Eigen::Vector3d(0.061, -0.0003, 0.0062)};
  const std::string path = TempPath("head.h5").string();
  WriteVisualMap(path, d, Provenance{});
  const VisualMapData whole = ReadVisualMap(path);
  const VisualMapData header = ReadVisualMapHeader(path);
  EXPECT_EQ(header.camera_choice.index, 2);
  EXPECT_EQ(header.camera_choice.offset, whole.camera_choice.offset);
  EXPECT_EQ(header.scale_factor, whole.scale_factor);
  EXPECT_EQ(header.num_levels, whole.num_levels);
  EXPECT_EQ(header.keyframes.frames, whole.keyframes.frames);
  ASSERT_EQ(header.keyframes.size(), whole.keyframes.size());
  for (size_t i = 0; i < header.keyframes.size(); ++i)
    EXPECT_EQ(header.keyframes.world_from_cam[i].ToArray(),
              whole.keyframes.world_from_cam[i].ToArray());
  EXPECT_TRUE(header.keypoint_keyframe.empty());
  EXPECT_TRUE(header.mappoint_position.empty());
  fs::remove(path);
}

// The keypoints of some keyframes equal their rows of the whole map; frames the map lacks are
// skipped and the rest of the map is not read.
TEST(VisualIo, KeypointsOfSomeKeyframesAreTheirRowsOfTheWholeMap) {
  const std::string path = TempPath("kp.h5").string();
  WriteVisualMap(path, MakeMap(), Provenance{});
  const VisualMapData whole = ReadVisualMap(path);
  const VisualMapData some = ReadVisualKeypoints(path, {5, 4});  // Frame 4 is no keyframe.
  EXPECT_EQ(some.keyframes.frames, whole.keyframes.frames);
  EXPECT_EQ(some.camera.K(), whole.camera.K());
  EXPECT_EQ(some.keypoint_keyframe, (std::vector<int32_t>{1, 1, 1}));
  EXPECT_EQ(some.keypoint_uv,
            std::vector<float>(whole.keypoint_uv.begin() + 6, whole.keypoint_uv.end()));
  EXPECT_EQ(some.keypoint_octave,
            std::vector<int32_t>(whole.keypoint_octave.begin() + 3, whole.keypoint_octave.end()));
  EXPECT_EQ(some.keypoint_angle,
            std::vector<float>(whole.keypoint_angle.begin() + 3, whole.keypoint_angle.end()));
  EXPECT_EQ(some.keypoint_descriptor,
            std::vector<uint8_t>(whole.keypoint_descriptor.begin() + 3 * 32,
                                 whole.keypoint_descriptor.end()));
  EXPECT_TRUE(some.mappoint_position.empty());
  EXPECT_TRUE(some.observation_keyframe.empty());
  const VisualMapData both = ReadVisualKeypoints(path, {5, 3});
  EXPECT_EQ(both.keypoint_keyframe, whole.keypoint_keyframe);
  EXPECT_EQ(both.keypoint_descriptor, whole.keypoint_descriptor);
  EXPECT_TRUE(ReadVisualKeypoints(path, {}).keypoint_keyframe.empty());
  fs::remove(path);
}

// Keypoints of one keyframe split by another's are refused with the keyframe named.
TEST(VisualIo, KeypointsOfAKeyframeMustBeContiguous) {
  VisualMapData d = MakeMap();
  d.keypoint_keyframe = {0, 1, 0, 1, 1, 1};
  d.observation_keypoint = {0, 1, 2, 3};  // Still of the keyframes they name.
  d.observation_keyframe = {0, 1, 0, 1};
  const std::string path = TempPath("split.h5").string();
  WriteVisualMap(path, d, Provenance{});
  try {
    ReadVisualKeypoints(path, {3});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("keyframe row 0 are not contiguous"), std::string::npos)
        << e.message();
  }
  fs::remove(path);
}

// The camera choice of a map built from another camera is kept; a camera-0 map has none written.
TEST(VisualIo, CameraChoiceRoundTrip) {
  const std::string path = TempPath("cam.h5").string();
  WriteVisualMap(path, MakeMap(), Provenance{});
  EXPECT_FALSE(H5Reader(path, kVisualSchema, kVisualSchemaVersion).Has("camera_index"));
  EXPECT_EQ(ReadVisualMap(path).camera_choice.index, 0);
  VisualMapData d = MakeMap();
  d.camera_choice = {2, Eigen::Vector3d(0.061, -0.0003, 0.0062)};
  WriteVisualMap(path, d, Provenance{});
  const VisualMapData r = ReadVisualMap(path);
  EXPECT_EQ(r.camera_choice.index, 2);
  EXPECT_EQ(r.camera_choice.offset, d.camera_choice.offset);
  const auto problems =
      CheckH5AgainstSchema(path, std::string(JVL_SOURCE_DIR) + "/schemas/visual.schema.json");
  EXPECT_TRUE(problems.empty()) << problems.front();
  fs::remove(path);
}

TEST(VisualIo, CovisibilityParts) {
  VisualMapData d = MakeMap();
  EXPECT_EQ(d.CovisibilityPartStarts(), (std::vector<int64_t>{3}));
  d.covisibility_edges.clear();
  d.covisibility_weight.clear();
  EXPECT_EQ(d.CovisibilityPartStarts(), (std::vector<int64_t>{3, 5}));
  EXPECT_TRUE(VisualMapData().CovisibilityPartStarts().empty());
}

TEST(VisualIo, RejectsInconsistentIndices) {
  VisualMapData d = MakeMap();
  d.observation_keypoint[0] = 4;  // A keypoint of keyframe 1 for an observation in keyframe 0.
  EXPECT_THROW(d.Check("map"), Error);
  d = MakeMap();
  d.observation_mappoint[1] = 9;
  EXPECT_THROW(WriteVisualMap(TempPath("bad.h5").string(), d, Provenance{}), Error);
  EXPECT_FALSE(fs::exists(TempPath("bad.h5")));
}

// Every dataset the schema lists exists with its dtype, rank and consistent symbolic sizes, and
// nothing undocumented is written.
TEST(VisualIo, WrittenFileMatchesSchema) {
  const std::string path = TempPath("schema.h5").string();
  WriteVisualMap(path, MakeMap(), Provenance{});
  const auto problems =
      CheckH5AgainstSchema(path, std::string(JVL_SOURCE_DIR) + "/schemas/visual.schema.json");
  EXPECT_TRUE(problems.empty()) << problems.front();
  fs::remove(path);
}

}  // namespace
}  // namespace jvl::io
