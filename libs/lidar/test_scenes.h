// Test-only synthetic scenes in the cam0 convention (y down, ground at y = +1.7 m): a street
// with facades and a few objects, and a featureless corridor.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace jvl::lidar::testing {

inline void AddRect(const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                    const Eigen::Vector3d& v, double step, std::vector<Eigen::Vector3d>* pts) {
  const int nu = static_cast<int>(u.norm() / step), nv = static_cast<int>(v.norm() / step);
  for (int i = 0; i <= nu; ++i) {
    for (int j = 0; j <= nv; ++j) {
      pts->push_back(origin + u * (static_cast<double>(i) / nu) +
                     v * (static_cast<double>(j) / nv));
    }
  }
}

// Street along z: ground, two facades with recesses, a cross wall, a box and a pole.
inline std::vector<Eigen::Vector3d> StreetScene(double step) {
  std::vector<Eigen::Vector3d> p;
  AddRect({-10, 1.7, -30}, {20, 0, 0}, {0, 0, 70}, step, &p);  // Ground.
  AddRect({-8, -6, -30}, {0, 0, 25}, {0, 7.7, 0}, step, &p);   // Left facade...
  AddRect({-9, -6, -5}, {0, 0, 10}, {0, 7.7, 0}, step, &p);    // ... recessed part ...
  AddRect({-9, -6, -5}, {1, 0, 0}, {0, 7.7, 0}, step, &p);     // ... and its side walls.
  AddRect({-9, -6, 5}, {1, 0, 0}, {0, 7.7, 0}, step, &p);
  AddRect({-8, -6, 5}, {0, 0, 35}, {0, 7.7, 0}, step, &p);
  AddRect({9, -6, -30}, {0, 0, 70}, {0, 7.7, 0}, step, &p);  // Right facade.
  AddRect({-8, -6, 38}, {17, 0, 0}, {0, 7.7, 0}, step, &p);  // Cross wall ahead.
  AddRect({3, -1.3, 12}, {2, 0, 0}, {0, 3, 0}, step, &p);    // Box, front face...
  AddRect({3, -1.3, 12}, {0, 0, 2}, {0, 3, 0}, step, &p);    // ... side face ...
  AddRect({3, -1.3, 12}, {2, 0, 0}, {0, 0, 2}, step, &p);    // ... top.
  for (double y = -4; y <= 1.7; y += step) {                 // Pole of radius 0.3.
    for (double a = 0; a < 2 * M_PI; a += step / 0.3) {
      p.emplace_back(-5 + 0.3 * std::cos(a), y, 20 + 0.3 * std::sin(a));
    }
  }
  return p;
}

// A straight corridor along z (160 m, longer than the scan range): floor, ceiling and two
// walls, nothing else.
inline std::vector<Eigen::Vector3d> CorridorScene(double step) {
  std::vector<Eigen::Vector3d> p;
  AddRect({-3, 1.7, -80}, {6, 0, 0}, {0, 0, 160}, step, &p);
  AddRect({-3, -2.5, -80}, {6, 0, 0}, {0, 0, 160}, step, &p);
  AddRect({-3, -2.5, -80}, {0, 4.2, 0}, {0, 0, 160}, step, &p);
  AddRect({3, -2.5, -80}, {0, 4.2, 0}, {0, 0, 160}, step, &p);
  return p;
}

}  // namespace jvl::lidar::testing
