#include "sim/raycaster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sim/sequence.h"

namespace jvl::sim {
namespace {

// The nearest hit by testing every triangle (double-precision Moeller-Trumbore, the lower index
// on an exact tie): what the BVH must return, bit for bit.
Hit BruteForce(const Mesh& mesh, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
               double t_max) {
  Hit best;
  best.t = t_max;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const Eigen::Vector3f& af = mesh.vertices[mesh.triangles[i][0]];
    const Eigen::Vector3d a = af.cast<double>();
    const Eigen::Vector3d e1 = mesh.vertices[mesh.triangles[i][1]].cast<double>() - a;
    const Eigen::Vector3d e2 = mesh.vertices[mesh.triangles[i][2]].cast<double>() - a;
    const Eigen::Vector3d p(d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                            d[0] * e2[1] - d[1] * e2[0]);
    const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (!(std::abs(det) >= 1e-30)) continue;
    const double inv = 1.0 / det;
    const Eigen::Vector3d s = o - a;
    const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q(s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                            s[0] * e1[1] - s[1] * e1[0]);
    const double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
    if (v < 0 || u + v > 1) continue;
    const double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    if (!(t > t_min)) continue;
    if (t < best.t || (t == best.t && static_cast<int32_t>(i) < best.triangle)) {
      best.t = t;
      best.triangle = static_cast<int32_t>(i);
    }
  }
  if (best.triangle < 0) best.t = std::numeric_limits<double>::infinity();
  return best;
}

// A scene with what makes a BVH hard: a coplanar grid of quads (ties on shared edges), long thin
// triangles, boxes, and random triangles of every size, some coincident.
Mesh HardMesh(std::mt19937& rng) {
  Mesh mesh;
  const uint32_t face = mesh.AddFace(Face());
  std::uniform_real_distribution<double> pos(-60, 60), size(0.01, 8), unit(-1, 1);
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      const uint32_t a = mesh.AddVertex({i * 2.0 - 40, j * 2.0 - 40, 0});
      const uint32_t b = mesh.AddVertex({i * 2.0 - 38, j * 2.0 - 40, 0});
      const uint32_t c = mesh.AddVertex({i * 2.0 - 38, j * 2.0 - 38, 0});
      const uint32_t e = mesh.AddVertex({i * 2.0 - 40, j * 2.0 - 38, 0});
      mesh.AddTriangle(a, b, c, face);
      mesh.AddTriangle(a, c, e, face);
    }
  }
  for (int k = 0; k < 3000; ++k) {
    const Eigen::Vector3d c(pos(rng), pos(rng), 0.5 * (pos(rng) + 60));
    const double s = size(rng);
    const uint32_t a = mesh.AddVertex(c + s * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    const uint32_t b = mesh.AddVertex(c + s * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    const uint32_t e =
        k % 7 == 0 ? mesh.AddVertex(c + 40 * Eigen::Vector3d::UnitX())
                   : mesh.AddVertex(c + s * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    mesh.AddTriangle(a, b, e, face);
    if (k % 50 == 0) mesh.AddTriangle(a, b, e, face);  // A coincident copy: an exact tie.
  }
  return mesh;
}

TEST(RayCasterTest, ReturnsTheNearestHitOfABruteForceSearchExactly) {
  std::mt19937 rng(5);
  const Mesh mesh = HardMesh(rng);
  const RayCaster caster(mesh);
  std::uniform_real_distribution<double> pos(-50, 50), unit(-1, 1);
  int hits = 0;
  for (int r = 0; r < 4000; ++r) {
    const Eigen::Vector3d o(pos(rng), pos(rng), r % 4 == 0 ? 1e-3 : 0.3 * (pos(rng) + 50));
    Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
    if (r % 10 == 0) d.z() = 0;  // Parallel to the ground grid.
    if (r % 13 == 0) d.x() = 0;  // Along an axis plane of the boxes.
    if (d.norm() < 1e-3) d = Eigen::Vector3d::UnitZ();
    d.normalize();
    const Hit expected = BruteForce(mesh, o, d, 0.05, 200);
    const Hit hit = caster.Intersect(o, d, 0.05, 200);
    ASSERT_EQ(hit.triangle, expected.triangle) << "ray " << r;
    if (expected.triangle < 0) continue;
    ++hits;
    ASSERT_EQ(hit.t, expected.t) << "ray " << r;
    EXPECT_EQ(hit.face, static_cast<int32_t>(mesh.triangle_face[expected.triangle]));
    EXPECT_NEAR(hit.normal.norm(), 1.0, 1e-12);
    EXPECT_LE(hit.normal.dot(d), 0.0);  // Facing the ray's origin.
    // Any hint, right or wrong, gives the same answer.
    const int32_t hint = static_cast<int32_t>(rng() % mesh.triangles.size());
    const Hit hinted = caster.Intersect(o, d, 0.05, 200, r % 2 ? hint : expected.triangle);
    ASSERT_EQ(hinted.triangle, expected.triangle) << "ray " << r;
    ASSERT_EQ(hinted.t, expected.t) << "ray " << r;
  }
  EXPECT_GT(hits, 2000);  // The scene is hit often enough to mean something.
}

// Rays through the shared diagonal and edges of the coplanar ground quads: the hit is on the
// ground at the same distance whichever triangle reports it, and the answer is the brute force's.
TEST(RayCasterTest, RaysThroughSharedEdgesHitTheGround) {
  std::mt19937 rng(9);
  const Mesh mesh = HardMesh(rng);
  const RayCaster caster(mesh);
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      // Straight down onto a vertex, an edge midpoint and the diagonal of quad (i, j).
      for (const Eigen::Vector2d& p : {Eigen::Vector2d(i * 2.0 - 40, j * 2.0 - 40),
                                       Eigen::Vector2d(i * 2.0 - 39, j * 2.0 - 40),
                                       Eigen::Vector2d(i * 2.0 - 39.5, j * 2.0 - 39.5)}) {
        const Eigen::Vector3d o(p.x(), p.y(), 0.5);
        const Eigen::Vector3d d = -Eigen::Vector3d::UnitZ();
        const Hit expected = BruteForce(mesh, o, d, 0.05, 200);
        const Hit hit = caster.Intersect(o, d, 0.05, 200);
        ASSERT_EQ(hit.triangle, expected.triangle);
        ASSERT_TRUE(hit.valid());
        EXPECT_LE(hit.t, 0.5);
      }
    }
  }
}

// Eight rays at a time give what the rays give one by one (the hint chain changes nothing).
TEST(RayCasterTest, EightRaysAtATimeAnswerAsOneByOne) {
  SequenceOptions opt;
  opt.frames = 5;
  opt.seed = 3;
  const std::unique_ptr<World> world = BuildWorld(opt);
  const RayCaster& caster = *world->caster;
  const Eigen::Vector3d o(0, 0, 1.7);
  for (int row = 0; row < 50; ++row) {
    Eigen::Vector3d d[8];
    for (int k = 0; k < 8; ++k) {
      const double az = 0.05 * (row * 8 + k), el = -0.3 + 0.012 * row;
      d[k] =
          Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    }
    Hit eight[8];
    caster.Intersect8(o, d, 8, 0.05, 300, eight, 17);
    for (int k = 0; k < 8; ++k) {
      const Hit one = caster.Intersect(o, d[k], 0.05, 300);
      ASSERT_EQ(eight[k].triangle, one.triangle) << row << " " << k;
      ASSERT_EQ(eight[k].t, one.t);
      ASSERT_EQ(eight[k].normal, one.normal);
    }
  }
}

}  // namespace
}  // namespace jvl::sim
