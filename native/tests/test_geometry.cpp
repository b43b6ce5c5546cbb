// Geometry helpers against answers known by hand.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "wiresculpt/geometry.hpp"

using namespace wiresculpt;

TEST_CASE("geometry: polyline_length of a 3 x 4 rectangle, open and closed, in 2D and 3D") {
  const Polyline2 flat{{0, 0}, {3, 0}, {3, 4}, {0, 4}};
  CHECK(polyline_length(flat, false) == Approx(10.0));
  CHECK(polyline_length(flat, true) == Approx(14.0));
  Polyline3 tilted;
  for (const Vec2& p : flat) tilted.emplace_back(p.x(), 0.0, p.y());
  CHECK(polyline_length(tilted, false) == Approx(10.0));
  CHECK(polyline_length(tilted, true) == Approx(14.0));
  CHECK(polyline_length(Polyline2{{1, 2}}, true) == 0.0);
  CHECK(polyline_length(Polyline2{}, true) == 0.0);
}

TEST_CASE("geometry: largest_box_side over several polylines") {
  // One polyline spans x in [-1, 2]; the other y in [0.5, 5] and z in [0, 1]: the box is 3 x 4.5 x 1.
  const Polyline3 a{{-1.0, 1.0, 0.0}, {2.0, 1.0, 0.5}};
  const Polyline3 b{{0.0, 0.5, 1.0}, {0.5, 5.0, 0.25}, {0.0, 2.0, 0.0}};
  CHECK(largest_box_side({a, b}) == 4.5);
  CHECK(largest_box_side({a}) == 3.0);  // x spans 3, y nothing, z 0.5
  CHECK(largest_box_side({}) == 0.0);
  CHECK(largest_box_side({Polyline3{}, a}) == 3.0);
  const Polyline3 bad{{0.0, std::nan(""), 0.0}};
  CHECK(std::isnan(largest_box_side({a, bad})));
}

TEST_CASE("geometry: largest_box_side is NaN where a side is inf - inf, as numpy's model size") {
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(std::isnan(largest_box_side({Polyline3{{0.0, 0.0, inf}, {1.0, 5.0, inf}}})));
  CHECK(largest_box_side({Polyline3{{0.0, 0.0, 0.0}, {1.0, 5.0, inf}}}) == inf);
}
