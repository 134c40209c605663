#include "mapping/visual/map_builder.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <map>
#include <utility>

#include "core/check.h"
#include "core/threads.h"
#include "core/timer.h"

namespace jvl::mapping {

void VisualMapOptions::Check() const {
  orb.Check();
  projection.Check();
  epipolar.Check();
  triangulation.Check();
  keyframe.Check();
  JVL_CHECK(local_keyframes >= 1, "visual map: local_keyframes must be >= 1");
  JVL_CHECK(triangulation_neighbors >= 1, "visual map: triangulation_neighbors must be >= 1");
  JVL_CHECK(min_baseline_ratio >= 0, "visual map: min_baseline_ratio must be >= 0");
  JVL_CHECK(min_view_cos >= -1 && min_view_cos <= 1, "visual map: min_view_cos in [-1, 1]");
  JVL_CHECK(min_observations >= 2, "visual map: min_observations must be >= 2");
  JVL_CHECK(cull_after_keyframes >= 1, "visual map: cull_after_keyframes must be >= 1");
  JVL_CHECK(min_found_ratio >= 0 && min_found_ratio <= 1, "visual map: min_found_ratio in [0, 1]");
  JVL_CHECK(max_final_chi2 > 0, "visual map: max_final_chi2 must be > 0");
  JVL_CHECK(track_chi2 >= 0, "visual map: track_chi2 must be >= 0");
  JVL_CHECK(min_covisibility_weight >= 1, "visual map: min_covisibility_weight must be >= 1");
  JVL_CHECK(track_min_inliers >= 6, "visual map: track_min_inliers must be >= 6");
  JVL_CHECK(track_min_rotation_deg >= 0 && track_min_translation_m >= 0,
            "visual map: track_min_rotation_deg and track_min_translation_m must be >= 0");
  JVL_CHECK(track_max_rotation_deg > 0 && track_max_translation_m > 0,
            "visual map: track_max_rotation_deg and track_max_translation_m must be positive");
  pose.Check();
}

VisualMapBuilder::VisualMapBuilder(const PinholeCamera& camera, const VisualMapOptions& options,
                                   int threads)
    : options_(options), threads_(std::max(1, threads)) {
  options_.Check();
  camera.Check();
  JVL_CHECK(camera.width > 0 && camera.height > 0, "visual map: camera image size unknown");
  map_.camera = camera;
  map_.orb = options.orb;
  map_.level_scales = vision::LevelScales(options.orb);
}

std::vector<int> VisualMapBuilder::LocalPoints() const {
  std::vector<int> points;
  const int n = static_cast<int>(map_.keyframes.size());
  for (int k = std::max(0, n - options_.local_keyframes); k < n; ++k) {
    for (int p : map_.keyframes[k].mappoint) {
      if (p >= 0 && !map_.points[p].bad) points.push_back(p);
    }
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}

std::vector<std::pair<int, int>> VisualMapBuilder::MatchAt(const vision::OrbFeatures& features,
                                                           const vision::KeypointGrid& grid,
                                                           const std::vector<int>& local,
                                                           const Rigid3d& cam_from_world,
                                                           std::vector<int>* predicted) const {
  predicted->clear();
  const auto projected =
      PredictInView(map_, local, cam_from_world, options_.min_view_cos, predicted);
  const std::vector<int> match =
      vision::MatchByProjection(projected, features, grid, map_.level_scales, options_.projection);
  std::vector<std::pair<int, int>> out;
  for (size_t i = 0; i < match.size(); ++i) {
    if (match[i] >= 0) out.emplace_back((*predicted)[i], match[i]);
  }
  return out;
}

// Tracking: the local map points matched by projection at the predicted pose; with track_pose
// the pose is refined from those matches and the points are matched again there.
std::vector<int> VisualMapBuilder::Track(const vision::OrbFeatures& features,
                                         Rigid3d* cam_from_world, FrameReport* report) {
  const std::vector<int> local = LocalPoints();
  const vision::KeypointGrid grid(features.keypoints, map_.camera.width, map_.camera.height);
  std::vector<int> predicted;
  std::vector<std::pair<int, int>> matches =
      MatchAt(features, grid, local, *cam_from_world, &predicted);
  if (options_.track_pose) {
    std::vector<vision::PointObservation> obs;
    for (const auto& [p, k] : matches) {
      const vision::OrbKeypoint& kp = features.keypoints[k];
      obs.push_back({map_.points[p].position, kp.uv.cast<double>(), map_.level_scales[kp.octave]});
    }
    const Rigid3d predicted_pose = *cam_from_world;
    const Eigen::Vector3d center = predicted_pose.Inverse().translation();
    const vision::PoseRefinement r =
        vision::RefinePose(map_.camera, obs, predicted_pose, options_.pose, center);
    const Rigid3d change = r.cam_from_world * predicted_pose.Inverse();
    report->correction_deg = RotationAngle(change.rotation()) * 180.0 / M_PI;
    report->correction_m = (r.cam_from_world.Inverse().translation() - center).norm();
    report->pose_inliers = r.inliers;
    for (const vision::PointObservation& o : obs) {
      const double s2 = o.level_scale * o.level_scale;
      if (vision::SquaredReprojectionError(map_.camera, predicted_pose, o.point_world, o.uv) <=
          options_.pose.chi2 * s2) {
        ++report->predicted_inliers;
      }
    }
    const bool small = report->correction_deg <= options_.track_max_rotation_deg &&
                       report->correction_m <= options_.track_max_translation_m;
    const bool disagree = report->correction_deg > options_.track_min_rotation_deg ||
                          report->correction_m > options_.track_min_translation_m;
    const bool explains_more =
        r.inliers >= options_.track_min_inlier_gain * report->predicted_inliers;
    if (r.ok && r.inliers >= options_.track_min_inliers && small && disagree && explains_more) {
      *cam_from_world = r.cam_from_world;
      report->pose_refined = true;
      matches = MatchAt(features, grid, local, *cam_from_world, &predicted);
    }
  }
  for (const int p : predicted) ++map_.points[p].visible;
  std::vector<int> keypoint_point(features.size(), -1);
  for (const auto& [point, keypoint] : matches) {
    MapPoint& p = map_.points[point];
    if (options_.track_chi2 > 0) {
      const vision::OrbKeypoint& kp = features.keypoints[keypoint];
      const double s = map_.level_scales[kp.octave];
      if (vision::SquaredReprojectionError(map_.camera, *cam_from_world, p.position,
                                           kp.uv.cast<double>()) > options_.track_chi2 * s * s) {
        continue;
      }
    }
    ++p.found;
    keypoint_point[keypoint] = point;
    ++report->tracked;
  }
  report->candidates = static_cast<int>(predicted.size());
  return keypoint_point;
}

// Points of the reference keyframe (the one sharing most tracked points) seen by >= 3 keyframes
// (2 while the map has at most 2 keyframes), as ORB-SLAM2's Tracking::NeedNewKeyFrame.
int VisualMapBuilder::ReferenceTracked(const std::vector<int>& keypoint_point) const {
  std::map<int, int> shared;
  for (int p : keypoint_point) {
    if (p < 0) continue;
    for (const Observation& o : map_.points[p].observations) ++shared[o.keyframe];
  }
  int reference = static_cast<int>(map_.keyframes.size()) - 1, best = -1;
  for (const auto& [k, n] : shared) {
    if (n >= best) best = n, reference = k;  // Ties: the most recent keyframe.
  }
  if (reference < 0) return 0;
  const int min_obs = map_.keyframes.size() <= 2 ? 2 : 3;
  int count = 0;
  for (int p : map_.keyframes[reference].mappoint) {
    if (p >= 0 && static_cast<int>(map_.points[p].observations.size()) >= min_obs) ++count;
  }
  return count;
}

FrameReport VisualMapBuilder::AddFrame(int64_t frame, const Rigid3d& world_from_cam,
                                       vision::OrbFeatures features, bool has_direction) {
  JVL_CHECK(frame > last_frame_ || first_,
            "visual map: frame " << frame << " does not follow frame " << last_frame_);
  const Timer timer;
  FrameReport report;
  report.frame = frame;
  report.keypoints = static_cast<int>(features.size());
  // The pose: the previous frame's pose moved by the prior's motion since then (the prior
  // itself while no frame was refined), refined by tracking.
  Rigid3d pose = world_from_cam;
  if (!first_ && options_.track_pose && corrected_) {
    pose = last_pose_ * (last_prior_.Inverse() * world_from_cam);
  }
  Rigid3d cam_from_world = pose.Inverse();
  ++frames_since_keyframe_;
  std::vector<int> keypoint_point(features.size(), -1);
  if (!first_) keypoint_point = Track(features, &cam_from_world, &report);
  if (report.pose_refined) {
    pose = cam_from_world.Inverse();
    corrected_ = true;
  }
  const Rigid3d change = world_from_cam.Inverse() * pose;
  report.pose_change_deg = RotationAngle(change.rotation()) * 180.0 / M_PI;
  report.pose_change_m = change.translation().norm();
  last_prior_ = world_from_cam;
  last_pose_ = pose;

  KeyframeRuleInput input;
  input.first_frame = first_;
  input.frames_since_last_keyframe = frames_since_keyframe_;
  input.tracked = report.tracked;
  input.reference_tracked = first_ ? 0 : ReferenceTracked(keypoint_point);
  input.has_direction = has_direction;
  const KeyframeDecision decision = DecideKeyframe(input, options_.keyframe);
  report.keyframe = decision.keyframe;
  report.reason = decision.reason;
  first_ = false;
  if (decision.keyframe) {
    Keyframe kf;
    kf.frame = frame;
    kf.world_from_cam = pose;
    kf.cam_from_world = cam_from_world;
    kf.mappoint.assign(features.size(), -1);
    kf.features = std::move(features);
    kf.has_direction = has_direction;
    map_.keyframes.push_back(std::move(kf));
    const int k = static_cast<int>(map_.keyframes.size()) - 1;
    // The tracked keypoints (one per point) are aligned first, in parallel: an alignment reads
    // its point's position and patch, which refining another point does not change.
    std::vector<std::pair<int, int>> tracked;  // (point, keypoint)
    for (size_t i = 0; i < keypoint_point.size(); ++i) {
      if (keypoint_point[i] >= 0) tracked.emplace_back(keypoint_point[i], static_cast<int>(i));
    }
    const std::vector<Alignment> aligned = ComputeAlignments(tracked, k);
    for (size_t t = 0; t < tracked.size(); ++t) {
      const auto [point, keypoint] = tracked[t];
      if (!ApplyAlignment(aligned[t], k, keypoint) && options_.require_alignment) continue;
      AddObservation(&map_, point, k, keypoint);
      if (options_.refine_on_insert) {
        RefineAndCheck(point);
      } else {
        UpdatePointGeometry(&map_, point);
      }
    }
    const size_t before = map_.points.size();
    report.new_points = CreateNewPoints(k);
    std::vector<int> created;
    for (size_t p = before; p < map_.points.size(); ++p) created.push_back(static_cast<int>(p));
    report.fused = FusePoints(k, created);
    report.culled = CullRecentPoints(k);
    // Only the local keyframes receive observations; older pyramids are not needed.
    const int old = k - options_.local_keyframes - 1;
    if (old >= 0) map_.keyframes[old].features.pyramid.clear();
    frames_since_keyframe_ = 0;
  }
  last_frame_ = frame;
  report.ms = timer.ElapsedMs();
  return report;
}

VisualMap VisualMapBuilder::Finish() {
  for (Keyframe& kf : map_.keyframes) kf.features.pyramid.clear();
  for (size_t i = 0; i < map_.points.size(); ++i) {
    MapPoint& p = map_.points[i];
    if (p.bad) continue;
    std::vector<vision::PointView> views;
    for (const Observation& o : p.observations) {
      const Keyframe& kf = map_.keyframes[o.keyframe];
      const vision::OrbKeypoint& kp = kf.features.keypoints[o.keypoint];
      views.push_back({kf.cam_from_world, kp.uv.cast<double>(), map_.level_scales[kp.octave]});
    }
    if (options_.refine_points && views.size() >= 2) {
      p.position = vision::RefinePoint(map_.camera, views, p.position);
    }
    std::vector<Observation> kept;
    for (size_t v = 0; v < views.size(); ++v) {
      const double e2 = vision::SquaredReprojectionError(map_.camera, views[v].cam_from_world,
                                                         p.position, views[v].uv);
      const double s2 = views[v].level_scale * views[v].level_scale;
      if (e2 <= options_.max_final_chi2 * s2) {
        kept.push_back(p.observations[v]);
      } else {
        map_.keyframes[p.observations[v].keyframe].mappoint[p.observations[v].keypoint] = -1;
      }
    }
    p.observations = kept;
    if (p.observations.size() < 2) {
      RemovePoint(&map_, static_cast<int>(i));
    } else {
      UpdatePointGeometry(&map_, static_cast<int>(i));
    }
  }
  VisualMap out = std::move(map_);
  map_ = VisualMap{};
  return out;
}

VisualMapResult BuildVisualMap(const PinholeCamera& camera, const Trajectory& poses,
                               const std::vector<int64_t>& direction_frames,
                               const std::function<cv::Mat(int64_t)>& load_image,
                               const VisualMapOptions& options, int threads,
                               const std::function<void(const FrameReport&)>& on_frame) {
  options.Check();
  poses.Check("prior poses");
  vision::OrbOptions orb = options.orb;
  orb.keep_pyramid = options.align_patches;
  std::vector<int64_t> directions = direction_frames;
  std::sort(directions.begin(), directions.end());
  VisualMapResult result;
  result.track_pose = options.track_pose;
  std::unique_ptr<VisualMapBuilder> builder;
  const int64_t n = static_cast<int64_t>(poses.size());
  const int64_t batch = std::max(1, threads) * 2;
  struct Batch {
    std::vector<vision::OrbFeatures> features;
    std::vector<double> ms;
    std::vector<cv::Size> sizes;
  };
  const auto extract = [&](int64_t start) {
    const int64_t m = std::min(batch, n - start);
    Batch b;
    b.features.resize(m);
    b.ms.resize(m);
    b.sizes.resize(m);
    ParallelFor(m, threads, [&](int64_t i) {
      const Timer t;
      const cv::Mat image = load_image(poses.frames[start + i]);
      b.sizes[i] = image.size();
      b.features[i] = vision::ExtractOrb(image, orb);
      b.ms[i] = t.ElapsedMs();
    });
    return b;
  };
  // With two or more threads the next batch is extracted while this one is associated; the
  // features do not depend on the association, so the map is the same either way.
  const bool prefetch = threads >= 2;
  std::future<Batch> pending;
  if (prefetch && n > 0) pending = std::async(std::launch::async, extract, 0);
  for (int64_t start = 0; start < n; start += batch) {
    Batch b = prefetch ? pending.get() : extract(start);
    if (prefetch && start + batch < n) {
      pending = std::async(std::launch::async, extract, start + batch);
    }
    for (int64_t i = 0; i < static_cast<int64_t>(b.features.size()); ++i) {
      if (!builder) {
        PinholeCamera c = camera;
        if (c.width <= 0 || c.height <= 0) c.width = b.sizes[i].width, c.height = b.sizes[i].height;
        builder = std::make_unique<VisualMapBuilder>(c, options, threads);
      }
      const int64_t frame = poses.frames[start + i];
      const bool dir = std::binary_search(directions.begin(), directions.end(), frame);
      result.frames.push_back(
          builder->AddFrame(frame, poses.world_from_cam[start + i], std::move(b.features[i]), dir));
      result.orb_ms.push_back(b.ms[i]);
      if (on_frame) on_frame(result.frames.back());
    }
  }
  if (builder) result.map = builder->Finish();
  return result;
}

}  // namespace jvl::mapping
