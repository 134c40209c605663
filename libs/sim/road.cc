#include "sim/road.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "sim/random.h"

namespace jvl::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

RoadPiece Straight(double length, double speed, bool open = false) {
  RoadPiece p;
  p.length = length;
  p.speed = speed;
  p.open = open;
  return p;
}

// A turn of `angle_deg` (left positive) with the given radius.
RoadPiece Turn(double angle_deg, double radius, double speed) {
  RoadPiece p;
  p.length = std::abs(angle_deg) * kPi / 180.0 * radius;
  p.curvature = (angle_deg > 0 ? 1.0 : -1.0) / radius;
  p.speed = speed;
  return p;
}

RoadPoint PieceAt(const RoadPiece& p, int index, double ds) {
  RoadPoint r;
  r.piece = index;
  r.curvature = p.curvature;
  const double h0 = p.start_heading;
  if (p.IsStraight()) {
    r.position = p.start + ds * Eigen::Vector2d(std::cos(h0), std::sin(h0));
    r.heading = h0;
  } else {
    const double k = p.curvature;
    r.heading = h0 + k * ds;
    r.position = p.start + Eigen::Vector2d((std::sin(r.heading) - std::sin(h0)) / k,
                                           (std::cos(h0) - std::cos(r.heading)) / k);
  }
  return r;
}

}  // namespace

Route::Route(std::vector<RoadPiece> pieces, const Eigen::Vector2d& start, double heading)
    : pieces_(std::move(pieces)) {
  JVL_CHECK(!pieces_.empty(), "route has no pieces");
  Eigen::Vector2d p = start;
  double h = heading;
  for (size_t i = 0; i < pieces_.size(); ++i) {
    RoadPiece& piece = pieces_[i];
    JVL_CHECK(piece.length > 0, "route piece " << i << " has length " << piece.length);
    piece.start = p;
    piece.start_heading = h;
    piece.s0 = length_;
    const RoadPoint end = PieceAt(piece, static_cast<int>(i), piece.length);
    Cache c;
    c.dir = Eigen::Vector2d(std::cos(h), std::sin(h));
    if (!piece.IsStraight()) {
      c.centre = piece.start + Eigen::Vector2d(-c.dir.y(), c.dir.x()) / piece.curvature;
      c.radius = 1.0 / std::abs(piece.curvature);
    }
    c.end = end.position;
    c.end_heading = end.heading;
    c.mid = PieceAt(piece, static_cast<int>(i), piece.length / 2).position;
    cache_.push_back(c);
    p = end.position;
    h = end.heading;
    length_ += piece.length;
    piece_ends_.push_back(length_);
    if (!piece.repeat) all_pieces_.push_back(static_cast<int>(i));
  }
  JVL_CHECK(!all_pieces_.empty(), "route has only repeated pieces");
  size_t first = 0, last = pieces_.size();
  while (first < last && pieces_[first].lead) ++first;
  while (last > first && pieces_[last - 1].lead) --last;
  JVL_CHECK(first < last, "route has only lead pieces");
  for (size_t i = first; i < last; ++i) {
    JVL_CHECK(!pieces_[i].lead, "route piece " << i << " is a lead piece between driven ones");
  }
  drive_begin_ = pieces_[first].s0;
  drive_end_ = pieces_[last - 1].s0 + pieces_[last - 1].length;
  // Grid index for Project(): a cell lists the pieces whose bounding circle comes within
  // kIndexReach of some point of the cell.
  const double half_diagonal = kIndexCell * std::sqrt(0.5);
  for (size_t i = 0; i < pieces_.size(); ++i) {
    if (pieces_[i].repeat) continue;
    const double reach = pieces_[i].length / 2 + kIndexReach + half_diagonal;
    const Eigen::Vector2d& mid = cache_[i].mid;
    const int64_t x0 = CellIndex(mid.x() - reach), x1 = CellIndex(mid.x() + reach);
    const int64_t y0 = CellIndex(mid.y() - reach), y1 = CellIndex(mid.y() + reach);
    for (int64_t x = x0; x <= x1; ++x) {
      for (int64_t y = y0; y <= y1; ++y) {
        const Eigen::Vector2d centre((static_cast<double>(x) + 0.5) * kIndexCell,
                                     (static_cast<double>(y) + 0.5) * kIndexCell);
        if ((centre - mid).norm() <= reach) index_[CellKey(x, y)].push_back(static_cast<int>(i));
      }
    }
  }
}

int64_t Route::CellIndex(double v) { return static_cast<int64_t>(std::floor(v / kIndexCell)); }

uint64_t Route::CellKey(int64_t x, int64_t y) {
  return (static_cast<uint64_t>(x) << 32) ^ (static_cast<uint64_t>(y) & 0xffffffffULL);
}

uint64_t Route::CellKey(const Eigen::Vector2d& p) {
  return CellKey(CellIndex(p.x()), CellIndex(p.y()));
}

RoadPoint Route::At(double s) const {
  s = std::clamp(s, 0.0, length_);
  const size_t i = PieceIndex(s);
  return PieceAt(pieces_[i], static_cast<int>(i), s - pieces_[i].s0);
}

size_t Route::PieceIndex(double s) const {
  // The first piece whose end is at or beyond s (the earlier piece at a shared end).
  const auto it = std::lower_bound(piece_ends_.begin(), piece_ends_.end(), s);
  return std::min(static_cast<size_t>(it - piece_ends_.begin()), pieces_.size() - 1);
}

std::pair<size_t, size_t> Route::PiecesStartingIn(double lo, double hi) const {
  const auto starts_after = [](const RoadPiece& piece, double v) { return piece.s0 <= v; };
  const auto first = std::lower_bound(pieces_.begin(), pieces_.end(), lo, starts_after);
  const auto last = std::lower_bound(first, pieces_.end(), hi,
                                     [](const RoadPiece& piece, double v) { return piece.s0 < v; });
  return {static_cast<size_t>(first - pieces_.begin()),
          static_cast<size_t>(last - pieces_.begin())};
}

void Route::Project(const Eigen::Vector2d& p, double* s, double* lateral) const {
  // The pieces of p's grid cell hold every piece within kIndexReach of p; when the nearest of
  // them is that close, no other piece can be nearer (the full loop would give the same result,
  // ties included: both visit the pieces in route order).
  const auto cell = index_.find(CellKey(p));
  if (cell != index_.end()) {
    ProjectOnto(p, cell->second, s, lateral);
    if (std::abs(*lateral) <= kIndexReach) return;
  }
  ProjectOnto(p, all_pieces_, s, lateral);
}

void Route::ProjectOnto(const Eigen::Vector2d& p, const std::vector<int>& candidates, double* s,
                        double* lateral) const {
  double best = std::numeric_limits<double>::infinity();
  *s = 0;
  *lateral = best;
  for (const int i : candidates) {
    const RoadPiece& piece = pieces_[i];
    const Cache& c = cache_[i];
    // Every point of the piece lies within length/2 of its mid point.
    const double bound = std::max(0.0, (p - c.mid).norm() - piece.length / 2);
    if (bound * bound >= best) continue;
    double ds, lat;
    bool inside;
    if (piece.IsStraight()) {
      const Eigen::Vector2d d = p - piece.start;
      ds = d.dot(c.dir);
      lat = c.dir.x() * d.y() - c.dir.y() * d.x();
      inside = ds >= 0 && ds <= piece.length;
    } else {
      // p - centre = (1/k)(sin h, -cos h) scaled: recover the heading h of the nearest point.
      const double k = piece.curvature;
      const Eigen::Vector2d r = (p - c.centre) * (k > 0 ? 1.0 : -1.0);
      ds = std::remainder(std::atan2(r.x(), -r.y()) - piece.start_heading, 2 * kPi) / k;
      lat = (k > 0 ? 1.0 : -1.0) * (c.radius - r.norm());
      inside = ds >= 0 && ds <= piece.length;
    }
    if (inside) {
      if (lat * lat < best) {
        best = lat * lat;
        *s = piece.s0 + ds;
        *lateral = lat;
      }
      continue;
    }
    // Off the piece: the nearer of its two ends.
    const double d0 = (p - piece.start).squaredNorm(), d1 = (p - c.end).squaredNorm();
    const bool at_end = d1 < d0;
    const double dist2 = at_end ? d1 : d0;
    if (dist2 < best) {
      best = dist2;
      *s = piece.s0 + (at_end ? piece.length : 0.0);
      const double h = at_end ? c.end_heading : piece.start_heading;
      const Eigen::Vector2d d = p - (at_end ? c.end : piece.start);
      const double cross = std::cos(h) * d.y() - std::sin(h) * d.x();
      *lateral = (cross >= 0 ? 1.0 : -1.0) * std::sqrt(dist2);
    }
  }
}

double Route::Distance(const Eigen::Vector2d& p) const {
  double s, lateral;
  Project(p, &s, &lateral);
  return std::abs(lateral);
}

double Terrain::Height(double x, double y) const {
  const double u[3] = {x, y, (x + y) * 0.7071};
  double h = 0;
  for (int i = 0; i < 3; ++i)
    h += amplitude[i] * std::sin(2 * kPi * u[i] / wavelength[i] + phase[i]);
  return h;
}

Eigen::Vector2d Terrain::Gradient(double x, double y) const {
  const double u[3] = {x, y, (x + y) * 0.7071};
  const Eigen::Vector2d du[3] = {{1, 0}, {0, 1}, {0.7071, 0.7071}};
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  for (int i = 0; i < 3; ++i) {
    const double w = 2 * kPi / wavelength[i];
    g += amplitude[i] * w * std::cos(w * u[i] + phase[i]) * du[i];
  }
  return g;
}

Scenario ParseScenario(const std::string& name) {
  if (name == "urban") return Scenario::kUrban;
  if (name == "suburban") return Scenario::kSuburban;
  if (name == "highway") return Scenario::kHighway;
  if (name == "straight") return Scenario::kStraight;
  if (name == "loop") return Scenario::kLoop;
  if (name == "figure8") return Scenario::kFigureEight;
  JVL_THROW(
      "unknown scenario '" << name
                           << "' (expected urban, suburban, highway, straight, loop or figure8)");
}

std::string ToString(Scenario scenario) {
  switch (scenario) {
    case Scenario::kUrban:
      return "urban";
    case Scenario::kSuburban:
      return "suburban";
    case Scenario::kHighway:
      return "highway";
    case Scenario::kStraight:
      return "straight";
    case Scenario::kLoop:
      return "loop";
    case Scenario::kFigureEight:
      return "figure8";
  }
  return "?";
}

bool IsUrbanLike(Scenario scenario) {
  return scenario == Scenario::kUrban || scenario == Scenario::kLoop ||
         scenario == Scenario::kFigureEight;
}

bool IsHighwayLike(Scenario scenario) {
  return scenario == Scenario::kHighway || scenario == Scenario::kStraight;
}

namespace {

std::vector<RoadPiece> ScenarioLap(Scenario scenario) {
  switch (scenario) {
    case Scenario::kUrban:
      // ~471 m: two long straights, three 90-degree corners, one gentle bend, an open stretch.
      return {Straight(130, 10.5),      Turn(90, 12, 5.0), Straight(110, 11.0), Turn(-30, 150, 9.0),
              Straight(55, 11.5, true), Turn(90, 12, 5.0), Straight(60, 10.0)};
    case Scenario::kSuburban:
      return {Straight(120, 10.0),      Turn(-90, 15, 5.5), Straight(140, 11.0), Turn(45, 60, 8.0),
              Straight(70, 11.0, true), Turn(-90, 15, 5.5), Straight(60, 10.0)};
    case Scenario::kHighway:
      return {Straight(320, 20.0), Turn(20, 600, 20.0), Straight(300, 21.0, true),
              Turn(-15, 700, 20.0), Straight(200, 20.0)};
    case Scenario::kStraight:
      return {Straight(1200, 20.5)};
    case Scenario::kLoop:
    case Scenario::kFigureEight:
      break;  // LoopRoute(), FigureEightRoute().
  }
  return {};
}

RoadPiece Repeat(RoadPiece p) {
  p.repeat = true;
  return p;
}

// kLoop: street A (east) to the block's south-west corner J, `laps` counter-clockwise circuits
// of the block (W x H between centre lines, corners of radius R), back along A (west). The first
// circuit passes J straight on from A; later ones turn left at J; the way back turns right at J.
std::vector<RoadPiece> LoopRoute(int laps) {
  constexpr double kA = 150, kW = 130, kH = 110, kR = 12;
  const RoadPiece corner = Turn(90, kR, 5.0);
  std::vector<RoadPiece> p = {Straight(kA, 10.5),
                              Straight(kW - kR, 11.0),
                              corner,
                              Straight(kH - 2 * kR, 10.5),
                              corner,
                              Straight(kW - 2 * kR, 11.0),
                              corner,
                              Straight(kH - 2 * kR, 10.5)};
  for (int lap = 1; lap < laps; ++lap) {
    p.push_back(lap == 1 ? corner : Repeat(corner));  // Left at J: new on the second circuit.
    p.push_back(Repeat(Straight(kW - 2 * kR, 11.0)));
    p.push_back(Repeat(corner));
    p.push_back(Repeat(Straight(kH - 2 * kR, 10.5)));
    p.push_back(Repeat(corner));
    p.push_back(Repeat(Straight(kW - 2 * kR, 11.0)));
    p.push_back(Repeat(corner));
    p.push_back(Repeat(Straight(kH - 2 * kR, 10.5)));
  }
  p.push_back(Turn(-90, kR, 5.0));  // Right at J, back onto A.
  p.push_back(Repeat(Straight(kA - kR, 10.5)));
  return p;
}

// kFigureEight: two blocks meet at a crossing X, block A (W x H between centre lines) on one
// side of both streets through X, block B (H x W) on the other. Street S leads (heading west)
// to A's corner J opposite X on their common street; the vehicle passes J straight on, crosses
// X straight on along B's side, drives round B counter-clockwise (three left corners) back to X,
// crosses X at right angles to the first time along A's side and drives round A clockwise
// (three right corners) back towards J: one eight. Later eights turn right at J (new on the
// second) and drive the same pieces again (marked repeat); the last one turns left at J onto S
// and drives it back. Every place of the blocks is revisited in the same direction laps - 1
// times, S once in the opposite direction; X is a crossing of four streets, J a junction of
// three. Corners of radius R.
std::vector<RoadPiece> FigureEightRoute(int laps) {
  constexpr double kS = 150, kW = 130, kH = 110, kR = 12;
  const RoadPiece left = Turn(90, kR, 5.0), right = Turn(-90, kR, 5.0);
  // One eight from J onwards but for the piece into X: B's side through X, round B, through X,
  // round A up to the corner before J.
  const std::vector<RoadPiece> eight = {Straight(kH - kR, 11.0),
                                        left,
                                        Straight(kW - 2 * kR, 10.5),
                                        left,
                                        Straight(kH - 2 * kR, 11.0),
                                        left,
                                        Straight(kW - kR, 10.5),
                                        Straight(kH - kR, 11.0),
                                        right,
                                        Straight(kW - 2 * kR, 10.5),
                                        right,
                                        Straight(kH - 2 * kR, 11.0)};
  std::vector<RoadPiece> p = {Straight(kS, 10.5), Straight(kW, 11.0)};
  p.insert(p.end(), eight.begin(), eight.end());
  for (int lap = 1; lap < laps; ++lap) {
    p.push_back(lap == 1 ? right : Repeat(right));  // Right at J: new on the second eight.
    p.push_back(Repeat(Straight(kW - kR, 11.0)));   // J to X.
    for (const RoadPiece& piece : eight) p.push_back(Repeat(piece));
  }
  p.push_back(left);  // Left at J, back onto S.
  p.push_back(Repeat(Straight(kS - kR, 10.5)));
  return p;
}

}  // namespace

std::vector<RoadPiece> ScenarioRoute(Scenario scenario, int laps) {
  JVL_CHECK(laps >= 1 && laps <= 100, "laps must be in [1, 100], got " << laps);
  if (scenario == Scenario::kLoop) return LoopRoute(laps);
  if (scenario == Scenario::kFigureEight) return FigureEightRoute(laps);
  std::vector<RoadPiece> pieces;
  for (int lap = 0; lap < laps; ++lap) {
    for (RoadPiece p : ScenarioLap(scenario)) {
      if (lap % 2 == 1) p.curvature = -p.curvature;
      pieces.push_back(p);
    }
  }
  return pieces;
}

std::vector<RoadPiece> WithLeads(std::vector<RoadPiece> pieces, double length) {
  JVL_CHECK(std::isfinite(length) && length >= 0, "lead length must be >= 0 m, got " << length);
  if (length == 0 || pieces.empty()) return pieces;
  RoadPiece in = Straight(length, pieces.front().speed, pieces.front().open);
  RoadPiece out = Straight(length, pieces.back().speed, pieces.back().open);
  in.lead = out.lead = true;
  out.repeat = pieces.back().repeat;
  pieces.insert(pieces.begin(), in);
  pieces.push_back(out);
  return pieces;
}

void DriveOptions::Check() const {
  JVL_CHECK(frame_rate_hz > 0, "frame_rate_hz must be > 0, got " << frame_rate_hz);
  JVL_CHECK(max_accel > 0 && max_decel > 0,
            "max_accel and max_decel must be > 0, got " << max_accel << " and " << max_decel);
  JVL_CHECK(stop_duration >= 0, "stop_duration must be >= 0, got " << stop_duration);
  JVL_CHECK(std::isfinite(steer_transition) && steer_transition >= 0 && steer_transition <= 100,
            "steer_transition must be in [0, 100] m, got " << steer_transition);
  JVL_CHECK(std::isfinite(body_vibration) && body_vibration >= 0 && body_vibration <= 2,
            "body_vibration must be in [0, 2] deg, got " << body_vibration);
}

Drive PlanDrive(const Route& route, const DriveOptions& options) {
  options.Check();
  Drive d;
  const auto& pieces = route.pieces();
  // Speed allowed at s: the piece's speed, and no faster than what still allows braking to the
  // speed of every later piece (and to 0 at a stop).
  auto allowed = [&](double s) {
    double v = 1e9;
    for (const RoadPiece& p : pieces) {
      const double dist = std::max(0.0, p.s0 - s);
      if (p.s0 + p.length < s) continue;
      v = std::min(v, std::sqrt(p.speed * p.speed + 2 * options.max_decel * dist));
    }
    if (options.stop_at_s >= 0 && s <= options.stop_at_s) {
      v = std::min(v, std::sqrt(2 * options.max_decel * (options.stop_at_s - s)));
    }
    return v;
  };
  const double begin = route.drive_begin(), end = route.drive_end();
  double s = begin, v = std::min(pieces[route.PieceIndex(begin)].speed, allowed(begin)),
         stopped = 0;
  bool stop_done = options.stop_at_s < 0;
  d.s.push_back(s);
  d.v.push_back(v);
  while (s < end) {
    double a = (allowed(s) - v) / 0.5;
    a = std::clamp(a, -options.max_decel * 1.5, options.max_accel);
    if (!stop_done && options.stop_at_s - s < 0.2) {
      a = 0;
      v = 0;
      stopped += d.dt;
      if (stopped >= options.stop_duration) stop_done = true;
    }
    v = std::max(0.0, v + a * d.dt);
    if (stop_done && v < 0.5) v = 0.5;  // Pull away after the stop.
    s += v * d.dt;
    d.s.push_back(std::min(s, end));
    d.v.push_back(v);
    JVL_CHECK(d.s.size() < 10000000, "drive does not reach the end of the route");
  }
  return d;
}

double DriveArcLength(const Drive& drive, double t) {
  // Before the first and after the last sample the vehicle keeps its speed (a LiDAR sweep
  // reaches 0.05 s beyond both ends of the drive).
  if (t < 0) return drive.s.front() + drive.v.front() * t;
  if (t > drive.duration()) return drive.s.back() + drive.v.back() * (t - drive.duration());
  const double x = std::clamp(t / drive.dt, 0.0, static_cast<double>(drive.s.size() - 1));
  const size_t i = std::min(static_cast<size_t>(x), drive.s.size() - 2);
  const double u = x - static_cast<double>(i);
  return drive.s[i] + u * (drive.s[i + 1] - drive.s[i]);
}

namespace {

// Centre line at arc length s, continued straight (curvature 0) beyond both ends of the route.
RoadPoint CentreLine(const Route& route, double s) {
  RoadPoint r = route.At(s);
  const double beyond = s < 0 ? s : std::max(0.0, s - route.length());
  if (beyond != 0) {
    r.position += beyond * Eigen::Vector2d(std::cos(r.heading), std::sin(r.heading));
    r.curvature = 0;
  }
  return r;
}

struct PathPoint {
  Eigen::Vector2d position;
  double heading = 0;
  double curvature = 0;
};

// The centre line averaged over [s - window/2, s + window/2]. Its tangent is the chord between
// the window's ends and its curvature the heading change across the window over its length, so
// a straight-to-arc step of the road becomes a linear ramp of the curvature over `window`.
// The average itself is a midpoint rule (error below a millimetre for the route's radii).
PathPoint SmoothedPath(const Route& route, double s, double window) {
  if (window <= 0) {
    const RoadPoint r = CentreLine(route, s);
    return {r.position, r.heading, r.curvature};
  }
  constexpr int kSamples = 16;
  PathPoint out;
  out.position.setZero();
  for (int i = 0; i < kSamples; ++i) {
    out.position += CentreLine(route, s + window * ((i + 0.5) / kSamples - 0.5)).position;
  }
  out.position /= kSamples;
  const RoadPoint a = CentreLine(route, s - window / 2), b = CentreLine(route, s + window / 2);
  const Eigen::Vector2d chord = b.position - a.position;
  out.heading = std::atan2(chord.y(), chord.x());
  out.curvature = std::remainder(b.heading - a.heading, 2 * kPi) / window;
  return out;
}

}  // namespace

namespace {

// A unit-RMS vibration signal at time t: four sinusoids of 0.5-2.5 Hz, frequencies and phases
// drawn from (seed, axis).
double Vibration(double t, uint64_t seed, int axis) {
  double sum = 0;
  for (int k = 0; k < 4; ++k) {
    const double f = 0.5 + 2.0 * HashUnit(10 + axis, k, seed);
    sum += std::sin(2 * kPi * f * t + 2 * kPi * HashUnit(20 + axis, k, seed));
  }
  return sum / std::sqrt(2.0);
}

}  // namespace

Rigid3d VehiclePose(const Route& route, const Terrain& terrain, const Drive& drive,
                    const DriveOptions& options, double t, uint64_t seed) {
  const double s = DriveArcLength(drive, t);
  const double x = std::clamp(t / drive.dt, 0.0, static_cast<double>(drive.v.size() - 1));
  const double v = drive.v[static_cast<size_t>(x)];
  const PathPoint rp = SmoothedPath(route, s, options.steer_transition);
  // Lane keeping: a slow weave around the lane centre; the heading follows its derivative.
  const double phase = 6.283185307 * HashUnit(1, 2, seed);
  const double w = 2 * kPi / 70.0;
  const double lateral = options.lane_offset + options.lane_wobble * std::sin(w * s + phase);
  const double dlat_ds = options.lane_wobble * w * std::cos(w * s + phase);
  const Eigen::Vector2d normal(-std::sin(rp.heading), std::cos(rp.heading));
  const Eigen::Vector2d p = rp.position + lateral * normal;
  const double yaw = rp.heading + std::atan(dlat_ds);
  // Pitch and roll from the terrain slope under the car; body roll leans out of turns
  // (~0.5 deg per m/s^2 of lateral acceleration) plus a small suspension sway.
  const Eigen::Vector2d g = terrain.Gradient(p.x(), p.y());
  const Eigen::Vector2d fwd(std::cos(yaw), std::sin(yaw)), left(-std::sin(yaw), std::cos(yaw));
  const double lat_acc = v * v * rp.curvature;
  const double vibration = options.body_vibration * kPi / 180 * std::min(1.0, v / 5.0);
  const double pitch = -std::atan(g.dot(fwd)) + vibration * Vibration(t, seed, 0);
  const double roll = std::atan(g.dot(left)) + 0.0087 * lat_acc +
                      0.003 * std::sin(2 * kPi * s / 23.0 + 2 * phase) +
                      vibration * Vibration(t, seed, 1);
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return Rigid3d(q, Eigen::Vector3d(p.x(), p.y(), terrain.Height(p.x(), p.y())));
}

}  // namespace jvl::sim
