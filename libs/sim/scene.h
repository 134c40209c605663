// The static world around the route: terrain with the road, kerbs, building blocks, poles, signs,
// parked cars and vegetation as one triangle mesh (for ray casting), plus the object list that
// describes it (for the scene ground truth) and the moving cars (analytic boxes, per frame).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "sim/road.h"

namespace jvl::sim {

enum class Material : uint8_t {
  kGround = 0,  // Road, sidewalk and verge; texture from the route (lane markings).
  kFacade,      // Building wall with floors and windows.
  kRoof,
  kKerb,
  kPole,
  kSign,
  kCar,
  kFoliage,
  kTrunk,
};
const char* ToString(Material m);

// A planar patch's texture frame: texture coordinates are ((p-origin).u, (p-origin).v).
struct Face {
  Material material = Material::kGround;
  int32_t object = -1;  // Index into Scene::buildings for facades/roofs, else -1.
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector3f u = Eigen::Vector3f::UnitX(), v = Eigen::Vector3f::UnitZ();
  float albedo = 0.5f;
  float width = 0;  // Extent along u (walls), for window layout.
};

struct Mesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<uint32_t> triangle_face;  // Face index of every triangle.
  std::vector<Face> faces;
  uint32_t AddFace(const Face& f) {
    faces.push_back(f);
    return static_cast<uint32_t>(faces.size() - 1);
  }
  void AddTriangle(uint32_t a, uint32_t b, uint32_t c, uint32_t face) {
    triangles.push_back({a, b, c});
    triangle_face.push_back(face);
  }
  uint32_t AddVertex(const Eigen::Vector3d& p) {
    vertices.push_back(p.cast<float>());
    return static_cast<uint32_t>(vertices.size() - 1);
  }
};

struct Building {
  Eigen::Vector2d center;  // Footprint centre.
  double yaw = 0;          // Direction of the length axis (facade along the road).
  double length = 0, depth = 0, height = 0, base_z = 0;
  int floors = 0;
  double floor_height = 3.0, window_width = 1.2, window_height = 1.5, window_spacing = 3.0;
  float albedo = 0.6f;
  int axis_group = 0;  // Buildings sharing an orientation (yaw rounded to 1 degree).
  std::array<Eigen::Vector2d, 4> Corners() const;
};

// A box-shaped object (parked or moving car, sign plate): centre, yaw, size (x along yaw).
struct Box {
  Eigen::Vector3d center;
  double yaw = 0;
  Eigen::Vector3d size;
};

struct Pole {
  Eigen::Vector3d base;
  double radius = 0.1, height = 6.0;
};

struct Plant {
  Eigen::Vector3d center;  // Canopy centre.
  double radius = 1.0;
  bool tree = true;  // Trunk + canopy; otherwise a bush on the ground.
};

struct MovingCar {
  double s0 = 0;       // Route arc length at t = 0.
  double speed = 0;    // Along the route (negative: oncoming traffic).
  double lateral = 0;  // Offset from the centre line (left +).
  Eigen::Vector3d size{4.3, 1.8, 1.5};
};

// Hedge coverage of the highway-like scenarios' roadsides (docs/sim.md "Fidelity table": set
// from the real KITTI 04 scans' ground and scattered fractions); other scenarios have none.
inline constexpr double kHighwayHedgeCoverage = 0.7;

struct SceneOptions {
  Scenario scenario = Scenario::kUrban;
  uint64_t seed = 1;
  double road_half_width = 5.5;  // Two 3.5 m lanes plus a 2 m parking strip each side.
  double sidewalk_width = 4.0;
  double ground_cell = 2.0;  // Terrain mesh resolution (m).
  double ground_margin = 90.0;
  int moving_cars = 4;
  // Multiplies the terrain amplitudes (0 = flat ground; slopes scale with it).
  double terrain_scale = 1.0;
  // Leaf area density of crowns and bushes (m^2 of leaf clumps per m^3): they are volumes of
  // small clumps that rays pass through (mean free path 2 / density). 0: each is one opaque
  // irregular surface.
  double foliage_density = 1.0;
  // Fraction of each roadside lined by hedge rows beyond the sidewalk; NaN: the scenario's
  // (HedgeCoverage()).
  double hedge_coverage = std::numeric_limits<double>::quiet_NaN();
  double HedgeCoverage() const;
  void Check() const;
};

struct Scene {
  SceneOptions options;
  Route route;
  Terrain terrain;
  std::vector<Building> buildings;
  std::vector<Pole> poles;
  std::vector<Box> signs, parked_cars;
  std::vector<Plant> plants;
  std::vector<MovingCar> moving_cars;
  std::vector<double> axis_group_yaw;  // Yaw of every building axis group.
  Mesh mesh;
  // Oriented box of moving car i at time t (on the terrain, following the route).
  Box MovingCarBox(size_t i, double t) const;
};

Scene BuildScene(const Route& route, const SceneOptions& options);

}  // namespace jvl::sim
