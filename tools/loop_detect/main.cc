// loop_detect: loop closures of a drive (the paper's loop-closing module, supplement 1.3).
// Reads the dataset's scans and images and a trajectory (the prior or the odometry: only its path
// length is used, to skip the keyframes just driven, and a bound on its drift), finds revisited
// places with two independent detectors - the LiDAR place descriptor and the paper's visual words
// (bag of binary words, ORB-SLAM2's procedure) - verifies each candidate (scan registration;
// visual: PnP on LiDAR depth, then scan registration), and writes every verified candidate,
// accepted or not, to a loops artifact. With --gt it reports the revisits of the ground truth and
// how many each detector found (recall) and how many loops were right (precision).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <future>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "app/option_group.h"
#include "app/tool.h"
#include "core/check.h"
#include "core/progress.h"
#include "core/strings.h"
#include "core/threads.h"
#include "io/dataset.h"
#include "io/files.h"
#include "io/loops_io.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "loop/lidar_loops.h"
#include "loop/visual_loops.h"
#include "loop/vocabulary.h"
#include "mapping/visual/visual_artifact.h"

namespace {

using namespace jvl;

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// Keyframes: every `every`-th frame of the trajectory that the dataset has.
Trajectory SelectKeyframes(const Trajectory& poses, const io::Dataset& dataset, int every) {
  Trajectory out;
  const auto& frames = dataset.frames();
  size_t count = 0;
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!std::binary_search(frames.begin(), frames.end(), poses.frames[i])) continue;
    if (count++ % static_cast<size_t>(every) == 0)
      out.Append(poses.frames[i], poses.world_from_cam[i]);
  }
  return out;
}

// Against the ground truth: a keyframe revisits a place when an earlier keyframe at least
// min_separation back along the true path lies within 5 m (same direction: headings within
// 30 deg; opposite: more than 150 deg apart). A loop is right when its relative pose is within
// 1 m and 2 deg of the true one.
// detector: -1 = every accepted loop; 0 / 1 / 2 = the loops that detector accepted. A detector
// run after another verified only the queries left open: run it alone (--detectors) for its own
// recall.
// Returns the figures it logs (the --report entry of `label`).
nlohmann::json ReportAgainstGroundTruth(const Trajectory& gt, const io::LoopsData& loops,
                                        double min_separation, int detector,
                                        const std::string& label) {
  Trajectory kf;
  for (const int64_t f : loops.keyframes) {
    const auto i = gt.IndexOf(f);
    JVL_CHECK(i, "--gt has no pose for keyframe " << f);
    kf.Append(f, gt.world_from_cam[*i]);
  }
  const size_t n = kf.size();
  std::vector<double> path(n, 0.0);
  for (size_t i = 1; i < n; ++i)
    path[i] = path[i - 1] +
              (kf.world_from_cam[i].translation() - kf.world_from_cam[i - 1].translation()).norm();
  std::vector<int> kind(n, 0);  // 0 none, 1 same direction, 2 opposite.
  for (size_t q = 0; q < n; ++q) {
    const Eigen::Vector3d zq = kf.world_from_cam[q].rotation() * Eigen::Vector3d::UnitZ();
    for (size_t j = 0; j < q && path[q] - path[j] >= min_separation; ++j) {
      if ((kf.world_from_cam[q].translation() - kf.world_from_cam[j].translation()).norm() > 5)
        continue;
      const Eigen::Vector3d zj = kf.world_from_cam[j].rotation() * Eigen::Vector3d::UnitZ();
      const double angle = std::acos(std::clamp(zq.dot(zj), -1.0, 1.0)) * kRadToDeg;
      if (angle < 30) kind[q] = 1;
      if (angle > 150 && kind[q] == 0) kind[q] = 2;
    }
  }
  std::vector<int> found(n, 0);
  int accepted = 0, right = 0;
  for (const io::LoopRecord& r : loops.loops) {
    if (r.status != 0 || (detector >= 0 && r.detector != detector)) continue;
    ++accepted;
    const auto q = gt.IndexOf(r.query), m = gt.IndexOf(r.match);
    const Rigid3d truth = gt.world_from_cam[*m].Inverse() * gt.world_from_cam[*q];
    const Rigid3d error = truth.Inverse() * r.match_from_query;
    const bool ok =
        error.translation().norm() <= 1 && RotationAngle(error.rotation()) * kRadToDeg <= 2;
    right += ok ? 1 : 0;
    if (!ok) {
      spdlog::warn(
          "loop {} -> {} is wrong: {:.2f} m apart in truth, relative pose off by {:.2f} m, {:.2f} "
          "deg",
          r.query, r.match, truth.translation().norm(), error.translation().norm(),
          RotationAngle(error.rotation()) * kRadToDeg);
    }
    const auto k = std::lower_bound(loops.keyframes.begin(), loops.keyframes.end(), r.query) -
                   loops.keyframes.begin();
    if (ok) found[static_cast<size_t>(k)] = 1;
  }
  int same = 0, opposite = 0, same_found = 0, opposite_found = 0;
  for (size_t q = 0; q < n; ++q) {
    if (kind[q] == 1) same += 1, same_found += found[q];
    if (kind[q] == 2) opposite += 1, opposite_found += found[q];
  }
  // Stretches: runs of consecutive revisiting keyframes of one kind; closed when a right loop
  // has its query in the run.
  int stretches[3] = {0, 0, 0}, closed[3] = {0, 0, 0};
  for (size_t q = 0; q < n;) {
    size_t end = q;
    int any = 0;
    while (end < n && kind[end] == kind[q]) any |= found[end++];
    stretches[kind[q]] += 1;
    closed[kind[q]] += any;
    q = end;
  }
  auto pct = [](int a, int b) {
    return b > 0 ? fmt::format("{:.0f} %", 100.0 * a / b) : std::string("-");
  };
  spdlog::info(
      "against --gt, {}: {} accepted loops, {} right (precision {}); revisiting keyframes "
      "{} in the same direction, {} found (recall {}), {} in the opposite direction, "
      "{} found (recall {}); revisit stretches closed: same direction {} of {} ({}), "
      "opposite {} of {} ({})",
      label, accepted, right, pct(right, accepted), same, same_found, pct(same_found, same),
      opposite, opposite_found, pct(opposite_found, opposite), closed[1], stretches[1],
      pct(closed[1], stretches[1]), closed[2], stretches[2], pct(closed[2], stretches[2]));
  return {{"detector", label},
          {"accepted", accepted},
          {"right", right},
          {"revisits_same", same},
          {"found_same", same_found},
          {"revisits_opposite", opposite},
          {"found_opposite", opposite_found},
          {"stretches_same", stretches[1]},
          {"closed_same", closed[1]},
          {"stretches_opposite", stretches[2]},
          {"closed_opposite", closed[2]}};
}

}  // namespace

int main(int argc, char** argv) {
  app::Tool tool("loop_detect",
                 "Loop closures of a drive: revisited places found with visual words (bag of "
                 "binary ORB words, ORB-SLAM2's candidate groups and temporal consistency), with "
                 "a LiDAR place descriptor (polar grid of largest heights, rotation-invariant "
                 "ring key) and by proximity in the trajectory given (its nearest earlier "
                 "keyframe); a visual candidate is verified by PnP on the LiDAR depth of the "
                 "earlier image and then the scan registration, the others by registering the "
                 "two scans; every verified candidate, accepted or not, goes to the loops "
                 "artifact.");
  std::string dataset_dir, frames = ":", poses_path, output, gt_path, csv, visual_path, report;
  int every = 5;
  int scan_cache = 1024;
  std::vector<std::string> detectors = {"lidar", "visual", "proximity"};
  std::string vocabulary_path = JVL_DEFAULT_VOCABULARY;
  io::DatasetOptions dataset_options;
  loop::LidarLoopOptions options;
  loop::VisualLoopOptions visual_options;
  std::string vertical_correction = "auto";
  CLI::App& cli = tool.cli();
  cli.add_option("--dataset,-d", dataset_dir, "Sequence folder (KITTI odometry/raw, synthetic)")
      ->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--frames", frames, "Frame range A:B (B exclusive)")->capture_default_str();
  CLI::Option* camera_option =
      cli.add_option("--camera", visual_options.camera,
                     std::string(io::kCameraHelp) + " (with --visual: the visual map's camera)")
          ->capture_default_str();
  cli.add_option("--poses", poses_path,
                 "Trajectory of the drive (odometry or prior: .h5 artifact, KITTI or TUM text); "
                 "only its path length is used, to skip the keyframes just driven")
      ->required();
  cli.add_option("--every", every, "Keyframes: every K-th frame of the trajectory")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  tool.OutputFile(cli.add_option("-o,--output", output, "Output loops artifact (.h5)")->required());
  tool.OutputFile(
      cli.add_option("--csv", csv,
                     "Also write the candidates as CSV (query, match, detector, status, "
                     "scores, registration, relative translation)"));
  cli.add_option("--detectors", detectors,
                 "Detectors to run (any of visual, lidar, proximity; run in that order, each "
                 "later one verifying only the queries the ones before it left open). proximity: "
                 "the trajectory's nearest earlier keyframe, verified by scan registration")
      ->delimiter(',')
      ->check(CLI::IsMember({"lidar", "visual", "proximity"}))
      ->capture_default_str();
  cli.add_option("--vocabulary", vocabulary_path,
                 "Vocabulary of the visual detector (vocab_train); the default is the one shipped "
                 "in data/vocabulary")
      ->capture_default_str();
  cli.add_option("--visual", visual_path,
                 "Visual map of the drive (visual_assoc): the visual detector takes the ORB "
                 "features of the keyframes it holds from there instead of extracting them again "
                 "(the same features when visual_assoc ran with the same ORB settings); the "
                 "others are extracted");
  cli.add_option("--scan-cache", scan_cache,
                 "Prepared scans kept for the verification (about 1 MB each on KITTI scans): more "
                 "saves preparing a scan again when matches lie several laps back")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cli.add_option("--gt", gt_path,
                 "Ground-truth trajectory: report the revisits and the loops' recall and "
                 "precision in the log");
  tool.OutputFile(cli.add_option(
      "--report", report,
      "With --gt: also write those figures as JSON (per detector in the order they ran, then "
      "\"combined\": accepted and right loops, revisiting keyframes found in the same and the "
      "opposite direction, revisit stretches closed; and the keyframes and candidates)"));
  app::OptionGroup shared(tool, "Every detector");
  shared.Add("--min-separation", "min_separation_m", options.min_separation_m,
             "Candidates lie at least this far back along the path (m)");
  shared.Add("--max-residual", "max_residual", options.max_residual,
             "Accept a registration with an RMS IMLS distance up to this (m)");
  shared.Add("--min-correspondences", "min_correspondences", options.min_correspondences,
             "Accept a registration with at least this many correspondences");
  shared.Add("--vertical-correction", "vertical_correction_deg", vertical_correction,
             std::string(io::kVerticalCorrectionHelp) + "; the scans the registrations use");
  app::OptionGroup lidar(tool, "LiDAR detector");
  lidar.Add("--max-descriptor-distance", "max_descriptor_distance", options.max_descriptor_distance,
            "Verify the best candidate only below this descriptor distance (0 = identical, 1)");
  lidar.Add("--consistency", "consistency", options.consistency,
            "Accept a loop when this many consecutive keyframes have verified matches that agree");
  app::OptionGroup proximity(tool, "Proximity detector");
  proximity.Add("--proximity-radius", "proximity_radius_m", options.proximity_radius_m,
                "Candidates lie within this distance of the query in the trajectory given (m) ...");
  proximity.Add("--proximity-drift", "proximity_drift", options.proximity_drift,
                "... plus this fraction of the path length between them (the trajectory's drift)");
  app::OptionGroup visual(tool, "Visual detector");
  visual.Add("--visual-consistency", "visual_consistency", visual_options.consistency,
             "Verify a candidate group once this many consecutive keyframes have overlapping "
             "groups");
  visual.Add("--min-inliers", "min_inliers", visual_options.min_inliers,
             "Accept a visual candidate with at least this many PnP inliers");
  visual.Add("--visual-features", "num_features", visual_options.orb.num_features,
             "ORB features per keyframe image");

  return tool.Run(argc, argv, [&] {
    options.Check();
    JVL_CHECK(report.empty() || !gt_path.empty(), "--report needs --gt");
    const bool use_lidar =
        std::find(detectors.begin(), detectors.end(), "lidar") != detectors.end();
    const bool use_visual =
        std::find(detectors.begin(), detectors.end(), "visual") != detectors.end();
    const bool use_proximity =
        std::find(detectors.begin(), detectors.end(), "proximity") != detectors.end();
    // One set of separation, registration and drift bounds for every detector.
    visual_options.lidar = options;
    visual_options.Check();
    std::optional<loop::Vocabulary> vocabulary;
    if (use_visual) {
      JVL_CHECK(std::filesystem::exists(vocabulary_path),
                "vocabulary " << vocabulary_path
                              << " not found: give one with --vocabulary (vocab_train makes one) "
                                 "or run only the LiDAR detector with --detectors lidar");
      tool.AddInput(vocabulary_path, /*same_dataset=*/false);  // Serves every sequence.
      vocabulary = loop::Vocabulary::Load(vocabulary_path);
    }
    const auto dataset = io::OpenDataset(dataset_dir, dataset_options, ParseFrameRange(frames));
    tool.AddDataset(*dataset, dataset_dir);
    options.preprocess.vertical_correction_deg =
        io::ResolveVerticalCorrection(vertical_correction, *dataset);
    options.Check();
    visual_options.lidar = options;
    tool.AddInput(poses_path);
    const Trajectory poses = io::ReadTrajectory(poses_path);
    const Trajectory keyframes = SelectKeyframes(poses, *dataset, every);
    JVL_CHECK(keyframes.size() >= 2,
              poses_path << ": fewer than 2 of its frames are in the dataset");
    // One cache of prepared scans for every detector: the later ones verify pairs near those
    // the earlier ones prepared.
    loop::LoopScanCache scans([&](int64_t f) { return dataset->LoadScan(f); },
                              dataset->calibration(), options, static_cast<size_t>(scan_cache));
    // The visual map's keypoints of a keyframe: rows [first, last) of keypoints/*.
    io::VisualMapData map;
    std::unordered_map<int64_t, std::pair<size_t, size_t>> rows;
    // The features of the keyframes the visual map lacks, extracted while the map is read.
    std::unordered_map<int64_t, vision::OrbFeatures> extracted_early;
    if (use_visual && !visual_path.empty()) {
      tool.AddInput(visual_path);
      const io::VisualMapData header = io::ReadVisualMapHeader(visual_path);
      JVL_CHECK(camera_option->count() == 0 || header.camera_choice.index == visual_options.camera,
                visual_path << " was built from camera " << header.camera_choice.index
                            << ", not --camera " << visual_options.camera);
      visual_options.camera = header.camera_choice.index;
      JVL_CHECK(std::abs(header.scale_factor - visual_options.orb.scale_factor) < 1e-9 &&
                    header.num_levels == visual_options.orb.num_levels,
                visual_path << ": ORB pyramid " << header.num_levels << " levels x "
                            << header.scale_factor << ", the visual detector uses "
                            << visual_options.orb.num_levels << " x "
                            << visual_options.orb.scale_factor);
      dataset->CheckCamera(visual_options.camera);
      std::vector<int64_t> missing, present;
      for (const int64_t f : keyframes.frames)
        (header.keyframes.IndexOf(f) ? present : missing).push_back(f);
      // A thread of its own reads the keypoints of the keyframes the map holds (only those rows:
      // HDF5 is read by one thread at a time) while the worker threads extract. A map that cannot
      // be read is reported after the extraction; an image that cannot be read first (the future's
      // destructor waits for the reader).
      std::vector<vision::OrbFeatures> features(missing.size());
      auto reading = std::async(std::launch::async,
                                [&] { return io::ReadVisualKeypoints(visual_path, present); });
      ParallelFor(static_cast<int64_t>(missing.size()), tool.threads(), [&](int64_t i) {
        features[static_cast<size_t>(i)] = vision::ExtractOrb(
            dataset->LoadImage(missing[static_cast<size_t>(i)], visual_options.camera),
            visual_options.orb);
      });
      map = reading.get();
      for (size_t i = 0; i < missing.size(); ++i)
        extracted_early.emplace(missing[i], std::move(features[i]));
      try {
        rows = mapping::KeypointRowsByFrame(map);
      } catch (const Error& e) {
        JVL_THROW(visual_path << ": " << e.what());
      }
    }
    // The camera is checked before any detector's work.
    if (use_visual) dataset->CheckCamera(visual_options.camera);
    // The detectors in turn: visual, LiDAR, proximity. A later one verifies only the queries
    // the ones before it left open (and the keyframes before them that its temporal
    // consistency needs) and returns only theirs, so a query gets at most one loop.
    std::vector<loop::LoopCandidate> candidates;
    std::vector<int64_t> closed;  // Queries a detector accepted, sorted.
    auto is_closed = [&](int64_t query) {
      return std::binary_search(closed.begin(), closed.end(), query);
    };
    auto take = [&](const loop::LoopResult& result) {
      for (const loop::LoopCandidate& c : result.candidates) {
        candidates.push_back(c);
        if (c.status == loop::LoopStatus::kAccepted) closed.push_back(c.query);
      }
      std::sort(closed.begin(), closed.end());
    };
    if (use_visual) {
      std::atomic<int64_t> extracted{0};
      auto features_of = [&](int64_t f) {
        const auto it = rows.find(f);
        if (it == rows.end()) {
          ++extracted;
          if (const auto early = extracted_early.find(f); early != extracted_early.end())
            return std::move(early->second);
          return vision::ExtractOrb(dataset->LoadImage(f, visual_options.camera),
                                    visual_options.orb);
        }
        return mapping::KeyframeFeatures(map, it->second.first, it->second.second);
      };
      Progress progress("visual keyframes", static_cast<int64_t>(keyframes.size()), !tool.quiet());
      take(loop::DetectVisualLoops(keyframes, features_of, scans, *vocabulary, visual_options,
                                   tool.threads(), [&] { progress.Tick(); }));
      if (!visual_path.empty())
        spdlog::info("visual detector: features of {} of {} keyframes from {}, {} extracted",
                     static_cast<int64_t>(keyframes.size()) - extracted.load(), keyframes.size(),
                     visual_path, extracted.load());
    }
    if (use_lidar) {
      Progress progress("LiDAR keyframes", static_cast<int64_t>(keyframes.size()), !tool.quiet());
      const size_t before = candidates.size();
      take(loop::DetectLidarLoops(keyframes, scans, options, tool.threads(), is_closed,
                                  [&] { progress.Tick(); }));
      spdlog::info("LiDAR detector: {} candidates verified", candidates.size() - before);
    }
    if (use_proximity) {
      const size_t before = candidates.size();
      take(loop::DetectProximityLoops(keyframes, scans, options, tool.threads(), is_closed));
      spdlog::info("proximity detector: {} candidates verified", candidates.size() - before);
    }
    // By query, in the detectors' order (stable).
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const loop::LoopCandidate& a, const loop::LoopCandidate& b) {
                       return a.query < b.query;
                     });
    io::LoopsData data;
    data.keyframes = keyframes.frames;
    if (use_visual)
      data.camera_choice = CameraChoice::Of(dataset->calibration(), visual_options.camera);
    int accepted = 0;
    for (const loop::LoopCandidate& c : candidates) {
      io::LoopRecord r;
      r.query = c.query;
      r.match = c.match;
      r.detector = c.detector == "visual" ? 1 : c.detector == "proximity" ? 2 : 0;
      r.status = static_cast<int32_t>(c.status);
      r.match_from_query = c.match_from_query;
      r.score = c.descriptor_distance;
      r.ring_key_distance = c.ring_key_distance;
      r.yaw_deg = c.yaw_rad * kRadToDeg;
      r.correspondences = c.correspondences;
      r.inliers = c.inliers;
      if (c.status == loop::LoopStatus::kAccepted) {
        for (const loop::LoopPoint& p : c.points)
          r.points.push_back({p.p_match, p.match_uv, p.query_uv, p.match_octave, p.query_octave});
      }
      r.residual = c.residual;
      data.loops.push_back(r);
      accepted += c.status == loop::LoopStatus::kAccepted ? 1 : 0;
    }
    io::WriteLoopsArtifact(output, data, tool.MakeProvenance());
    if (!csv.empty()) io::WriteLoopsCsv(csv, data);
    spdlog::info("loop_detect: {} keyframes, {} candidates verified, {} loops accepted -> {}",
                 data.keyframes.size(), data.loops.size(), accepted, output);
    if (!gt_path.empty()) {
      const Trajectory gt = io::ReadTrajectory(gt_path);
      nlohmann::json detectors_json = nlohmann::json::array();
      // The detectors in the order they ran; a later one verified only the queries left open.
      if (use_visual)
        detectors_json.push_back(
            ReportAgainstGroundTruth(gt, data, options.min_separation_m, 1, "visual"));
      if (use_lidar)
        detectors_json.push_back(ReportAgainstGroundTruth(
            gt, data, options.min_separation_m, 0, use_visual ? "LiDAR (after visual)" : "LiDAR"));
      if (use_proximity)
        detectors_json.push_back(ReportAgainstGroundTruth(
            gt, data, options.min_separation_m, 2,
            use_visual || use_lidar ? "proximity (after the others)" : "proximity"));
      if (use_lidar + use_visual + use_proximity > 1)
        detectors_json.push_back(
            ReportAgainstGroundTruth(gt, data, options.min_separation_m, -1, "combined"));
      if (!report.empty()) {
        const nlohmann::json body = {{"keyframes", data.keyframes.size()},
                                     {"candidates", data.loops.size()},
                                     {"accepted", accepted},
                                     {"detectors", detectors_json}};
        io::WriteTextFileAtomic(report, body.dump(1) + "\n");
      }
    }
  });
}
