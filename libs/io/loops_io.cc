#include "io/loops_io.h"

#include <algorithm>
#include <sstream>

#include "core/check.h"
#include "core/strings.h"
#include "io/camera_io.h"
#include "io/files.h"

namespace jvl::io {

void WriteLoopsArtifact(const std::string& path, const LoopsData& data,
                        const Provenance& provenance) {
  const int64_t m = static_cast<int64_t>(data.loops.size());
  H5Writer writer(path, kLoopsSchema, kLoopsSchemaVersion);
  writer.WriteArray("keyframes", data.keyframes);
  WriteCameraChoice(writer, data.camera_choice);
  std::vector<int64_t> query, match;
  std::vector<int32_t> detector, status, correspondences, inliers;
  std::vector<double> pose, score, ring, yaw, residual;
  for (const LoopRecord& r : data.loops) {
    query.push_back(r.query);
    match.push_back(r.match);
    detector.push_back(r.detector);
    status.push_back(r.status);
    const auto a = r.match_from_query.ToArray();
    pose.insert(pose.end(), a.begin(), a.end());
    score.push_back(r.score);
    ring.push_back(r.ring_key_distance);
    yaw.push_back(r.yaw_deg);
    correspondences.push_back(r.correspondences);
    inliers.push_back(r.inliers);
    residual.push_back(r.residual);
  }
  writer.WriteArray("loops/query", query);
  writer.WriteArray("loops/match", match);
  writer.WriteArray("loops/detector", detector);
  writer.WriteArray("loops/status", status);
  writer.WriteArray("loops/match_from_query", pose, {m, 7});
  writer.WriteArray("loops/score", score);
  writer.WriteArray("loops/ring_key_distance", ring);
  writer.WriteArray("loops/yaw_deg", yaw);
  writer.WriteArray("loops/correspondences", correspondences);
  writer.WriteArray("loops/inliers", inliers);
  // The 3D-2D matches of every loop, by loop row.
  std::vector<int64_t> point_loop;
  std::vector<double> p_match, match_uv, query_uv;
  std::vector<int32_t> octaves;
  for (size_t i = 0; i < data.loops.size(); ++i) {
    for (const LoopPointRecord& p : data.loops[i].points) {
      point_loop.push_back(static_cast<int64_t>(i));
      p_match.insert(p_match.end(), {p.p_match.x(), p.p_match.y(), p.p_match.z()});
      match_uv.insert(match_uv.end(), {p.match_uv.x(), p.match_uv.y()});
      query_uv.insert(query_uv.end(), {p.query_uv.x(), p.query_uv.y()});
      octaves.insert(octaves.end(), {p.match_octave, p.query_octave});
    }
  }
  const int64_t np = static_cast<int64_t>(point_loop.size());
  writer.WriteArray("loop_points/loop", point_loop);
  writer.WriteArray("loop_points/p_match", p_match, {np, 3});
  writer.WriteArray("loop_points/match_uv", match_uv, {np, 2});
  writer.WriteArray("loop_points/query_uv", query_uv, {np, 2});
  writer.WriteArray("loop_points/octaves", octaves, {np, 2});
  writer.WriteArray("loops/residual", residual);
  writer.Commit(provenance);
}

LoopsData ReadLoopsArtifact(const std::string& path) {
  H5Reader reader(path, kLoopsSchema, kLoopsSchemaVersion);
  LoopsData data;
  data.keyframes = reader.ReadArray<int64_t>("keyframes");
  data.camera_choice = ReadCameraChoice(reader);
  JVL_CHECK(
      std::is_sorted(data.keyframes.begin(), data.keyframes.end()) &&
          std::adjacent_find(data.keyframes.begin(), data.keyframes.end()) == data.keyframes.end(),
      path << ": 'keyframes' is not strictly increasing");
  const auto query = reader.ReadArray<int64_t>("loops/query");
  const auto match = reader.ReadArray<int64_t>("loops/match");
  const auto detector = reader.ReadArray<int32_t>("loops/detector");
  const auto status = reader.ReadArray<int32_t>("loops/status");
  const auto pose = reader.ReadArray<double>("loops/match_from_query", 7);
  const auto score = reader.ReadArray<double>("loops/score");
  const auto ring = reader.ReadArray<double>("loops/ring_key_distance");
  const auto yaw = reader.ReadArray<double>("loops/yaw_deg");
  const auto correspondences = reader.ReadArray<int32_t>("loops/correspondences");
  const auto inliers = reader.ReadArray<int32_t>("loops/inliers");
  const auto residual = reader.ReadArray<double>("loops/residual");
  const size_t m = query.size();
  JVL_CHECK(match.size() == m && detector.size() == m && status.size() == m &&
                pose.size() == 7 * m && score.size() == m && ring.size() == m && yaw.size() == m &&
                correspondences.size() == m && inliers.size() == m && residual.size() == m,
            path << ": the loops/* datasets disagree in length (loops/query has " << m << " rows)");
  auto is_keyframe = [&](int64_t f) {
    return std::binary_search(data.keyframes.begin(), data.keyframes.end(), f);
  };
  for (size_t i = 0; i < m; ++i) {
    JVL_CHECK(is_keyframe(query[i]) && is_keyframe(match[i]) && match[i] < query[i],
              path << ": loop row " << i << " (" << query[i] << " -> " << match[i]
                   << ") does not join an earlier keyframe to a later one");
    LoopRecord r;
    r.query = query[i];
    r.match = match[i];
    r.detector = detector[i];
    r.status = status[i];
    r.match_from_query = Rigid3d::FromArray(&pose[7 * i]);
    r.score = score[i];
    r.ring_key_distance = ring[i];
    r.yaw_deg = yaw[i];
    r.correspondences = correspondences[i];
    r.inliers = inliers[i];
    r.residual = residual[i];
    data.loops.push_back(r);
  }
  const auto point_loop = reader.ReadArray<int64_t>("loop_points/loop");
  const auto p_match = reader.ReadArray<double>("loop_points/p_match", 3);
  const auto match_uv = reader.ReadArray<double>("loop_points/match_uv", 2);
  const auto query_uv = reader.ReadArray<double>("loop_points/query_uv", 2);
  const auto octaves = reader.ReadArray<int32_t>("loop_points/octaves", 2);
  const size_t np = point_loop.size();
  JVL_CHECK(p_match.size() == 3 * np && match_uv.size() == 2 * np && query_uv.size() == 2 * np &&
                octaves.size() == 2 * np,
            path << ": the loop_points/* datasets disagree in length (loop_points/loop has " << np
                 << " rows)");
  for (size_t i = 0; i < np; ++i) {
    JVL_CHECK(point_loop[i] >= 0 && static_cast<size_t>(point_loop[i]) < m,
              path << ": loop_points row " << i << " refers to loop row " << point_loop[i] << " of "
                   << m);
    LoopPointRecord p;
    p.p_match = Eigen::Vector3d(p_match[3 * i], p_match[3 * i + 1], p_match[3 * i + 2]);
    p.match_uv = Eigen::Vector2d(match_uv[2 * i], match_uv[2 * i + 1]);
    p.query_uv = Eigen::Vector2d(query_uv[2 * i], query_uv[2 * i + 1]);
    p.match_octave = octaves[2 * i];
    p.query_octave = octaves[2 * i + 1];
    JVL_CHECK(p.p_match.allFinite() && p.p_match.z() > 0 && p.match_uv.allFinite() &&
                  p.query_uv.allFinite(),
              path << ": loop_points row " << i << " is not a point in front of the camera");
    data.loops[static_cast<size_t>(point_loop[i])].points.push_back(p);
  }
  return data;
}

std::string FormatLoopsCsv(const LoopsData& data) {
  std::ostringstream out;
  out << "query,match,detector,status,score,ring_key_distance,yaw_deg,correspondences,inliers,"
         "residual,tx,ty,tz\n";
  for (const LoopRecord& r : data.loops) {
    const Eigen::Vector3d& t = r.match_from_query.translation();
    out << r.query << ',' << r.match << ',' << r.detector << ',' << r.status << ','
        << FormatDouble(r.score) << ',' << FormatDouble(r.ring_key_distance) << ','
        << FormatDouble(r.yaw_deg) << ',' << r.correspondences << ',' << r.inliers << ','
        << FormatDouble(r.residual) << ',' << FormatDouble(t.x()) << ',' << FormatDouble(t.y())
        << ',' << FormatDouble(t.z()) << '\n';
  }
  return out.str();
}

void WriteLoopsCsv(const std::string& path, const LoopsData& data) {
  WriteTextFileAtomic(path, FormatLoopsCsv(data));
}

}  // namespace jvl::io
