#include "fidelity/edge_alignment.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <unordered_map>

#include "core/check.h"
#include "core/statistics.h"
#include "core/threads.h"
#include "geometry/angles.h"
#include "geometry/rigid3.h"

namespace jvl::fidelity {
namespace {

constexpr double kRadPerDeg = 1.0 / kDegPerRad;

Eigen::Matrix3d RotationOfDeg(const Eigen::Vector3d& deg) {
  return ExpSO3(deg * kRadPerDeg).toRotationMatrix();
}

// Offsets of a grid within +-half (inclusive) at `step`: -n*step .. n*step.
std::vector<double> GridOffsets(double half, double step) {
  const int n = static_cast<int>(std::floor(half / step + 1e-9));
  std::vector<double> v;
  for (int i = -n; i <= n; ++i) v.push_back(i * step);
  return v;
}

// Vertex of the parabola through (-1, a), (0, b), (1, c), within [-0.5, 0.5] steps; 0 when
// b is not a maximum of the three.
double ParabolaPeak(double a, double b, double c) {
  const double curvature = a - 2 * b + c;
  if (!(curvature < 0)) return 0.0;
  return std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
}

// Grid point g of a cubic grid with n points per axis as its index per axis (x, y, z): g =
// (i * n + j) * n + k.
std::array<size_t, 3> GridIndex(size_t g, size_t n) { return {g / (n * n), (g / n) % n, g % n}; }

// Whether grid point g lies on the grid's border along some axis.
bool OnGridBorder(size_t g, size_t n) {
  for (const size_t i : GridIndex(g, n))
    if (i == 0 || i + 1 == n) return true;
  return false;
}

// The best of a cubic grid of scores (index = (i * n + j) * n + k over the axes x, y, z) with
// the per-axis parabola refinement, as offsets from the grid centre (in the grid's units).
Eigen::Vector3d GridPeak(const std::vector<double>& scores, const std::vector<double>& offsets,
                         double step, size_t* best_index = nullptr) {
  const size_t n = offsets.size();
  size_t best = 0;
  for (size_t g = 1; g < scores.size(); ++g)
    if (scores[g] > scores[best]) best = g;  // Ties: the lowest index (deterministic).
  if (best_index) *best_index = best;
  const std::array<size_t, 3> idx = GridIndex(best, n);
  Eigen::Vector3d peak;
  for (int axis = 0; axis < 3; ++axis) {
    double sub = 0.0;
    if (idx[axis] > 0 && idx[axis] + 1 < n) {
      std::array<size_t, 3> lo = idx, hi = idx;
      --lo[axis];
      ++hi[axis];
      auto at = [&](const std::array<size_t, 3>& i) {
        return scores[(i[0] * n + i[1]) * n + i[2]];
      };
      sub = ParabolaPeak(at(lo), scores[best], at(hi));
    }
    peak[axis] = offsets[idx[axis]] + sub * step;
  }
  return peak;
}

}  // namespace

void EdgeAlignmentOptions::Check() const {
  JVL_CHECK(ring_elevation_deg > 0 && ring_azimuth_deg > 0,
            "ring_elevation_deg and ring_azimuth_deg must be > 0");
  JVL_CHECK(min_discontinuity_m > 0 && max_discontinuity_m >= min_discontinuity_m,
            "min_discontinuity_m must be > 0 and <= max_discontinuity_m (got "
                << min_discontinuity_m << ", " << max_discontinuity_m << ")");
  JVL_CHECK(min_depth_m > 0 && max_depth_m > min_depth_m,
            "min_depth_m must be > 0 and < max_depth_m (got " << min_depth_m << ", " << max_depth_m
                                                              << ")");
  JVL_CHECK(edge_saturation > 0, "edge_saturation must be > 0 (got " << edge_saturation << ")");
  JVL_CHECK(edge_decay > 0 && edge_decay < 1,
            "edge_decay must be in (0, 1) (got " << edge_decay << ")");
  JVL_CHECK(edge_mix >= 0 && edge_mix <= 1, "edge_mix must be in [0, 1] (got " << edge_mix << ")");
  JVL_CHECK(background_sigma_px > 0,
            "background_sigma_px must be > 0 (got " << background_sigma_px << ")");
  JVL_CHECK(ring_spacing_deg > ring_elevation_deg,
            "ring_spacing_deg must be > ring_elevation_deg (got " << ring_spacing_deg << ")");
  JVL_CHECK(fine_step_deg > 0 && fine_step_deg <= coarse_step_deg,
            "fine_step_deg must be > 0 and <= coarse_step_deg (got " << fine_step_deg << ", "
                                                                     << coarse_step_deg << ")");
  JVL_CHECK(coarse_step_deg <= search_deg && search_deg <= 10,
            "search_deg must be within [coarse_step_deg, 10] (got " << search_deg << ")");
  // Grid sizes: (2 search / coarse + 1)^3 and (2 coarse / fine + 1)^3 rotations.
  JVL_CHECK(search_deg / coarse_step_deg <= 50 && coarse_step_deg / fine_step_deg <= 25,
            "search_deg / coarse_step_deg must be <= 50 and coarse_step_deg / fine_step_deg <= 25 "
            "(got "
                << search_deg / coarse_step_deg << " and " << coarse_step_deg / fine_step_deg
                << ")");
  JVL_CHECK(bootstrap >= 0, "bootstrap must be >= 0 (got " << bootstrap << ")");
  JVL_CHECK(min_edge_points >= 1, "min_edge_points must be >= 1 (got " << min_edge_points << ")");
}

DepthEdges FindDepthEdges(const PointCloud& scan, const EdgeAlignmentOptions& o) {
  const size_t n = scan.size();
  std::vector<double> range(n), azimuth(n), elevation(n);
  // Cells of ring_elevation x ring_azimuth: a return's ring neighbours are in its own and the
  // 8 cells around it.
  std::unordered_map<int64_t, std::vector<int>> cells;
  auto key = [](int64_t e, int64_t a) { return e * 100000 + a; };
  // Azimuth cells wrap round at +-180 deg, as do the gaps between azimuths.
  const int64_t ring_cells = static_cast<int64_t>(std::ceil(360.0 / o.ring_azimuth_deg));
  const int64_t column_cells = static_cast<int64_t>(std::ceil(720.0 / o.ring_azimuth_deg));
  auto wrap_cell = [](int64_t a, int64_t cells) { return ((a % cells) + cells) % cells; };
  auto wrap_gap = [](double gap) { return gap > 180 ? gap - 360 : gap < -180 ? gap + 360 : gap; };
  std::vector<int64_t> ce(n), ca(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = scan.points[i];
    range[i] = p.norm();
    if (!(range[i] > 0.5) || !std::isfinite(range[i])) {
      range[i] = -1;
      continue;
    }
    azimuth[i] = std::atan2(p.y(), p.x()) * kDegPerRad;
    elevation[i] = std::atan2(p.z(), std::hypot(p.x(), p.y())) * kDegPerRad;
    ce[i] = static_cast<int64_t>(std::floor(elevation[i] / o.ring_elevation_deg));
    ca[i] = wrap_cell(static_cast<int64_t>(std::floor((azimuth[i] + 180.0) / o.ring_azimuth_deg)),
                      ring_cells);
    cells[key(ce[i], ca[i])].push_back(static_cast<int>(i));
  }
  // Cells of ring_spacing x ring_azimuth / 2 for the neighbours on the rings above and below.
  std::unordered_map<int64_t, std::vector<int>> columns;
  const double column_azimuth = 0.5 * o.ring_azimuth_deg;
  std::vector<int64_t> ve(n), va(n);
  for (size_t i = 0; i < n; ++i) {
    if (range[i] < 0) continue;
    ve[i] = static_cast<int64_t>(std::floor(elevation[i] / o.ring_spacing_deg));
    va[i] = wrap_cell(static_cast<int64_t>(std::floor((azimuth[i] + 180.0) / column_azimuth)),
                      column_cells);
    columns[key(ve[i], va[i])].push_back(static_cast<int>(i));
  }
  DepthEdges edges;
  for (size_t i = 0; i < n; ++i) {
    if (range[i] < 0) continue;
    // The nearest return on the same ring to the left and to the right (in azimuth) ...
    int left = -1, right = -1;
    double left_gap = o.ring_azimuth_deg, right_gap = o.ring_azimuth_deg;
    for (int64_t de = -1; de <= 1; ++de) {
      for (int64_t da = -1; da <= 1; ++da) {
        const auto it = cells.find(key(ce[i] + de, wrap_cell(ca[i] + da, ring_cells)));
        if (it == cells.end()) continue;
        for (const int j : it->second) {
          if (static_cast<size_t>(j) == i) continue;
          if (std::abs(elevation[j] - elevation[i]) >= o.ring_elevation_deg) continue;
          const double gap = wrap_gap(azimuth[j] - azimuth[i]);
          if (gap > 0 && (gap < right_gap || (gap == right_gap && j < right))) {
            right_gap = gap;
            right = j;
          } else if (gap < 0 && (-gap < left_gap || (-gap == left_gap && j < left))) {
            left_gap = -gap;
            left = j;
          }
        }
      }
    }
    // ... and on the rings above and below (the nearest in elevation, then in azimuth).
    int up = -1, down = -1;
    double up_gap = 2 * o.ring_spacing_deg, down_gap = 2 * o.ring_spacing_deg;
    for (int64_t de = -1; de <= 1; ++de) {
      for (int64_t da = -1; da <= 1; ++da) {
        const auto it = columns.find(key(ve[i] + de, wrap_cell(va[i] + da, column_cells)));
        if (it == columns.end()) continue;
        for (const int j : it->second) {
          const double rise = elevation[j] - elevation[i];
          if (std::abs(rise) <= o.ring_elevation_deg || std::abs(rise) >= o.ring_spacing_deg)
            continue;
          const double across = std::abs(wrap_gap(azimuth[j] - azimuth[i]));
          if (across >= column_azimuth) continue;
          const double gap = std::abs(rise) + across;  // Nearer ring first, then nearer column.
          if (rise > 0 && (gap < up_gap || (gap == up_gap && j < up))) {
            up_gap = gap;
            up = j;
          } else if (rise < 0 && (gap < down_gap || (gap == down_gap && j < down))) {
            down_gap = gap;
            down = j;
          }
        }
      }
    }
    // An occluding edge between i's two neighbours a and b: one much farther, the other at
    // about the same range (a surface seen at a grazing angle, or the road between two rings,
    // has both differences alike: a range gradient, not an edge). The jump, or 0.
    auto jump_between = [&](int a, int b, int* far) {
      if (a < 0 || b < 0) return 0.0;
      const double da = range[a] - range[i], db = range[b] - range[i];
      const double jump = std::max(da, db), other = std::abs(da > db ? db : da);
      *far = da > db ? a : b;
      return jump >= o.min_discontinuity_m && jump - 2.0 * other >= 0.5 * jump ? jump : 0.0;
    };
    int far_across = -1, far_along = -1;
    const double across = jump_between(left, right, &far_across);
    double along = jump_between(up, down, &far_along);
    // A horizontal outline seen from above (its far neighbour above it, the return below the
    // sensor's horizontal plane) may be the far edge of a top surface (a car's roof, a low
    // wall): the return lies on that surface, nearer than the outline by up to a ring's
    // footprint, and the camera, ahead of and below the LiDAR, sees it shifted by parallax
    // (about 0.2 deg at 10 m for 0.7 m). Likewise a bottom outline seen from below. Only
    // outlines seen edge-on are used.
    if (along > 0 && (elevation[far_along] > elevation[i]) != (elevation[i] >= 0)) along = 0;
    const double jump = std::max(across, along);
    if (jump <= 0) continue;
    // The outline lies somewhere between this return's ray and its far neighbour's: on average
    // half way. (The return itself lies inside the outline, by up to a ring spacing at the top
    // of a wall: it would pull the alignment down.)
    const int far = across >= along ? far_across : far_along;
    const Eigen::Vector3d mid =
        scan.points[i] / range[i] + scan.points[static_cast<size_t>(far)] / range[far];
    edges.points.push_back(range[i] * mid.normalized());
    edges.weights.push_back(std::sqrt(std::min(jump, o.max_discontinuity_m)));
    edges.horizontal.push_back(across >= along ? 0 : 1);
  }
  return edges;
}

namespace {

// One direction's field from its gradient (along rows when `rows`, else along columns).
cv::Mat DirectionalField(const cv::Mat& gradient, bool rows, const EdgeAlignmentOptions& o) {
  cv::Mat e = cv::abs(gradient);
  e = e / (e + o.edge_saturation);
  // D: the decayed maximum along the direction, one pass each way.
  cv::Mat d = e.clone();
  const float decay = static_cast<float>(o.edge_decay);
  const int lines = rows ? d.rows : d.cols, length = rows ? d.cols : d.rows;
  auto at = [&](int line, int k) -> float& {
    return rows ? d.at<float>(line, k) : d.at<float>(k, line);
  };
  for (int line = 0; line < lines; ++line) {
    for (int k = 1; k < length; ++k) at(line, k) = std::max(at(line, k), decay * at(line, k - 1));
    for (int k = length - 2; k >= 0; --k)
      at(line, k) = std::max(at(line, k), decay * at(line, k + 1));
  }
  cv::Mat field, background;
  cv::addWeighted(e, o.edge_mix, d, 1.0 - o.edge_mix, 0.0, field);
  const int k = 2 * static_cast<int>(std::ceil(3 * o.background_sigma_px)) + 1;
  if (rows) {
    cv::GaussianBlur(field, background, cv::Size(k, 1), o.background_sigma_px, 0,
                     cv::BORDER_REPLICATE);
  } else {
    cv::GaussianBlur(field, background, cv::Size(1, k), 0, o.background_sigma_px,
                     cv::BORDER_REPLICATE);
  }
  return field - background;
}

}  // namespace

EdgeFields EdgeField(const cv::Mat& image, const EdgeAlignmentOptions& o) {
  JVL_CHECK(!image.empty(), "edge field of an empty image");
  JVL_CHECK(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
            "edge field: an 8-bit grey or colour image is needed (got depth "
                << image.depth() << ", " << image.channels() << " channels)");
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  cv::Mat smooth, gu, gv;
  grey.convertTo(smooth, CV_32F);
  cv::GaussianBlur(smooth, smooth, cv::Size(5, 5), 1.0, 1.0, cv::BORDER_REPLICATE);
  cv::Sobel(smooth, gu, CV_32F, 1, 0, 3, 1.0 / 8.0, 0, cv::BORDER_REPLICATE);
  cv::Sobel(smooth, gv, CV_32F, 0, 1, 3, 1.0 / 8.0, 0, cv::BORDER_REPLICATE);
  return {DirectionalField(gu, true, o), DirectionalField(gv, false, o)};
}

AlignmentFrame MakeAlignmentFrame(const PointCloud& scan, const cv::Mat& image,
                                  const Calibration& calibration, int camera,
                                  const EdgeAlignmentOptions& o) {
  AlignmentFrame frame;
  frame.fields = EdgeField(image, o);
  const int cols = frame.fields.across_u.cols, rows = frame.fields.across_u.rows;
  const PinholeCamera cam = calibration.Camera(camera);
  const Eigen::Vector3d offset = calibration.CameraOffset(camera);
  const DepthEdges edges = FindDepthEdges(scan, o);
  for (size_t i = 0; i < edges.points.size(); ++i) {
    const Eigen::Vector3d q = calibration.cam0_from_velo * edges.points[i];
    if (q.z() < o.min_depth_m || q.z() > o.max_depth_m) continue;
    const Eigen::Vector2d uv = cam.Project(q + offset);
    if (uv.x() < 0 || uv.y() < 0 || uv.x() > cols - 1 || uv.y() > rows - 1) continue;
    frame.points.push_back(q);
    frame.weights.push_back(edges.weights[i]);
    frame.horizontal.push_back(edges.horizontal[i]);
  }
  return frame;
}

double FrameScore(const AlignmentFrame& frame, const Eigen::Matrix3d& rotation,
                  const PinholeCamera& camera, const Eigen::Vector3d& camera_offset) {
  const int cols = frame.fields.across_u.cols, rows = frame.fields.across_u.rows;
  // Bilinear value of f at the projection of x, or NaN outside the image.
  auto sample = [&](const cv::Mat& f, const Eigen::Vector3d& x) {
    if (x.z() <= 0) return std::numeric_limits<double>::quiet_NaN();
    const Eigen::Vector2d uv = camera.Project(x);
    const double u = uv.x(), v = uv.y();
    if (!(u >= 0 && v >= 0 && u < cols - 1 && v < rows - 1))
      return std::numeric_limits<double>::quiet_NaN();
    const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
    const double a = u - u0, b = v - v0;
    const float* r0 = f.ptr<float>(v0);
    const float* r1 = f.ptr<float>(v0 + 1);
    return (1 - b) * ((1 - a) * r0[u0] + a * r0[u0 + 1]) + b * ((1 - a) * r1[u0] + a * r1[u0 + 1]);
  };
  double score = 0;
  for (size_t i = 0; i < frame.points.size(); ++i) {
    const double value = sample(frame.horizontal[i] ? frame.fields.across_v : frame.fields.across_u,
                                rotation * frame.points[i] + camera_offset);
    if (!std::isnan(value)) score += frame.weights[i] * value;
  }
  return score;
}

EdgeAlignmentResult AlignEdges(const std::vector<AlignmentFrame>& frames,
                               const PinholeCamera& camera, const Eigen::Vector3d& camera_offset,
                               const EdgeAlignmentOptions& o, int threads) {
  o.Check();
  JVL_CHECK(!frames.empty(), "edge alignment needs at least one frame");
  EdgeAlignmentResult result;
  result.frames = static_cast<int>(frames.size());
  for (const AlignmentFrame& f : frames)
    result.edge_points += static_cast<int64_t>(f.points.size());
  JVL_CHECK(result.edge_points >= o.min_edge_points,
            "only " << result.edge_points << " LiDAR depth edges fall into the images at depths "
                    << o.min_depth_m << "-" << o.max_depth_m << " m (min_edge_points: "
                    << o.min_edge_points << "): too few to measure the calibration by");
  const size_t nf = frames.size();
  // Scores of every frame at every rotation of a cubic grid around `centre` (deg).
  auto score_grid = [&](const Eigen::Vector3d& centre, const std::vector<double>& offsets) {
    const size_t n = offsets.size();
    std::vector<double> per_frame(n * n * n * nf);
    ParallelFor(static_cast<int64_t>(n * n * n), threads, [&](int64_t g) {
      const size_t gi = static_cast<size_t>(g);
      const std::array<size_t, 3> idx = GridIndex(gi, n);
      const Eigen::Vector3d deg =
          centre + Eigen::Vector3d(offsets[idx[0]], offsets[idx[1]], offsets[idx[2]]);
      const Eigen::Matrix3d r = RotationOfDeg(deg);
      for (size_t f = 0; f < nf; ++f)
        per_frame[gi * nf + f] = FrameScore(frames[f], r, camera, camera_offset);
    });
    return per_frame;
  };
  auto totals = [&](const std::vector<double>& per_frame, const std::vector<int>& counts) {
    std::vector<double> t(per_frame.size() / nf, 0.0);
    for (size_t g = 0; g < t.size(); ++g)
      for (size_t f = 0; f < nf; ++f) t[g] += counts[f] * per_frame[g * nf + f];
    return t;
  };
  const std::vector<int> all(nf, 1);

  const std::vector<double> coarse = GridOffsets(o.search_deg, o.coarse_step_deg);
  size_t coarse_best = 0;
  const std::vector<double> coarse_totals =
      totals(score_grid(Eigen::Vector3d::Zero(), coarse), all);
  GridPeak(coarse_totals, coarse, o.coarse_step_deg, &coarse_best);
  {
    // The score along each axis through calib.txt's extrinsic, relative to it (debug log).
    const size_t n = coarse.size(), c = n / 2;
    const double at_zero = coarse_totals[(c * n + c) * n + c];
    const char* names[3] = {"pitch", "yaw", "roll"};
    for (int axis = 0; axis < 3 && at_zero != 0; ++axis) {
      std::string line;
      for (size_t i = 0; i < n; ++i) {
        std::array<size_t, 3> idx = {c, c, c};
        idx[axis] = i;
        line += fmt::format(
            " {:+.1f}",
            100.0 * (coarse_totals[(idx[0] * n + idx[1]) * n + idx[2]] / at_zero - 1.0));
      }
      spdlog::debug("edge score along {} ({:+.2f} .. {:+.2f} deg, % of calib.txt's):{}",
                    names[axis], coarse.front(), coarse.back(), line);
    }
  }
  result.at_search_limit = OnGridBorder(coarse_best, coarse.size());
  const std::array<size_t, 3> coarse_idx = GridIndex(coarse_best, coarse.size());
  const Eigen::Vector3d coarse_centre(coarse[coarse_idx[0]], coarse[coarse_idx[1]],
                                      coarse[coarse_idx[2]]);
  // The fine grid within one coarse step of the best coarse rotation; while its best lies on
  // its border (the coarse grid can miss a peak narrower than its step), moved there.
  const std::vector<double> fine = GridOffsets(o.coarse_step_deg, o.fine_step_deg);
  const size_t nfine = fine.size();
  Eigen::Vector3d centre = coarse_centre;
  std::vector<double> fine_scores;
  for (int move = 0;; ++move) {
    fine_scores = score_grid(centre, fine);
    size_t best = 0;
    const Eigen::Vector3d peak = GridPeak(totals(fine_scores, all), fine, o.fine_step_deg, &best);
    const std::array<size_t, 3> idx = GridIndex(best, nfine);
    const bool border = OnGridBorder(best, nfine);
    const Eigen::Vector3d moved =
        centre + Eigen::Vector3d(fine[idx[0]], fine[idx[1]], fine[idx[2]]);
    if (!border || move == 5 || moved.cwiseAbs().maxCoeff() > o.search_deg + 1e-9) {
      result.correction_deg = centre + peak;
      result.at_search_limit |= border;  // Still on the border: not a maximum found.
      break;
    }
    centre = moved;
  }

  // Bootstrap over the frames on the fine grid.
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<size_t> pick(0, nf - 1);
  std::vector<double> samples[3];
  for (int b = 0; b < o.bootstrap; ++b) {
    std::vector<int> counts(nf, 0);
    for (size_t k = 0; k < nf; ++k) ++counts[pick(rng)];
    size_t best = 0;
    const Eigen::Vector3d c =
        centre + GridPeak(totals(fine_scores, counts), fine, o.fine_step_deg, &best);
    for (int a = 0; a < 3; ++a) samples[a].push_back(c[a]);
    result.bootstrap_at_border += OnGridBorder(best, nfine) ? 1 : 0;
  }
  for (int a = 0; a < 3; ++a) {
    if (samples[a].empty()) continue;
    double mean = 0, var = 0;
    for (double s : samples[a]) mean += s;
    mean /= static_cast<double>(samples[a].size());
    for (double s : samples[a]) var += (s - mean) * (s - mean);
    result.bootstrap_std_deg[a] = std::sqrt(var / static_cast<double>(samples[a].size()));
    result.bootstrap_p05_deg[a] = Quantile(samples[a], 0.05);
    result.bootstrap_p95_deg[a] = Quantile(samples[a], 0.95);
  }

  const Eigen::Matrix3d best = RotationOfDeg(result.correction_deg);
  double weight = 0;
  for (const AlignmentFrame& f : frames)
    for (double w : f.weights) weight += w;
  result.frame_score_calibration.resize(nf);
  result.frame_score_corrected.resize(nf);
  for (size_t f = 0; f < nf; ++f) {
    result.frame_score_calibration[f] =
        FrameScore(frames[f], Eigen::Matrix3d::Identity(), camera, camera_offset);
    result.frame_score_corrected[f] = FrameScore(frames[f], best, camera, camera_offset);
    result.score_calibration += result.frame_score_calibration[f];
    result.score_corrected += result.frame_score_corrected[f];
  }
  result.score_calibration /= weight;
  result.score_corrected /= weight;
  return result;
}

namespace {

nlohmann::json RotationJson(const Eigen::Vector3d& v) {
  return nlohmann::json{{"pitch_x", v.x()}, {"yaw_y", v.y()}, {"roll_z", v.z()}};
}

}  // namespace

nlohmann::json EdgeAlignmentJson(const EdgeAlignmentResult& r, const EdgeAlignmentOptions& o) {
  nlohmann::json body;
  body["edge_points"] = r.edge_points;
  body["correction_deg"] = RotationJson(r.correction_deg);
  body["calibration_error_deg"] = RotationJson(-r.correction_deg);
  body["correction_angle_deg"] = r.correction_deg.norm();
  body["bootstrap"] = {{"resamples", o.bootstrap},
                       {"at_border", r.bootstrap_at_border},
                       {"std_deg", RotationJson(r.bootstrap_std_deg)},
                       {"p05_deg", RotationJson(r.bootstrap_p05_deg)},
                       {"p95_deg", RotationJson(r.bootstrap_p95_deg)}};
  body["at_search_limit"] = r.at_search_limit;
  body["score_calibration"] = r.score_calibration;
  body["score_corrected"] = r.score_corrected;
  body["frame_score_calibration"] = r.frame_score_calibration;
  body["frame_score_corrected"] = r.frame_score_corrected;
  int better = 0;
  for (size_t f = 0; f < r.frame_score_corrected.size(); ++f)
    better += r.frame_score_corrected[f] > r.frame_score_calibration[f] ? 1 : 0;
  body["frames_better"] = better;
  return body;
}

Calibration CorrectedCalibration(const Calibration& calibration,
                                 const Eigen::Vector3d& correction_deg) {
  Calibration c = calibration;
  c.cam0_from_velo = Rigid3d(ExpSO3(correction_deg * kRadPerDeg), Eigen::Vector3d::Zero()) *
                     calibration.cam0_from_velo;
  return c;
}

}  // namespace jvl::fidelity
