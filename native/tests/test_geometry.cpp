// Geometry helpers against answers known by hand.
#include <catch2/catch.hpp>

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
