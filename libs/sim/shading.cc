#include "sim/shading.h"

#include <algorithm>
#include <cmath>

#include "sim/random.h"

namespace jvl::sim {
namespace {

double Fract(double x) { return x - std::floor(x); }

// Value noise of the given frequency (1/m) minus its mean 0.5, faded out where its cells (1 /
// frequency) span less than four footprints and gone below two: finer detail averages out
// within one sample.
double Octave(double x, double y, double frequency, uint64_t seed, double footprint) {
  const double cells = 1.0 / (frequency * std::max(footprint, 1e-9));  // Footprints per cell.
  const double fade = std::clamp(0.5 * cells - 1.0, 0.0, 1.0);
  if (fade == 0.0) return 0.0;
  return fade * (ValueNoise(x * frequency, y * frequency, seed) - 0.5);
}

// Road surface in route coordinates (s along, lat to the left of the centre line).
Surface ShadeGround(const Scene& scene, const Eigen::Vector3d& p, double footprint) {
  const uint64_t seed = scene.options.seed;
  Surface out;
  double s = 0, lat = 0;
  scene.route.Project(p.head<2>(), &s, &lat);
  const double hw = scene.options.road_half_width, a = std::abs(lat);
  const double fine = Octave(p.x(), p.y(), 7, seed + 1, footprint);
  const double coarse = Octave(p.x(), p.y(), 0.6, seed + 2, footprint);
  if (a <= hw) {
    out.albedo = static_cast<float>(0.22 + 0.07 * coarse + 0.05 * fine);
    out.reflectance = 0.12f;
    bool mark = std::abs(a - 3.5) < 0.08;                     // Solid lane edge lines.
    mark = mark || (a < 0.07 && Fract(s / 9.0) < 1.0 / 3.0);  // Dashed centre line 3 m / 6 m.
    // Zebra crossings 6-10 m before every sharp corner.
    const auto [first, last] = scene.route.PiecesStartingIn(s + 6, s + 10);
    for (size_t i = first; i < last; ++i) {
      const RoadPiece& piece = scene.route.pieces()[i];
      if (piece.IsStraight() || std::abs(piece.curvature) < 0.05) continue;
      if (a < 3.3 && Fract((lat + 10) / 1.0) < 0.5) mark = true;
    }
    if (mark) {
      out.albedo = static_cast<float>(0.82 + 0.04 * fine);
      out.reflectance = 0.55f;
      out.marking = true;
    }
  } else if (a <= hw + scene.options.sidewalk_width) {
    // Paving slabs 0.6 m with darker joints: a grid of corners for the feature detector.
    const double u = s / 0.6, w = (a - hw) / 0.6;
    const bool joint = Fract(u) < 0.07 || Fract(w) < 0.07;
    const double tile = HashUnit(static_cast<int64_t>(std::floor(u)),
                                 static_cast<int64_t>(std::floor(w)), seed + 3);
    out.albedo = static_cast<float>(joint ? 0.3 : 0.48 + 0.08 * tile + 0.03 * fine);
    out.reflectance = 0.25f;
  } else {
    out.albedo = static_cast<float>(0.32 + 0.14 * coarse + 0.08 * fine +
                                    0.06 * Octave(p.x(), p.y(), 2, seed + 4, footprint));
    out.reflectance = 0.2f;
  }
  return out;
}

// Facade: floors with a ledge, a window grid with bright frames and dark glass, shop windows
// on the ground floor (Sec. 4.3 relies on such lines parallel to the road and vertical).
Surface ShadeFacade(const Scene& scene, const Face& f, const Eigen::Vector3d& p, double footprint) {
  const Building& b = scene.buildings[f.object];
  const Eigen::Vector3f q = p.cast<float>() - f.origin;
  const double u = q.dot(f.u), v = q.dot(f.v);
  const uint64_t seed = scene.options.seed + static_cast<uint64_t>(f.object) * 7919;
  Surface out;
  out.reflectance = 0.3f;
  double albedo = b.albedo * (0.93 + 0.12 * Octave(u, v, 1.3, seed, footprint) +
                              0.08 * Octave(u, v, 9, seed + 1, footprint));
  const int floor = static_cast<int>(std::floor(v / b.floor_height));
  const double fv = v - floor * b.floor_height;
  const double margin = 1.2;
  const double usable = f.width - 2 * margin;
  const int cols =
      static_cast<int>(std::floor((usable + b.window_spacing - b.window_width) / b.window_spacing));
  const double offset = margin + 0.5 * (usable - (cols - 1) * b.window_spacing - b.window_width);
  const double cu = (u - offset) / b.window_spacing;
  const int col = static_cast<int>(std::floor(cu));
  const double fu = (cu - col) * b.window_spacing;
  if (v >= 0 && floor >= 0 && floor < b.floors && col >= 0 && col < cols && cols > 0) {
    const bool shop = floor == 0;
    const double w = shop ? std::min(b.window_spacing - 0.5, 2.6) : b.window_width;
    const double sill = shop ? 0.5 : 0.9, h = shop ? 2.0 : b.window_height;
    if (fu < w && fv >= sill && fv < sill + h) {
      const double frame = 0.09;
      if (fu < frame || fu > w - frame || fv < sill + frame || fv > sill + h - frame) {
        albedo = 0.88;
      } else {
        albedo = 0.08 + 0.3 * HashUnit(col, floor, seed + 2) * HashUnit(col, floor, seed + 3);
        out.glass = true;
        out.reflectance = 0.05f;
      }
    } else if (fv < 0.22 && floor > 0) {
      albedo *= 0.72;  // Floor ledge.
    }
  }
  if (v > b.height - 0.5) albedo = std::min(1.0, albedo * 1.25);  // Parapet.
  out.albedo = static_cast<float>(std::clamp(albedo, 0.0, 1.0));
  return out;
}

}  // namespace

Surface ShadeSurface(const Scene& scene, const Hit& hit, const Eigen::Vector3d& p,
                     double footprint) {
  Surface out;
  if (hit.dynamic >= 0) {
    out.albedo = static_cast<float>(0.15 + 0.2 * (hit.dynamic % 3));
    out.reflectance = 0.35f;
    return out;
  }
  if (hit.face < 0) return out;
  const Face& f = scene.mesh.faces[hit.face];
  auto noise = [&] {
    return 0.5 + Octave(p.x(), p.y() + p.z(), 4, scene.options.seed + 9, footprint);
  };
  switch (f.material) {
    case Material::kGround:
      return ShadeGround(scene, p, footprint);
    case Material::kFacade:
      return ShadeFacade(scene, f, p, footprint);
    case Material::kRoof:
      out.albedo = 0.35f;
      out.reflectance = 0.25f;
      break;
    case Material::kKerb:
      out.albedo = static_cast<float>(0.68 + 0.1 * (noise() - 0.5));
      out.reflectance = 0.4f;
      break;
    case Material::kPole:
      out.albedo = 0.5f;
      out.reflectance = 0.4f;
      break;
    case Material::kSign: {
      const Eigen::Vector3f q = p.cast<float>() - f.origin;
      const double u = q.dot(f.u), v = q.dot(f.v);
      const bool border = u < 0.08 || v < 0.08 || v > 0.67 || (f.width > 0.3 && u > f.width - 0.08);
      out.albedo = border ? 0.15f : 0.92f;
      out.reflectance = 0.95f;
      break;
    }
    case Material::kCar:
      out.albedo = f.albedo;
      out.reflectance = 0.35f;
      break;
    case Material::kFoliage:
      out.albedo = static_cast<float>(f.albedo * (0.55 + 0.9 * noise()));
      out.reflectance = 0.25f;
      break;
    case Material::kTrunk:
      out.albedo = 0.28f;
      out.reflectance = 0.3f;
      break;
  }
  return out;
}

}  // namespace jvl::sim
