#include "loop/visual_loops.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <optional>

#include "core/check.h"
#include "core/lru_cache.h"
#include "core/threads.h"
#include "core/timer.h"

namespace jvl::loop {

void VisualLoopOptions::Check() const {
  orb.Check();
  lidar.Check();
  JVL_CHECK(camera >= 0 && camera < 4, "--camera " << camera << " is not a camera (0..3)");
  JVL_CHECK(group_keyframes >= 0, "group_keyframes must be >= 0, got " << group_keyframes);
  JVL_CHECK(min_common_ratio > 0 && min_common_ratio <= 1,
            "min_common_ratio must be in (0, 1], got " << min_common_ratio);
  JVL_CHECK(min_group_ratio > 0 && min_group_ratio <= 1,
            "min_group_ratio must be in (0, 1], got " << min_group_ratio);
  JVL_CHECK(consistency >= 1, "visual_consistency must be >= 1, got " << consistency);
  JVL_CHECK(match_level >= 0, "match_level must be >= 0, got " << match_level);
  JVL_CHECK(max_hamming >= 0 && max_hamming <= 256,
            "max_hamming must be in [0, 256], got " << max_hamming);
  JVL_CHECK(ratio > 0 && ratio <= 1, "ratio must be in (0, 1], got " << ratio);
  JVL_CHECK(depth_window_px >= 0 && max_depth_m > 0,
            "depth_window_px must be >= 0 and max_depth_m > 0");
  JVL_CHECK(max_reprojection_px > 0 && ransac_iterations >= 1,
            "max_reprojection_px must be > 0 and ransac_iterations >= 1");
  JVL_CHECK(min_inliers >= 4, "min_inliers must be >= 4, got " << min_inliers);
  JVL_CHECK(point_max_error_sigmas > 0,
            "point_max_error_sigmas must be > 0, got " << point_max_error_sigmas);
  JVL_CHECK(max_disagreement_m > 0 && max_disagreement_deg > 0,
            "max_disagreement_m and max_disagreement_deg must be > 0");
}

VisualKeyframe DescribeImage(const cv::Mat& image, const Vocabulary& vocabulary,
                             const VisualLoopOptions& o) {
  return DescribeFeatures(vision::ExtractOrb(image, o.orb), vocabulary, o);
}

VisualKeyframe DescribeFeatures(vision::OrbFeatures features, const Vocabulary& vocabulary,
                                const VisualLoopOptions& o) {
  VisualKeyframe k;
  k.keypoints = std::move(features.keypoints);
  k.descriptors = std::move(features.descriptors);
  k.nodes.resize(k.descriptors.size());
  for (size_t i = 0; i < k.descriptors.size(); ++i)
    vocabulary.Word(k.descriptors[i], o.match_level, &k.nodes[i]);
  k.bow = vocabulary.Transform(k.descriptors);
  return k;
}

namespace {

// Matches of query features to match features within the same vocabulary node: the nearest by
// Hamming distance up to max_hamming and below ratio x the second nearest; each match feature
// keeps its best query feature. Pairs (query index, match index), by query index.
std::vector<std::pair<int, int>> MatchByNode(const VisualKeyframe& q, const VisualKeyframe& m,
                                             const VisualLoopOptions& o) {
  // The match features by (node, index).
  std::vector<std::pair<int32_t, int>> by_node(m.nodes.size());
  for (size_t j = 0; j < m.nodes.size(); ++j) by_node[j] = {m.nodes[j], static_cast<int>(j)};
  std::sort(by_node.begin(), by_node.end());
  std::vector<int> best_query(m.descriptors.size(), -1), best_distance(m.descriptors.size(), 257);
  for (size_t i = 0; i < q.descriptors.size(); ++i) {
    auto it = std::lower_bound(by_node.begin(), by_node.end(),
                               std::make_pair(q.nodes[i], std::numeric_limits<int>::min()));
    int best = -1, d1 = 257, d2 = 257;
    for (; it != by_node.end() && it->first == q.nodes[i]; ++it) {
      const int j = it->second;
      const int d =
          vision::HammingDistance(q.descriptors[i], m.descriptors[static_cast<size_t>(j)]);
      if (d < d1) {
        d2 = d1, d1 = d, best = j;
      } else if (d < d2) {
        d2 = d;
      }
    }
    if (best < 0 || d1 > o.max_hamming || (d2 <= 256 && d1 >= o.ratio * d2)) continue;
    if (d1 < best_distance[static_cast<size_t>(best)]) {
      best_distance[static_cast<size_t>(best)] = d1;
      best_query[static_cast<size_t>(best)] = static_cast<int>(i);
    }
  }
  std::vector<std::pair<int, int>> pairs;
  for (size_t j = 0; j < best_query.size(); ++j)
    if (best_query[j] >= 0) pairs.emplace_back(best_query[j], static_cast<int>(j));
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// Depth image of a scan in the chosen camera: the nearest return per pixel (0 where none).
cv::Mat ScanDepth(const PointCloud& scan, const Calibration& calibration,
                  const PinholeCamera& camera, const Eigen::Vector3d& camera_offset) {
  cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(0));
  for (const Eigen::Vector3d& p : scan.points) {
    const Eigen::Vector3d c = calibration.cam0_from_velo * p + camera_offset;
    if (c.z() < 0.5) continue;
    const Eigen::Vector2d uv = camera.Project(c);
    if (!camera.InImage(uv)) continue;
    float& d = depth.at<float>(static_cast<int>(uv.y()), static_cast<int>(uv.x()));
    if (d == 0 || c.z() < d) d = static_cast<float>(c.z());
  }
  return depth;
}

// The non-zero pixels of ScanDepth's image (row-major index, depth): a match keyframe's depth
// is kept in this form between candidates (a few hundred kB where the scan is read and
// projected again in milliseconds), and the image rebuilt from it is the same.
using SparseDepth = std::vector<std::pair<int32_t, float>>;

SparseDepth ToSparse(const cv::Mat& depth) {
  SparseDepth sparse;
  for (int v = 0; v < depth.rows; ++v) {
    const float* row = depth.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u)
      if (row[u] > 0) sparse.emplace_back(v * depth.cols + u, row[u]);
  }
  return sparse;
}

// The image rebuilt from a sparse depth in a buffer of the calling thread (an image of its own
// per candidate cost a megabyte or two of fresh, zeroed pages each time), zeroed again when the
// guard goes out of scope.
class DenseDepth {
 public:
  DenseDepth(const SparseDepth& sparse, int rows, int cols) : sparse_(sparse) {
    thread_local cv::Mat buffer;
    if (buffer.rows != rows || buffer.cols != cols || buffer.type() != CV_32F)
      buffer = cv::Mat(rows, cols, CV_32F, cv::Scalar(0));
    image_ = buffer;
    float* data = image_.ptr<float>(0);
    for (const auto& [index, z] : sparse_) data[index] = z;
  }
  ~DenseDepth() {
    float* data = image_.ptr<float>(0);
    for (const auto& entry : sparse_) data[entry.first] = 0;
  }
  DenseDepth(const DenseDepth&) = delete;
  DenseDepth& operator=(const DenseDepth&) = delete;
  const cv::Mat& image() const { return image_; }

 private:
  const SparseDepth& sparse_;
  cv::Mat image_;  // Shares the thread's buffer.
};

// The depth of the latest match keyframes (sparse), shared by the threads verifying candidates
// (a match keyframe of one lap is the match of the queries of every later lap).
using DepthCache = LruCache<int64_t, SparseDepth>;

// Depth at a keypoint: the nearest return in the window, averaged with the returns within 5 %
// of it; 0 unless at least two agree.
// `found` is scratch space.
double DepthAt(const cv::Mat& depth, const Eigen::Vector2f& uv, const VisualLoopOptions& o,
               std::vector<float>& found) {
  const int r = static_cast<int>(std::ceil(o.depth_window_px));
  const int u0 = static_cast<int>(uv.x()), v0 = static_cast<int>(uv.y());
  found.clear();
  for (int v = std::max(0, v0 - r); v <= std::min(depth.rows - 1, v0 + r); ++v)
    for (int u = std::max(0, u0 - r); u <= std::min(depth.cols - 1, u0 + r); ++u)
      if (const float d = depth.at<float>(v, u); d > 0) found.push_back(d);
  if (found.size() < 2) return 0;
  const float nearest = *std::min_element(found.begin(), found.end());
  double sum = 0;
  int count = 0;
  for (const float d : found)
    if (d <= nearest * 1.05f) sum += d, ++count;
  const double z = sum / count;
  return count >= 2 && z <= o.max_depth_m ? z : 0;
}

// The images' part of a verification: keypoints matched, their depth from the match keyframe's
// scan, PnP. The candidate with its inliers (status kFewInliers); *image_pose = match_from_query
// when PnP found one with at least min_inliers.
LoopCandidate MatchVisualCandidate(const VisualKeyframe& query, const VisualKeyframe& match,
                                   int64_t match_frame, LoopScanCache& scans,
                                   const VisualLoopOptions& o, DepthCache* depths,
                                   std::optional<Rigid3d>* image_pose_out) {
  image_pose_out->reset();
  const Calibration& calibration = scans.calibration();
  LoopCandidate c;
  c.detector = "visual";
  c.status = LoopStatus::kFewInliers;
  // Geometry in the chosen camera's frame; the points and poses returned are in camera 0's.
  const PinholeCamera camera = calibration.Camera(o.camera);
  const CameraChoice choice = CameraChoice::Of(calibration, o.camera);
  const std::vector<std::pair<int, int>> matches = MatchByNode(query, match, o);
  // Too few matches for PnP to find min_inliers: the scan is not read.
  if (static_cast<int>(matches.size()) < o.min_inliers) return c;
  // The match keyframe's depth: projected from its scan (and kept), or rebuilt from the depth
  // kept.
  cv::Mat depth;
  auto project = [&] {
    depth = ScanDepth(scans.Load(match_frame), calibration, camera, choice.offset);
    return ToSparse(depth);
  };
  std::shared_ptr<const SparseDepth> kept;
  std::optional<DenseDepth> dense;
  if (!depths) {
    project();
  } else if (kept = depths->Get(match_frame, project); depth.empty()) {
    dense.emplace(*kept, camera.height, camera.width);
    depth = dense->image();
  }
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  std::vector<LoopPoint> points;
  std::vector<float> scratch;
  for (const auto& [qi, mi] : matches) {
    const vision::OrbKeypoint& km = match.keypoints[static_cast<size_t>(mi)];
    const vision::OrbKeypoint& kq = query.keypoints[static_cast<size_t>(qi)];
    const double z = DepthAt(depth, km.uv, o, scratch);
    if (z <= 0) continue;
    LoopPoint point;
    const Eigen::Vector3d p_camera = z * camera.Unproject(km.uv.cast<double>());
    point.p_match = p_camera - choice.offset;
    point.match_uv = km.uv.cast<double>();
    point.query_uv = kq.uv.cast<double>();
    point.match_octave = km.octave;
    point.query_octave = kq.octave;
    object.emplace_back(p_camera.x(), p_camera.y(), p_camera.z());
    image.emplace_back(point.query_uv.x(), point.query_uv.y());
    points.push_back(point);
  }
  if (static_cast<int>(object.size()) < o.min_inliers) return c;
  cv::Mat k;
  cv::eigen2cv(camera.K(), k);
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const bool solved =
      cv::solvePnPRansac(object, image, k, cv::noArray(), rvec, tvec, false, o.ransac_iterations,
                         static_cast<float>(o.max_reprojection_px), 0.999, inliers);
  c.inliers = solved ? static_cast<int>(inliers.size()) : 0;
  if (!solved || c.inliers < o.min_inliers) return c;
  std::sort(inliers.begin(), inliers.end());
  for (const int i : inliers) c.points.push_back(points[static_cast<size_t>(i)]);
  // solvePnP: x_query = R X_match + t, i.e. query_from_match.
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(r, rotation);
  cv::cv2eigen(tvec, translation);
  const Rigid3d image_pose =
      choice.camera_from_cam0().Inverse() *
      Rigid3d(Eigen::Quaterniond(rotation).normalized(), translation).Inverse() *
      choice.camera_from_cam0();
  *image_pose_out = image_pose;
  return c;
}

// The scans' part: the query's scan registered on the match's from the image's pose, the bounds,
// and the points kept.
void RegisterVisualCandidate(const Rigid3d& image_pose, int64_t query_frame, int64_t match_frame,
                             LoopScanCache& scans, const VisualLoopOptions& o, LoopCandidate* out) {
  LoopCandidate& c = *out;
  const Calibration& calibration = scans.calibration();
  const PinholeCamera camera = calibration.Camera(o.camera);
  const CameraChoice choice = CameraChoice::Of(calibration, o.camera);
  const lidar::RegistrationResult reg =
      RegisterLoopScans(*scans.Get(query_frame), *scans.Get(match_frame), image_pose, o.lidar);
  TakeRegistration(reg, o.lidar, &c);
  if (!reg.ok) c.match_from_query = image_pose;  // No registered pose: the image's.
  const Rigid3d moved = image_pose.Inverse() * c.match_from_query;
  if (c.status == LoopStatus::kAccepted &&
      (moved.translation().norm() > o.max_disagreement_m ||
       RotationAngle(moved.rotation()) * kRadToDeg > o.max_disagreement_deg)) {
    c.status = LoopStatus::kDisagree;
  }
  // The points kept for the global optimisation: the inliers that the registered pose also
  // projects within point_max_error_sigmas pyramid-level sigmas of their query pixel (a depth
  // taken across an edge, or a match the image's pose tolerated, is left out).
  const Rigid3d query_from_match = c.match_from_query.Inverse();
  const std::vector<double> scales = vision::LevelScales(o.orb);
  std::vector<LoopPoint> kept;
  for (const LoopPoint& p : c.points) {
    const Eigen::Vector3d x = query_from_match * p.p_match + choice.offset;
    const double sigma = scales[static_cast<size_t>(
        std::clamp(p.query_octave, 0, static_cast<int>(scales.size()) - 1))];
    if (x.z() > 0 && (camera.Project(x) - p.query_uv).norm() <= o.point_max_error_sigmas * sigma)
      kept.push_back(p);
  }
  c.points = std::move(kept);
  // Heading of the query relative to the match (about the camera's vertical, left positive).
  c.yaw_rad = RelativeHeading(c.match_from_query);
}

}  // namespace

LoopCandidate VerifyVisualCandidate(const VisualKeyframe& query, const VisualKeyframe& match,
                                    int64_t query_frame, int64_t match_frame, LoopScanCache& scans,
                                    const VisualLoopOptions& o) {
  std::optional<Rigid3d> image_pose;
  LoopCandidate c = MatchVisualCandidate(query, match, match_frame, scans, o, nullptr, &image_pose);
  if (image_pose) RegisterVisualCandidate(*image_pose, query_frame, match_frame, scans, o, &c);
  return c;
}

LoopResult DetectVisualLoops(const Trajectory& keyframes,
                             const std::function<vision::OrbFeatures(int64_t)>& features_of,
                             LoopScanCache& scans, const Vocabulary& vocabulary,
                             const VisualLoopOptions& o, int threads,
                             const std::function<void()>& tick) {
  o.Check();
  keyframes.Check("loop keyframes");
  const size_t n = keyframes.size();
  LoopResult result;
  result.keyframes = keyframes.frames;
  const std::vector<double> path = PathLengths(keyframes);
  Timer timer;
  std::vector<VisualKeyframe> described(n);
  ParallelFor(static_cast<int64_t>(n), threads, [&](int64_t i) {
    described[static_cast<size_t>(i)] =
        DescribeFeatures(features_of(keyframes.frames[static_cast<size_t>(i)]), vocabulary, o);
    if (tick) tick();
  });
  spdlog::debug("visual detector: {} keyframes described in {:.2f} s", n, timer.ElapsedSeconds());
  timer.Reset();

  // Inverted index: word -> keyframes holding it, in keyframe order (a query looks only at the
  // keyframes before it).
  std::vector<std::vector<size_t>> inverted(static_cast<size_t>(vocabulary.num_words()));
  for (size_t q = 0; q < n; ++q)
    for (const auto& [word, weight] : described[q].bow)
      inverted[static_cast<size_t>(word)].push_back(q);
  // The scored candidates of every query (in parallel; they depend on the query alone): the
  // earlier keyframes far enough back that share enough words with it and score at least as
  // high as its own neighbours (the keyframes just before it), by keyframe index.
  const long nb = o.group_keyframes;
  std::vector<std::vector<std::pair<size_t, double>>> scored(n);
  ParallelFor(static_cast<int64_t>(n), threads, [&](int64_t qi) {
    const size_t q = static_cast<size_t>(qi);
    const BowVector& bow = described[q].bow;
    // The lowest score against the query's own neighbours.
    double min_score = 1;
    bool have_neighbour = false;
    for (long b = 1; b <= std::max(nb, 1L) && static_cast<long>(q) - b >= 0; ++b) {
      min_score =
          std::min(min_score, Vocabulary::Score(bow, described[q - static_cast<size_t>(b)].bow));
      have_neighbour = true;
    }
    if (!have_neighbour) min_score = 0;
    std::vector<int> common(q, 0);
    for (const auto& [word, weight] : bow)
      for (const size_t j : inverted[static_cast<size_t>(word)]) {
        if (j >= q) break;
        ++common[j];
      }
    int most = 0;
    for (size_t j = 0; j < q; ++j)
      if (path[q] - path[j] >= o.lidar.min_separation_m) most = std::max(most, common[j]);
    if (most == 0) return;
    const double least = o.min_common_ratio * most;
    for (size_t j = 0; j < q; ++j) {
      if (path[q] - path[j] < o.lidar.min_separation_m || common[j] < least) continue;
      const double s = Vocabulary::Score(bow, described[j].bow);
      if (s >= min_score) scored[q].emplace_back(j, s);
    }
  });
  struct Group {
    long lo, hi;      // Keyframe indices.
    int consecutive;  // Query keyframes in a row that had an overlapping group, this one included.
  };
  std::vector<Group> previous_groups;
  std::vector<std::pair<size_t, size_t>> to_verify;  // (query, match) keyframe indices.
  std::vector<double> to_verify_score;
  for (size_t q = 0; q < n; ++q) {
    std::vector<double> score(q, -1);  // >= 0: a candidate.
    for (const auto& [j, s] : scored[q]) score[j] = s;
    // Groups: a candidate with its candidate neighbours; the accumulated score, its best member.
    std::vector<std::pair<double, size_t>> groups;  // (accumulated, best member)
    double best_accumulated = 0;
    for (size_t j = 0; j < q; ++j) {
      if (score[j] < 0) continue;
      double accumulated = 0, best = -1;
      size_t best_member = j;
      for (long g = static_cast<long>(j) - nb; g <= static_cast<long>(j) + nb; ++g) {
        if (g < 0 || g >= static_cast<long>(q) || score[static_cast<size_t>(g)] < 0) continue;
        accumulated += score[static_cast<size_t>(g)];
        if (score[static_cast<size_t>(g)] > best)
          best = score[static_cast<size_t>(g)], best_member = static_cast<size_t>(g);
      }
      groups.emplace_back(accumulated, best_member);
      best_accumulated = std::max(best_accumulated, accumulated);
    }
    std::vector<size_t> representatives;
    for (const auto& [accumulated, member] : groups)
      if (accumulated >= o.min_group_ratio * best_accumulated) representatives.push_back(member);
    std::sort(representatives.begin(), representatives.end());
    representatives.erase(std::unique(representatives.begin(), representatives.end()),
                          representatives.end());
    // Temporal consistency with the previous query's groups.
    std::vector<Group> current;
    for (const size_t r : representatives) {
      Group group{static_cast<long>(r) - nb, static_cast<long>(r) + nb, 1};
      for (const Group& p : previous_groups)
        if (group.lo <= p.hi && p.lo <= group.hi)
          group.consecutive = std::max(group.consecutive, p.consecutive + 1);
      current.push_back(group);
      if (group.consecutive >= o.consistency) {
        to_verify.emplace_back(q, r);
        to_verify_score.push_back(score[r]);
      }
    }
    previous_groups = std::move(current);
  }

  // Verification (independent, in parallel; results in their slots), then the best accepted
  // candidate per query (most inliers), or the first rejected one.
  spdlog::debug("visual detector: {} candidates found in {:.2f} s", to_verify.size(),
                timer.ElapsedSeconds());
  timer.Reset();
  // 1. The images of every candidate (in parallel): matching, depth, PnP.
  std::vector<LoopCandidate> verified(to_verify.size());
  std::vector<std::optional<Rigid3d>> image_pose(to_verify.size());
  DepthCache depths(512);
  ParallelFor(static_cast<int64_t>(to_verify.size()), threads, [&](int64_t vi) {
    const size_t v = static_cast<size_t>(vi);
    const auto [q, m] = to_verify[v];
    verified[v] = MatchVisualCandidate(described[q], described[m], keyframes.frames[m], scans, o,
                                       &depths, &image_pose[v]);
    verified[v].query = keyframes.frames[q];
    verified[v].match = keyframes.frames[m];
    verified[v].descriptor_distance = to_verify_score[v];
    if (tick) tick();
  });
  spdlog::debug("visual detector: {} candidates matched in {:.2f} s", verified.size(),
                timer.ElapsedSeconds());
  timer.Reset();
  // 2. Per query (to_verify runs query by query), the candidates with an image pose, most PnP
  // inliers first (ties: the order found). The scans of each query's first one are prepared in
  // parallel.
  std::vector<std::pair<size_t, size_t>> queries;  // [begin, end) of to_verify.
  for (size_t v = 0; v < to_verify.size();) {
    size_t end = v;
    while (end < to_verify.size() && to_verify[end].first == to_verify[v].first) ++end;
    queries.emplace_back(v, end);
    v = end;
  }
  std::vector<std::vector<size_t>> order(queries.size());
  std::vector<int64_t> frames;
  for (size_t g = 0; g < queries.size(); ++g) {
    for (size_t v = queries[g].first; v < queries[g].second; ++v)
      if (image_pose[v]) order[g].push_back(v);
    std::stable_sort(order[g].begin(), order[g].end(),
                     [&](size_t a, size_t b) { return verified[a].inliers > verified[b].inliers; });
    if (order[g].empty()) continue;
    frames.push_back(verified[order[g][0]].query);
    frames.push_back(verified[order[g][0]].match);
  }
  scans.Prepare(std::move(frames), threads);
  std::vector<LoopCandidate> result_slots(queries.size());
  // 3. Registered in that order until one is accepted (in parallel over the queries): the
  // accepted candidate with the most inliers, as if every one had been registered; a query
  // without one keeps its first candidate.
  ParallelFor(static_cast<int64_t>(queries.size()), threads, [&](int64_t gi) {
    const size_t g = static_cast<size_t>(gi);
    size_t keep = queries[g].first;
    for (const size_t v : order[g]) {
      LoopCandidate& c = verified[v];
      const auto [q, m] = to_verify[v];
      RegisterVisualCandidate(*image_pose[v], c.query, c.match, scans, o, &c);
      if (c.status == LoopStatus::kAccepted && FarInPrior(keyframes, path, q, m, o.lidar))
        c.status = LoopStatus::kFarInPrior;
      if (c.status == LoopStatus::kAccepted) {
        keep = v;
        break;
      }
    }
    result_slots[g] = verified[keep];
  });
  spdlog::debug("visual detector: {} queries registered in {:.2f} s", queries.size(),
                timer.ElapsedSeconds());
  result.candidates = std::move(result_slots);
  return result;
}

}  // namespace jvl::loop
