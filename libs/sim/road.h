// The road the vehicle drives: a chain of straight and circular-arc pieces on a gently rolling
// terrain, and the vehicle motion along it (speed profile, lane keeping, pitch and roll).
// Map frame: x east, y north, z up (metres). The vehicle base frame: x forward, y left, z up,
// origin on the road surface below the LiDAR.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geometry/rigid3.h"

namespace jvl::sim {

struct RoadPiece {
  double length = 0;     // Arc length (m).
  double curvature = 0;  // 1/radius, positive = left turn; 0 for a straight.
  double speed = 10;     // Target speed on this piece (m/s).
  bool open = false;     // No buildings along it (open road).
  // Retraces (part of) an earlier piece, in either direction: a later lap of a circuit, a street
  // driven back. The world is laid out along the other pieces; Route::Project and Distance
  // ignore it, so that a place has one arc length.
  bool repeat = false;
  // Not driven: the road continuing beyond either end of the drive (see WithLeads), so that the
  // world does not end where the drive does. The vehicle drives the pieces between the leads.
  bool lead = false;
  // Filled by Route: start pose and arc-length offset.
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  double start_heading = 0;
  double s0 = 0;
  bool IsStraight() const { return curvature == 0; }
};

struct RoadPoint {
  Eigen::Vector2d position;
  double heading = 0;  // Radians from +x, counter-clockwise.
  double curvature = 0;
  int piece = 0;
};

class Route {
 public:
  Route() = default;
  // Chains the pieces starting at `start` with `heading`.
  Route(std::vector<RoadPiece> pieces, const Eigen::Vector2d& start, double heading);

  const std::vector<RoadPiece>& pieces() const { return pieces_; }
  double length() const { return length_; }
  // The arc lengths where the drive begins and ends: the route without its lead pieces at
  // either end (0 and length() when it has none).
  double drive_begin() const { return drive_begin_; }
  double drive_end() const { return drive_end_; }
  // Centre line at arc length s (clamped to [0, length]).
  RoadPoint At(double s) const;
  // Nearest centre-line point over all pieces (exact projection onto lines and circles):
  // arc length and signed lateral offset (left +).
  void Project(const Eigen::Vector2d& p, double* s, double* lateral) const;
  double Distance(const Eigen::Vector2d& p) const;
  // Index of the piece holding arc length s (clamped; at a shared end, the earlier piece).
  size_t PieceIndex(double s) const;
  // Range [first, last) of the pieces whose start s0 lies in (lo, hi).
  std::pair<size_t, size_t> PiecesStartingIn(double lo, double hi) const;

 private:
  // Project() looks among the pieces of p's cell of a grid first (exact where one of them is
  // within kIndexReach, else all pieces): cost independent of the route's length.
  static constexpr double kIndexCell = 16.0;   // m
  static constexpr double kIndexReach = 40.0;  // m
  static int64_t CellIndex(double v);
  static uint64_t CellKey(int64_t x, int64_t y);
  static uint64_t CellKey(const Eigen::Vector2d& p);
  void ProjectOnto(const Eigen::Vector2d& p, const std::vector<int>& candidates, double* s,
                   double* lateral) const;

  // Per-piece constants for Project(): unit start direction, circle centre and radius (arcs),
  // end point and heading, and a bounding circle (mid point, radius length/2).
  struct Cache {
    Eigen::Vector2d dir, centre, end, mid;
    double radius = 0, end_heading = 0;
  };
  std::vector<RoadPiece> pieces_;
  std::vector<Cache> cache_;
  std::vector<double> piece_ends_;  // s0 + length of each piece
  std::vector<int> all_pieces_;     // 0 .. pieces - 1
  std::unordered_map<uint64_t, std::vector<int>> index_;
  double length_ = 0;
  double drive_begin_ = 0, drive_end_ = 0;
};

// Rolling terrain: a sum of long-wavelength sinusoids (slopes of a few percent).
struct Terrain {
  double amplitude[3] = {1.6, 1.2, 0.4};
  double wavelength[3] = {420.0, 330.0, 190.0};
  double phase[3] = {0.3, 1.1, 2.0};
  double Height(double x, double y) const;
  Eigen::Vector2d Gradient(double x, double y) const;
};

// Scenario presets: route pieces, speeds and density of the world.
// kStraight: the highway's scenery on one 1.2 km straight (the geometry direction priors are
// made for: one road direction over the whole drive). kLoop: the urban scenery around a city
// block with revisits: a 150 m street to the block, `laps` circuits of it (130 m x 110 m, four
// left corners, 459 m each; every place revisited in the same direction) and back along the
// street (revisited in the opposite direction). kFigureEight: the urban scenery along a figure
// eight of two blocks that meet at a crossing X (see FigureEightRoute in road.cc): a 150 m
// street to the first block's corner J, `laps` eights (every place of the blocks revisited in the
// same direction, X crossed in two directions at right angles) and back along the street.
enum class Scenario { kUrban, kSuburban, kHighway, kStraight, kLoop, kFigureEight };
// urban|suburban|highway|straight|loop|figure8
Scenario ParseScenario(const std::string& name);
std::string ToString(Scenario scenario);
// Highway and straight: fast, open scenery (few buildings far from the road, no kerbside
// furniture, flatter terrain).
bool IsHighwayLike(Scenario scenario);
// Urban, loop and figure eight: the city scenery (dense buildings, few plants).
bool IsUrbanLike(Scenario scenario);
// `laps` > 1 repeats the pieces; every second lap has its turns mirrored (left <-> right), so
// that the route zigzags on without crossing itself (urban: 9 laps = 4.3 km, 4779 frames). For
// kLoop, `laps` is the number of circuits of the block, for kFigureEight the number of eights
// (pieces driven before marked repeat).
std::vector<RoadPiece> ScenarioRoute(Scenario scenario, int laps = 1);
// `pieces` with a straight lead piece of `length` metres before the first and after the last
// one (none when length is 0): the road and its world continue straight beyond the ends of the
// drive, as real roads do, instead of ending where the drive does. The leads take the speed and
// the openness of their neighbours; the trailing one is marked repeat when the last piece is (a
// route that ends driving back along its first street retraces the leading one). The route's
// start then lies `length` metres before the drive's.
std::vector<RoadPiece> WithLeads(std::vector<RoadPiece> pieces, double length);

struct DriveOptions {
  double frame_rate_hz = 10.0;
  double max_accel = 1.2;      // m/s^2
  double max_decel = 1.8;      // m/s^2
  double lane_offset = -1.75;  // Right-hand traffic: centre of the right lane.
  double lane_wobble = 0.12;   // Amplitude (m) of lane-keeping weaving.
  double stop_at_s = -1;       // Arc length of a stop (< 0: no stop).
  double stop_duration = 3.0;  // s
  // The vehicle's path is the lane averaged over this arc length (m): its curvature, the yaw rate
  // and the body roll ramp over it where the road steps from straight to arc. Following the
  // centre line exactly (0) steps the yaw rate and the roll within one instant; a sweep of a
  // moving LiDAR that straddles that instant is bent in a way no motion model can undo. Default
  // from the KITTI ground truth (docs/sim.md "Vehicle motion").
  double steer_transition = 6.0;
  // RMS (deg) of the body's pitch and roll vibration on the road (each a sum of four sinusoids of
  // 0.5-2.5 Hz with random phases and frequencies, fading out below 5 m/s). Default from the
  // KITTI ground truth: frame-to-frame pitch and roll of 0.08-0.10 deg at the median
  // (docs/sim.md "Vehicle motion"). 0: a body fixed to the terrain.
  double body_vibration = 0.13;
  void Check() const;
};

// Vehicle motion: arc length and speed sampled at 100 Hz from t = 0 (at route.drive_begin())
// until route.drive_end().
struct Drive {
  double dt = 0.01;
  std::vector<double> s, v;
  double duration() const { return dt * static_cast<double>(s.size() - 1); }
};
Drive PlanDrive(const Route& route, const DriveOptions& options);

// world_from_base of the vehicle at time t (interpolated), with pitch and roll from the terrain,
// body roll from lateral acceleration and lane-keeping weaving. `seed` varies the weaving phase.
Rigid3d VehiclePose(const Route& route, const Terrain& terrain, const Drive& drive,
                    const DriveOptions& options, double t, uint64_t seed);
// Arc length along the route at time t.
double DriveArcLength(const Drive& drive, double t);

}  // namespace jvl::sim
