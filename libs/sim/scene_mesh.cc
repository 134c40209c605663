#include "sim/scene_mesh.h"

#include <cmath>
#include <map>

namespace jvl::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

void AddQuad(Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3d& c, const Eigen::Vector3d& d, uint32_t face) {
  const uint32_t ia = mesh.AddVertex(a), ib = mesh.AddVertex(b);
  const uint32_t ic = mesh.AddVertex(c), id = mesh.AddVertex(d);
  mesh.AddTriangle(ia, ib, ic, face);
  mesh.AddTriangle(ia, ic, id, face);
}

void AddTerrain(Scene& scene) {
  Eigen::Vector2d lo(1e18, 1e18), hi(-1e18, -1e18);
  for (double s = 0; s <= scene.route.length(); s += 2.0) {
    const Eigen::Vector2d p = scene.route.At(s).position;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double m = scene.options.ground_margin, cell = scene.options.ground_cell;
  lo -= Eigen::Vector2d(m, m);
  hi += Eigen::Vector2d(m, m);
  const int nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)) + 1;
  const int ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)) + 1;
  Face ground;
  ground.material = Material::kGround;
  const uint32_t face = scene.mesh.AddFace(ground);
  const uint32_t first = static_cast<uint32_t>(scene.mesh.vertices.size());
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = lo.x() + i * cell, y = lo.y() + j * cell;
      scene.mesh.AddVertex(Eigen::Vector3d(x, y, scene.terrain.Height(x, y)));
    }
  }
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const uint32_t a = first + j * nx + i, b = a + 1, c = a + nx + 1, d = a + nx;
      scene.mesh.AddTriangle(a, b, c, face);
      scene.mesh.AddTriangle(a, c, d, face);
    }
  }
}

// Kerb stones (0.15 m high, 0.25 m wide) along both road edges in 2 m pieces, skipped where
// they would stand on another piece of the road (inside corners).
void AddKerbs(Scene& scene) {
  const double hw = scene.options.road_half_width;
  for (double s = 0; s + 2.0 <= scene.route.length(); s += 2.0) {
    const RoadPoint rp = scene.route.At(s + 1.0);
    if (scene.route.pieces()[rp.piece].repeat) continue;
    const Eigen::Vector2d n(-std::sin(rp.heading), std::cos(rp.heading));
    for (double side : {-1.0, 1.0}) {
      const Eigen::Vector2d c = rp.position + side * n * (hw + 0.125);
      if (scene.route.Distance(c) < hw) continue;
      const double z = scene.terrain.Height(c.x(), c.y());
      AddBox(scene.mesh, c, rp.heading, 2.02, 0.25, z - 0.2, z + 0.15, z, Material::kKerb,
             Material::kKerb, -1, 0.7f);
    }
  }
}

void AddPrism(Mesh& mesh, const Eigen::Vector3d& base, double radius, double height,
              Material material, float albedo) {
  Face f;
  f.material = material;
  f.albedo = albedo;
  const uint32_t face = mesh.AddFace(f);
  const int n = 8;
  for (int i = 0; i < n; ++i) {
    const double a0 = 2 * kPi * i / n, a1 = 2 * kPi * (i + 1) / n;
    const Eigen::Vector3d p0 = base + radius * Eigen::Vector3d(std::cos(a0), std::sin(a0), 0);
    const Eigen::Vector3d p1 = base + radius * Eigen::Vector3d(std::cos(a1), std::sin(a1), 0);
    const Eigen::Vector3d up(0, 0, height);
    AddQuad(mesh, p0, p1, p1 + up, p0 + up, face);
  }
}

// An irregular blob: a once-subdivided icosahedron with random radial displacement: a crown as
// one opaque surface (foliage_density 0).
void AddBlob(Mesh& mesh, const Eigen::Vector3d& c, double radius, Rng& rng) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  std::map<std::pair<int, int>, int> mid;
  auto midpoint = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    v.push_back((v[a] + v[b]) / 2);
    mid[key] = static_cast<int>(v.size()) - 1;
    return static_cast<int>(v.size()) - 1;
  };
  std::vector<std::array<int, 3>> g;
  for (const auto& tri : f) {
    const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
              d = midpoint(tri[2], tri[0]);
    g.push_back({tri[0], a, d});
    g.push_back({tri[1], b, a});
    g.push_back({tri[2], d, b});
    g.push_back({a, b, d});
  }
  Face face;
  face.material = Material::kFoliage;
  face.albedo = static_cast<float>(rng.Uniform(0.25, 0.45));
  const uint32_t fi = mesh.AddFace(face);
  const uint32_t first = static_cast<uint32_t>(mesh.vertices.size());
  for (const auto& p : v) {
    Eigen::Vector3d q = p.normalized() * radius * rng.Uniform(0.65, 1.3);
    q.z() *= 0.8;
    mesh.AddVertex(c + q);
  }
  for (const auto& tri : g) mesh.AddTriangle(first + tri[0], first + tri[1], first + tri[2], fi);
}

// A crown (or bush) as a volume of leaf clumps: small triangles of random orientation spread
// uniformly through an irregular ellipsoid (semi-axes radius x U(0.85, 1.15) horizontally and
// 0.8 radius vertically), one face each. `density` is the one-sided clump area per unit volume
// (m^2/m^3, the leaf area density of forestry); with randomly oriented clumps a ray is stopped
// after a free path of mean 1 / (0.5 density) (Beer-Lambert, mean projection 1/2), so LiDAR
// returns spread through the crown and the camera sees sky and background through its gaps.
// Clumps deeper inside are darker (a stand-in for the crown's self-shadowing).
void AddFoliage(Mesh& mesh, const Eigen::Vector3d& c, double radius, double density, float albedo,
                Rng& rng) {
  const Eigen::Vector3d axes(radius * rng.Uniform(0.85, 1.15), radius * rng.Uniform(0.85, 1.15),
                             0.8 * radius);
  const double volume = 4.0 / 3.0 * kPi * axes.x() * axes.y() * axes.z();
  constexpr double kMeanArea = 0.037;  // Mean clump area (m^2): circumradius 0.12-0.22 m.
  const int count = static_cast<int>(std::lround(density * volume / kMeanArea));
  for (int k = 0; k < count; ++k) {
    Eigen::Vector3d q;
    do {
      q = Eigen::Vector3d(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
    } while (q.squaredNorm() > 1.0);
    const double depth = q.norm();  // 0 at the centre, 1 on the surface.
    Face face;
    face.material = Material::kFoliage;
    face.albedo = static_cast<float>(albedo * (0.45 + 0.55 * depth) * rng.Uniform(0.8, 1.2));
    const uint32_t fi = mesh.AddFace(face);
    // A random plane through the clump's centre; three corners at irregular angles.
    Eigen::Vector3d n(rng.Normal(), rng.Normal(), rng.Normal());
    n.normalize();
    const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
    const Eigen::Vector3d centre = c + q.cwiseProduct(axes);
    const double r = rng.Uniform(0.12, 0.22);
    const double phase = rng.Uniform(0, 2 * kPi);
    uint32_t v[3];
    for (int i = 0; i < 3; ++i) {
      const double angle = phase + 2 * kPi * i / 3 + rng.Uniform(-0.4, 0.4);
      v[i] = mesh.AddVertex(centre + r * (std::cos(angle) * a + std::sin(angle) * b));
    }
    mesh.AddTriangle(v[0], v[1], v[2], fi);
  }
}

}  // namespace

void AddBox(Mesh& mesh, const Eigen::Vector2d& c, double yaw, double sx, double sy, double z0,
            double z1, double ground_z, Material wall, Material top, int32_t object, float albedo) {
  const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw)), ay(-std::sin(yaw), std::cos(yaw));
  const Eigen::Vector2d a = ax * sx / 2, b = ay * sy / 2;
  const Eigen::Vector2d corners[4] = {c - a - b, c + a - b, c + a + b, c - a + b};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d p = corners[i], q = corners[(i + 1) % 4];
    Face f;
    f.material = wall;
    f.object = object;
    f.albedo = albedo;
    f.origin = Eigen::Vector3f(p.x(), p.y(), ground_z);
    f.u = Eigen::Vector3f(q.x() - p.x(), q.y() - p.y(), 0).normalized();
    f.v = Eigen::Vector3f::UnitZ();
    f.width = static_cast<float>((q - p).norm());
    const uint32_t face = mesh.AddFace(f);
    AddQuad(mesh, {p.x(), p.y(), z0}, {q.x(), q.y(), z0}, {q.x(), q.y(), z1}, {p.x(), p.y(), z1},
            face);
  }
  Face f;
  f.material = top;
  f.object = object;
  f.albedo = albedo;
  f.origin = Eigen::Vector3f(corners[0].x(), corners[0].y(), z1);
  f.u = Eigen::Vector3f(ax.x(), ax.y(), 0);
  f.v = Eigen::Vector3f(ay.x(), ay.y(), 0);
  const uint32_t face = mesh.AddFace(f);
  for (double z : {z0, z1}) {
    AddQuad(mesh, {corners[0].x(), corners[0].y(), z}, {corners[1].x(), corners[1].y(), z},
            {corners[2].x(), corners[2].y(), z}, {corners[3].x(), corners[3].y(), z}, face);
  }
}

void BuildSceneMesh(Scene& scene, Rng& rng) {
  Mesh& mesh = scene.mesh;
  AddTerrain(scene);
  AddKerbs(scene);
  for (size_t i = 0; i < scene.buildings.size(); ++i) {
    const Building& b = scene.buildings[i];
    const double ground = scene.terrain.Height(b.center.x(), b.center.y());
    AddBox(mesh, b.center, b.yaw, b.length, b.depth, b.base_z, ground + b.height, ground,
           Material::kFacade, Material::kRoof, static_cast<int32_t>(i), b.albedo);
  }
  for (const Pole& p : scene.poles)
    AddPrism(mesh, p.base, p.radius, p.height, Material::kPole, 0.5f);
  for (const Box& s : scene.signs) {
    const double z0 = s.center.z() - s.size.z() / 2;
    AddBox(mesh, s.center.head<2>(), s.yaw, s.size.x(), s.size.y(), z0, z0 + s.size.z(), z0,
           Material::kSign, Material::kSign, -1, 0.9f);
  }
  for (const Box& c : scene.parked_cars) {
    const float albedo = static_cast<float>(rng.Uniform(0.1, 0.7));
    const double z = c.center.z();
    AddBox(mesh, c.center.head<2>(), c.yaw, c.size.x(), c.size.y(), z + 0.25, z + 0.95, z,
           Material::kCar, Material::kCar, -1, albedo);
    AddBox(mesh, c.center.head<2>(), c.yaw, c.size.x() * 0.55, c.size.y() * 0.9, z + 0.95,
           z + c.size.z(), z, Material::kCar, Material::kCar, -1, albedo * 0.6f);
  }
  for (const Plant& p : scene.plants) {
    if (p.tree) {
      const double ground = scene.terrain.Height(p.center.x(), p.center.y());
      AddPrism(mesh, Eigen::Vector3d(p.center.x(), p.center.y(), ground - 0.2), 0.18,
               p.center.z() - ground, Material::kTrunk, 0.35f);
    }
    if (scene.options.foliage_density > 0) {
      Rng leaves(rng.Next());  // One stream per plant: its clumps do not shift the others.
      AddFoliage(mesh, p.center, p.radius, scene.options.foliage_density,
                 static_cast<float>(leaves.Uniform(0.3, 0.5)), leaves);
    } else {
      AddBlob(mesh, p.center, p.radius, rng);
    }
  }
}

}  // namespace jvl::sim
