#pragma once
// Plane contours whose shape is known by hand, for the target-shape tests: a straight line and a
// hairpin after a crossing.
#include <cmath>
#include <numbers>
#include <tuple>

#include "wiresculpt/geometry.hpp"

namespace fixtures {

using wiresculpt::Polyline2;
using wiresculpt::Vec2;

/// `n` points evenly from the origin along +x to `length`.
inline Polyline2 line(double length, int n) {
  Polyline2 pts;
  for (int k = 0; k < n; ++k) pts.emplace_back(length * k / (n - 1), 0.0);
  return pts;
}

/// A hairpin right after crossing A at the origin: the wire comes along +x from -tail, runs 18 mm
/// past A, turns back by 140° and meets crossing B 21 mm later, then runs on for `tail` metres;
/// contour points every 1 mm. Returns the contour and the vertices of A and B.
inline std::tuple<Polyline2, int, int> hairpin(double tail) {
  constexpr double pi = std::numbers::pi;
  Polyline2 contour;
  auto run = [&](Vec2 a, Vec2 b) {
    const int n = static_cast<int>(std::lround((b - a).norm() / 0.001));
    for (int k = 1; k <= n; ++k) contour.push_back(a + (b - a) * (static_cast<double>(k) / n));
  };
  const Vec2 d2(std::cos(140.0 * pi / 180.0), std::sin(140.0 * pi / 180.0));
  const Vec2 corner(0.018, 0.0), b = corner + 0.021 * d2;
  contour.push_back({-tail, 0.0});
  run({-tail, 0.0}, {0.0, 0.0});
  const int a_vertex = static_cast<int>(contour.size()) - 1;
  run({0.0, 0.0}, corner);
  run(corner, b);
  const int b_vertex = static_cast<int>(contour.size()) - 1;
  run(b, b + tail * d2);
  return {contour, a_vertex, b_vertex};
}

}  // namespace fixtures
