// Layout of the world along the route: where buildings, street furniture, plants and traffic go.
#include "sim/scene.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "sim/random.h"
#include "sim/scene_mesh.h"

namespace jvl::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector2d Normal(double heading) { return {-std::sin(heading), std::cos(heading)}; }

// Separating-axis test between two rectangles given by their corners (counter-clockwise).
bool RectanglesOverlap(const std::array<Eigen::Vector2d, 4>& a,
                       const std::array<Eigen::Vector2d, 4>& b, double margin) {
  for (const auto* poly : {&a, &b}) {
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d e = (*poly)[(i + 1) % 4] - (*poly)[i];
      const Eigen::Vector2d n(-e.y(), e.x());
      const Eigen::Vector2d axis = n.normalized();
      double amin = 1e18, amax = -1e18, bmin = 1e18, bmax = -1e18;
      for (const auto& p : a)
        amin = std::min(amin, p.dot(axis)), amax = std::max(amax, p.dot(axis));
      for (const auto& p : b)
        bmin = std::min(bmin, p.dot(axis)), bmax = std::max(bmax, p.dot(axis));
      if (amax + margin < bmin || bmax + margin < amin) return false;
    }
  }
  return true;
}

bool InsideAnyBuilding(const Scene& scene, const Eigen::Vector2d& p, double margin) {
  for (const Building& b : scene.buildings) {
    const Eigen::Vector2d d = p - b.center;
    const Eigen::Vector2d ax(std::cos(b.yaw), std::sin(b.yaw));
    if (std::abs(d.dot(ax)) < b.length / 2 + margin &&
        std::abs(d.dot(Normal(b.yaw))) < b.depth / 2 + margin) {
      return true;
    }
  }
  return false;
}

// The route without its repeated pieces: their total length, and the route arc length at
// distance u along them (u beyond the end: the route's end). Street furniture and hedges are
// spaced along it, so the world does not depend on how often the vehicle retraces a street.
double LaidOutLength(const Route& route) {
  double length = 0;
  for (const RoadPiece& p : route.pieces()) length += p.repeat ? 0.0 : p.length;
  return length;
}

// laid_out_length = LaidOutLength(route).
double LaidOutToRoute(const Route& route, double laid_out_length, double u) {
  if (laid_out_length == route.length()) return u;  // Nothing repeated: the same numbers.
  for (const RoadPiece& p : route.pieces()) {
    if (p.repeat) continue;
    if (u <= p.length) return p.s0 + u;
    u -= p.length;
  }
  return route.length();
}

struct BuildingStyle {
  double len_lo, len_hi, depth_lo, depth_hi, setback_jitter, gap_prob, gap_lo, gap_hi;
  int floors_lo, floors_hi;
  double extra_setback;
};

BuildingStyle StyleFor(Scenario s) {
  switch (s) {
    case Scenario::kUrban:
    case Scenario::kLoop:
    case Scenario::kFigureEight:
      return {12, 30, 10, 16, 1.0, 0.35, 4, 12, 3, 6, 0.0};
    case Scenario::kSuburban:
      return {8, 14, 8, 12, 3.0, 0.85, 6, 16, 1, 2, 3.0};
    case Scenario::kHighway:
    case Scenario::kStraight:
      return {30, 60, 15, 25, 4.0, 1.0, 25, 70, 2, 3, 18.0};
  }
  return {};
}

void PlaceBuildings(Scene& scene, Rng& rng) {
  const BuildingStyle st = StyleFor(scene.options.scenario);
  const double clear = scene.options.road_half_width + scene.options.sidewalk_width;
  for (const RoadPiece& piece : scene.route.pieces()) {
    if (piece.repeat || piece.open ||
        (!piece.IsStraight() && std::abs(1.0 / piece.curvature) < 50)) {
      continue;
    }
    for (double side : {-1.0, 1.0}) {
      double s = piece.s0 + rng.Uniform(2, 6);
      const double end = piece.s0 + piece.length - 2;
      while (s + 6 < end) {
        const double len = std::min(rng.Uniform(st.len_lo, st.len_hi), end - s);
        const RoadPoint rp = scene.route.At(s + len / 2);
        Building b;
        b.yaw = rp.heading;
        b.length = len;
        b.depth = rng.Uniform(st.depth_lo, st.depth_hi);
        b.floors = rng.UniformInt(st.floors_lo, st.floors_hi);
        b.floor_height = rng.Uniform(2.9, 3.4);
        b.height = b.floors * b.floor_height + rng.Uniform(0.3, 1.2);
        b.window_width = rng.Uniform(0.9, 1.6);
        b.window_height = rng.Uniform(1.2, 1.8);
        b.window_spacing = b.window_width + rng.Uniform(1.0, 2.2);
        b.albedo = static_cast<float>(rng.Uniform(0.45, 0.85));
        const double setback = clear + st.extra_setback + rng.Uniform(0, st.setback_jitter);
        b.center = rp.position + side * Normal(rp.heading) * (setback + b.depth / 2);
        const auto corners = b.Corners();
        bool ok = len >= 6;
        for (const auto& c : corners) ok = ok && scene.route.Distance(c) > clear - 0.3;
        for (const Building& o : scene.buildings) {
          ok = ok && !RectanglesOverlap(corners, o.Corners(), -0.1);
        }
        if (ok) {
          const Eigen::Vector2d ground = b.center;
          double zmin = scene.terrain.Height(ground.x(), ground.y());
          for (const auto& c : corners) zmin = std::min(zmin, scene.terrain.Height(c.x(), c.y()));
          b.base_z = zmin - 0.3;
          scene.buildings.push_back(b);
        }
        s += len + (rng.Bernoulli(st.gap_prob) ? rng.Uniform(st.gap_lo, st.gap_hi) : 0.0);
      }
    }
  }
}

// Axis groups: buildings whose yaw agrees modulo 90 deg within 1 degree share a group (a
// Manhattan frame: the blocks of a perpendicular street have the same two axes).
void AssignAxisGroups(Scene& scene) {
  const double q = kPi / 2;
  for (Building& b : scene.buildings) {
    double yaw = std::fmod(b.yaw, q);
    if (yaw < 0) yaw += q;
    b.axis_group = -1;
    for (size_t g = 0; g < scene.axis_group_yaw.size(); ++g) {
      double d = std::abs(yaw - scene.axis_group_yaw[g]);
      d = std::min(d, q - d);
      if (d < kPi / 180) b.axis_group = static_cast<int>(g);
    }
    if (b.axis_group < 0) {
      b.axis_group = static_cast<int>(scene.axis_group_yaw.size());
      scene.axis_group_yaw.push_back(yaw);
    }
  }
}

void PlaceStreetFurniture(Scene& scene, Rng& rng) {
  const double hw = scene.options.road_half_width;
  const double len = LaidOutLength(scene.route);
  const Terrain& tr = scene.terrain;
  for (double u = rng.Uniform(5, 15); u < len; u += rng.Uniform(25, 35)) {
    const double s = LaidOutToRoute(scene.route, len, u);
    for (double side : {-1.0, 1.0}) {
      const RoadPoint rp = scene.route.At(s + (side > 0 ? 12 : 0));
      const Eigen::Vector2d p = rp.position + side * Normal(rp.heading) * (hw + 0.8);
      if (scene.route.Distance(p) < hw + 0.5 || InsideAnyBuilding(scene, p, 0.5)) continue;
      scene.poles.push_back(
          {Eigen::Vector3d(p.x(), p.y(), tr.Height(p.x(), p.y())), 0.12, rng.Uniform(6.5, 8.5)});
    }
  }
  for (double u = rng.Uniform(20, 40); u < len; u += rng.Uniform(55, 85)) {
    const RoadPoint rp = scene.route.At(LaidOutToRoute(scene.route, len, u));
    const Eigen::Vector2d p = rp.position - Normal(rp.heading) * (hw + 1.2);
    if (scene.route.Distance(p) < hw + 0.8 || InsideAnyBuilding(scene, p, 0.5)) continue;
    const double z = tr.Height(p.x(), p.y());
    scene.poles.push_back({Eigen::Vector3d(p.x(), p.y(), z), 0.04, 2.6});
    scene.signs.push_back(
        {Eigen::Vector3d(p.x(), p.y(), z + 2.25), rp.heading, Eigen::Vector3d(0.06, 0.75, 0.75)});
  }
  if (IsHighwayLike(scene.options.scenario)) return;
  for (const RoadPiece& piece : scene.route.pieces()) {
    if (!piece.IsStraight() || piece.open || piece.repeat) continue;
    for (double side : {-1.0, 1.0}) {
      for (double s = piece.s0 + 15; s < piece.s0 + piece.length - 15; s += 6.5) {
        if (!rng.Bernoulli(0.45)) continue;
        const RoadPoint rp = scene.route.At(s);
        const Eigen::Vector2d p = rp.position + side * Normal(rp.heading) * (hw - 1.0);
        const Eigen::Vector3d size(rng.Uniform(4.0, 4.7), rng.Uniform(1.7, 1.9),
                                   rng.Uniform(1.4, 1.6));
        scene.parked_cars.push_back({Eigen::Vector3d(p.x(), p.y(), tr.Height(p.x(), p.y())),
                                     rp.heading + rng.Normal(0.02), size});
      }
    }
  }
}

void PlacePlants(Scene& scene, Rng& rng) {
  const double hw = scene.options.road_half_width;
  const bool green = !IsUrbanLike(scene.options.scenario);
  for (const RoadPiece& piece : scene.route.pieces()) {
    if (piece.repeat) continue;
    const double spacing = piece.open ? 7.0 : (green ? 14.0 : 30.0);
    for (double s = piece.s0 + rng.Uniform(0, spacing); s < piece.s0 + piece.length;
         s += rng.Uniform(0.6, 1.4) * spacing) {
      const RoadPoint rp = scene.route.At(s);
      const double side = rng.Bernoulli(0.5) ? 1.0 : -1.0;
      const double lat = piece.open ? rng.Uniform(hw + 3, hw + 25) : rng.Uniform(hw + 2, hw + 3.5);
      const Eigen::Vector2d p = rp.position + side * Normal(rp.heading) * lat;
      const bool tree = !piece.open || rng.Bernoulli(0.5);
      const double r = tree ? rng.Uniform(1.8, 3.0) : rng.Uniform(0.7, 1.6);
      if (scene.route.Distance(p) < hw + 1.5 || InsideAnyBuilding(scene, p, r)) continue;
      const double z = scene.terrain.Height(p.x(), p.y());
      scene.plants.push_back(
          {Eigen::Vector3d(p.x(), p.y(), z + (tree ? rng.Uniform(4.0, 5.5) : r * 0.6)), r, tree});
    }
  }
}

// Hedge rows along both sides of the road, beyond the sidewalk: runs of U(15, 60) m, each a
// chain of bushes 1.2 m apart (radius U(0.9, 1.4) m, so they merge into one row of leaf
// clumps), separated by gaps whose mean length makes `coverage` the covered fraction of each
// side. Buildings and the road are kept clear.
void PlaceHedges(Scene& scene, double coverage, Rng& rng) {
  if (coverage <= 0) return;
  const double clear = scene.options.road_half_width + scene.options.sidewalk_width;
  const double mean_run = 37.5;
  const double mean_gap = coverage >= 1 ? 0.0 : mean_run * (1 - coverage) / coverage;
  const double length = LaidOutLength(scene.route);
  for (double side : {-1.0, 1.0}) {
    double s = rng.Uniform(0, mean_gap + 5);
    while (s < length) {
      const double run = rng.Uniform(15, 60);
      const double offset = rng.Uniform(0.5, 1.5);
      for (double t = s; t < std::min(s + run, length); t += 1.2) {
        const RoadPoint rp = scene.route.At(LaidOutToRoute(scene.route, length, t));
        const double r = rng.Uniform(0.9, 1.4);
        const Eigen::Vector2d p = rp.position + side * Normal(rp.heading) * (clear + offset + r);
        if (scene.route.Distance(p) < clear + r || InsideAnyBuilding(scene, p, r + 0.5)) continue;
        const double z = scene.terrain.Height(p.x(), p.y());
        scene.plants.push_back({Eigen::Vector3d(p.x(), p.y(), z + 0.7 * r), r, false});
      }
      s += run + (mean_gap > 0 ? rng.Uniform(0, 2 * mean_gap) : 0.0);
    }
  }
}

void PlaceMovingCars(Scene& scene, Rng& rng) {
  // Placed relative to the drive: cars ahead in the lane, oncoming ones along the whole drive.
  const double begin = scene.route.drive_begin();
  const double len = scene.route.drive_end() - begin;
  for (int i = 0; i < scene.options.moving_cars; ++i) {
    MovingCar car;
    const bool oncoming = i % 2 == 0;
    const double v = IsHighwayLike(scene.options.scenario) ? 24 : 11;
    car.speed = oncoming ? -rng.Uniform(0.8 * v, v) : rng.Uniform(v, 1.15 * v);
    car.s0 =
        begin + (oncoming ? rng.Uniform(0.3 * len, 1.3 * len) : rng.Uniform(25, 70) + 60.0 * i);
    car.lateral = oncoming ? 1.75 : -1.75;
    car.size = Eigen::Vector3d(rng.Uniform(4.0, 4.8), rng.Uniform(1.7, 1.9), rng.Uniform(1.4, 1.6));
    scene.moving_cars.push_back(car);
  }
}

}  // namespace

const char* ToString(Material m) {
  switch (m) {
    case Material::kGround:
      return "ground";
    case Material::kFacade:
      return "facade";
    case Material::kRoof:
      return "roof";
    case Material::kKerb:
      return "kerb";
    case Material::kPole:
      return "pole";
    case Material::kSign:
      return "sign";
    case Material::kCar:
      return "car";
    case Material::kFoliage:
      return "foliage";
    case Material::kTrunk:
      return "trunk";
  }
  return "?";
}

std::array<Eigen::Vector2d, 4> Building::Corners() const {
  const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw)), ay(-std::sin(yaw), std::cos(yaw));
  const Eigen::Vector2d a = ax * length / 2, b = ay * depth / 2;
  return {center - a - b, center + a - b, center + a + b, center - a + b};
}

void SceneOptions::Check() const {
  JVL_CHECK(road_half_width > 3.5,
            "road_half_width must exceed one lane (3.5 m), got " << road_half_width);
  JVL_CHECK(sidewalk_width >= 0, "sidewalk_width must be >= 0, got " << sidewalk_width);
  JVL_CHECK(ground_cell > 0.2 && ground_cell <= 10,
            "ground_cell must be in (0.2, 10] m, got " << ground_cell);
  JVL_CHECK(moving_cars >= 0, "moving_cars must be >= 0, got " << moving_cars);
  JVL_CHECK(std::isnan(hedge_coverage) || (hedge_coverage >= 0 && hedge_coverage <= 1),
            "hedge_coverage must be in [0, 1], got " << hedge_coverage);
  JVL_CHECK(std::isfinite(foliage_density) && foliage_density >= 0 && foliage_density <= 5,
            "foliage_density must be in [0, 5] m^2/m^3, got " << foliage_density);
  JVL_CHECK(std::isfinite(terrain_scale) && terrain_scale >= 0 && terrain_scale <= 5,
            "terrain_scale must be in [0, 5], got " << terrain_scale);
}

Box Scene::MovingCarBox(size_t i, double t) const {
  const MovingCar& car = moving_cars.at(i);
  const double s = car.s0 + car.speed * t;
  Box box;
  if (s < 0 || s > route.length()) {
    box.size = Eigen::Vector3d::Zero();  // Off the route: not present.
    box.center = Eigen::Vector3d::Zero();
    return box;
  }
  const RoadPoint rp = route.At(s);
  const Eigen::Vector2d p = rp.position + car.lateral * Normal(rp.heading);
  box.center =
      Eigen::Vector3d(p.x(), p.y(), terrain.Height(p.x(), p.y()) + car.size.z() / 2 + 0.15);
  box.yaw = rp.heading + (car.speed < 0 ? kPi : 0.0);
  box.size = car.size;
  return box;
}

double SceneOptions::HedgeCoverage() const {
  if (!std::isnan(hedge_coverage)) return hedge_coverage;
  return IsHighwayLike(scenario) ? kHighwayHedgeCoverage : 0.0;
}

Scene BuildScene(const Route& route, const SceneOptions& options) {
  options.Check();
  Scene scene;
  scene.options = options;
  scene.route = route;
  const double terrain_scale =
      options.terrain_scale * (IsHighwayLike(options.scenario) ? 0.6 : 1.0);
  for (double& a : scene.terrain.amplitude) a *= terrain_scale;
  Rng rng(HashCombine(options.seed, 0x5ce7e));
  PlaceBuildings(scene, rng);
  AssignAxisGroups(scene);
  PlaceStreetFurniture(scene, rng);
  PlacePlants(scene, rng);
  Rng hedge_rng(HashCombine(options.seed, 0x4ed9e));  // Its own stream: the rest is unchanged.
  PlaceHedges(scene, options.HedgeCoverage(), hedge_rng);
  PlaceMovingCars(scene, rng);
  BuildSceneMesh(scene, rng);
  return scene;
}

}  // namespace jvl::sim
