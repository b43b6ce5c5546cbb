// Crossings of wires whose meeting points are known by hand: circles of one sphere.
#include <cstdio>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "wiresculpt/error.hpp"
#include "wiresculpt/network.hpp"
#include "wire_fixtures.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;
using fixtures::Cut;

namespace {
constexpr double pi = std::numbers::pi;
constexpr double R = 0.1;

WireSpec plain_circle(const std::string& name, Vec3 n, double h, int count, double phase) {
  return fixtures::circle_wire(Cut{name, n, h}, R, count, {}, phase);
}
}  // namespace

TEST_CASE("network: two great circles cross twice, inserted exactly on both planes") {
  // Half-step phase: the common line (the z axis) meets both polygons mid-edge, at the chord
  // midpoints (0, 0, ±R cos(pi/n)), the same for both circles by symmetry.
  const int n = 60;
  const auto a = plain_circle("X", Vec3::UnitX(), 0.0, n, pi / n);
  const auto b = plain_circle("Y", Vec3::UnitY(), 0.0, n, pi / n);
  // Which side the frame puts the poles on does not matter: both circles are symmetric.
  const Network net = build_network({a, b});
  REQUIRE(net.crossings.size() == 2);
  CHECK(net.warnings.empty());
  const double z = R * std::cos(pi / n);
  std::vector<double> zs;
  for (const auto& c : net.crossings) {
    CHECK(c.wires == std::array<int, 2>{0, 1});
    CHECK(std::abs(c.point.x()) < 1e-15);
    CHECK(std::abs(c.point.y()) < 1e-15);
    zs.push_back(c.point.z());
    for (int k = 0; k < 2; ++k) {
      const WireSpec& w = net.wires[c.wires[k]];
      CHECK(w.points[c.vertices[k]] == c.point);  // the same point, bit for bit
      CHECK(std::abs(net.wires[0].plane.signed_distance(c.point)) < 1e-15);
      CHECK(std::abs(net.wires[1].plane.signed_distance(c.point)) < 1e-15);
    }
  }
  std::sort(zs.begin(), zs.end());
  CHECK(zs[0] == Approx(-z).epsilon(1e-12));
  CHECK(zs[1] == Approx(z).epsilon(1e-12));
  // Two new vertices per wire, the others untouched.
  CHECK(net.wires[0].points.size() == static_cast<std::size_t>(n + 2));
  CHECK(net.wires[1].points.size() == static_cast<std::size_t>(n + 2));
  // Sorted along the common line d = n0 x n1 = +z.
  CHECK(net.crossings[0].point.z() < net.crossings[1].point.z());
  CHECK(net.crossings_of(0).size() == 2);
  CHECK(net.close_crossings.empty());
}

TEST_CASE("network: a crossing at an existing vertex replaces it instead of adding one") {
  const int n = 64;  // phase 0: the poles (0, 0, ±R) are vertices of both circles
  const Network net = build_network({plain_circle("X", Vec3::UnitX(), 0.0, n, 0.0),
                                     plain_circle("Y", Vec3::UnitY(), 0.0, n, 0.0)});
  REQUIRE(net.crossings.size() == 2);
  CHECK(net.wires[0].points.size() == static_cast<std::size_t>(n));
  CHECK(net.wires[1].points.size() == static_cast<std::size_t>(n));
  for (const auto& c : net.crossings) {
    CHECK(std::abs(std::abs(c.point.z()) - R) < 1e-15);
    CHECK(net.wires[0].points[c.vertices[0]] == c.point);
    CHECK(net.wires[1].points[c.vertices[1]] == c.point);
  }
}

TEST_CASE("network: three great circles have six crossings on the axes") {
  const Network net = build_network(fixtures::sphere_wires(fixtures::great_circle_cuts(), R));
  REQUIRE(net.crossings.size() == 6);
  for (const auto& c : net.crossings) {
    // On the axis common to both planes, at distance R from the centre.
    int axis = 3 - c.wires[0] - c.wires[1];
    CHECK(std::abs(std::abs(c.point[axis]) - R) < 1e-15);
    CHECK(c.point.norm() == Approx(R).epsilon(1e-14));
  }
}

TEST_CASE("network: wires of parallel planes never cross") {
  const Network net = build_network({plain_circle("low", Vec3::UnitZ(), -0.03, 48, 0.0),
                                     plain_circle("high", Vec3::UnitZ(), 0.02, 48, 0.0)});
  CHECK(net.crossings.empty());
  CHECK(net.warnings.empty());
}

TEST_CASE("network: a wire that only touches the other plane makes a warning, not a crossing") {
  // Circle A in z = 0 touches the plane x = R at (R, 0, 0). Circle B in x = R, centred at
  // (R, r, 0), passes through (R, 0, 0) crossing z = 0 there; A merely touches B's plane.
  const double r = 0.03;
  WireSpec a = plain_circle("A", Vec3::UnitZ(), 0.0, 64, 0.0);
  const Plane pb = Plane::make({R, 0, 0}, Vec3::UnitX());
  WireSpec b;
  b.name = "B";
  b.plane = pb;
  for (int k = 0; k < 40; ++k) {
    const double phi = pi + 2 * pi * k / 40;  // k = 0 is exactly (R, 0, 0)
    b.points.push_back(Vec3(R, r + r * std::cos(phi), r * std::sin(phi)));
  }
  b.points[0] = Vec3(R, 0, 0);
  // A's frame: make sure (R, 0, 0) is a vertex of A.
  bool has = false;
  for (auto& p : a.points)
    if ((p - Vec3(R, 0, 0)).norm() < 1e-12) {
      p = Vec3(R, 0, 0);
      has = true;
    }
  REQUIRE(has);
  const Network net = build_network({a, b});
  CHECK(net.crossings.empty());
  REQUIRE(net.warnings.size() == 1);
  CHECK_THAT(net.warnings[0], Contains("'A'") && Contains("'B'") && Contains("without crossing") &&
                                  Contains("touches"));
}

TEST_CASE("network: an open wire ending on another wire makes a warning, not a crossing") {
  // Open wire V in the plane y = 0 runs from (0.05, 0, R) to end exactly at (0, 0, R), the top
  // of great circle X (plane x = 0), which crosses V's plane there.
  const WireSpec x = plain_circle("X", Vec3::UnitX(), 0.0, 64, 0.0);
  WireSpec v;
  v.name = "V";
  v.plane = Plane::make({0, 0, 0}, Vec3::UnitY());
  v.closed = false;
  for (int k = 5; k >= 0; --k) v.points.push_back(Vec3(0.01 * k, 0, R));
  const Network net = build_network({x, v});
  CHECK(net.crossings.empty());
  REQUIRE(net.warnings.size() == 1);
  CHECK_THAT(net.warnings[0], Contains("'V' ends on") && Contains("without crossing"));
}

TEST_CASE("network: two wires of one plane that touch are an input error naming both") {
  const WireSpec a = plain_circle("left", Vec3::UnitZ(), 0.0, 48, 0.0);
  WireSpec b = a;
  b.name = "right";
  for (auto& p : b.points) p.x() += 0.15;  // overlapping discs: the circles cross twice
  CHECK_THROWS_AS(build_network({a, b}), InputError);
  CHECK_THROWS_WITH(build_network({a, b}), Contains("'left'") && Contains("'right'") && Contains("same plane"));
  for (auto& p : b.points) p.x() += 0.15;  // now far apart: fine, and no crossings
  CHECK(build_network({a, b}).crossings.empty());
}

TEST_CASE("network: three wires through one point are an input error naming the three") {
  // Three planes through the z axis: all three great circles pass through the poles.
  const std::vector<Cut> cuts{{"P", Vec3::UnitX(), 0.0}, {"Q", Vec3::UnitY(), 0.0},
                              {"S", Vec3(1, 1, 0).normalized(), 0.0}};
  const auto wires = fixtures::sphere_wires(cuts, R);
  CHECK_THROWS_AS(build_network(wires), InputError);
  CHECK_THROWS_WITH(build_network(wires), Contains("'P'") && Contains("'Q'") && Contains("'S'") &&
                                              Contains("one point"));
}

TEST_CASE("network: crossings closer than the minimum segment are reported with the scale needed") {
  // The scale gives room for a free bending point between them: twice 15 mm along the wire.
  // Great circle G (x = 0) and a small circle near the pole (z = h, radius rho = 4 mm): they meet
  // at (0, ±rho, h), 2 R asin(rho / R) apart along G and pi rho apart (both ways) along the
  // small circle; both less than 15 mm.
  const double rho = 0.004, h = std::sqrt(R * R - rho * rho);
  const std::vector<Cut> cuts{{"G", Vec3::UnitX(), 0.0}, {"cap", Vec3::UnitZ(), h}};
  const Network net = build_network(fixtures::sphere_wires(cuts, R, 2000));
  REQUIRE(net.crossings.size() == 2);
  const double along_g = 2 * R * std::asin(rho / R);
  const double along_cap = pi * rho;
  int on_g = 0, on_cap = 0;
  for (const auto& g : net.close_crossings) {
    if (g.wire == 0) {
      ++on_g;
      CHECK(g.distance == Approx(along_g).epsilon(1e-4));
      CHECK(g.scale == Approx(0.030 / along_g).epsilon(1e-4));
      char advice[96];  // 0.03 / 0.0080000 = 3.75: the size 0.2 m of both circles' box grows to 0.75 m
      std::snprintf(advice, sizeof advice, "scale the model up at least %.2f times (largest side 0.2 m -> %.4g m)",
                    0.030 / along_g, 0.2 * 0.030 / along_g);
      CHECK_THAT(g.message, Contains("'G'") && Contains("crossings") && Contains(advice));
    } else {
      ++on_cap;
      CHECK(g.distance == Approx(along_cap).epsilon(1e-3));
    }
  }
  CHECK(on_g == 1);   // the long way round G is far more than 15 mm
  CHECK(on_cap == 2); // both ways round the cap are short
  CHECK(net.min_scale == Approx(0.030 / along_g).epsilon(1e-4));
  CHECK(net.size == Approx(2 * R).epsilon(1e-6));
  CHECK(net.required_size == Approx(net.size * net.min_scale));

  NetworkOptions loose;
  loose.min_segment = 0.01;  // now the cap's gaps (12.6 mm) pass, G's 8 mm does not
  const Network net2 = build_network(fixtures::sphere_wires(cuts, R, 2000), loose);
  REQUIRE(net2.close_crossings.size() == 1);
  CHECK(net2.close_crossings[0].wire == 0);
}

TEST_CASE("network: bad wires are input errors naming the wire") {
  WireSpec w = plain_circle("bent", Vec3::UnitZ(), 0.0, 16, 0.0);
  w.points[3].z() += 0.001;
  CHECK_THROWS_WITH(build_network({w}), Contains("'bent'") && Contains("point 3") && Contains("off"));
  // just off, by 0.1 nm more than the 10 um tolerance: both read 1e-05 m with four significant digits
  WireSpec just = plain_circle("just", Vec3::UnitZ(), 0.0, 16, 0.0);
  just.points[3].z() = 1.00000001e-5;
  CHECK_THROWS_WITH(build_network({just}),
                    Contains("point 3 is 1.00000001e-05 m off the wire's plane (more than the tolerance 1e-05 m)"));
  WireSpec few;
  few.name = "stub";
  few.plane = Plane::make({0, 0, 0}, {0, 0, 1});
  few.points = {Vec3(0, 0, 0), Vec3(0.1, 0, 0)};
  CHECK_THROWS_WITH(build_network({few}), Contains("'stub'") && Contains("at least 3"));
  few.closed = false;
  CHECK_NOTHROW(build_network({few}));
  few.points[1].x() = std::nan("");
  CHECK_THROWS_WITH(build_network({few}), Contains("'stub'") && Contains("non-finite"));
}

TEST_CASE("network: a vertex just off the other plane on a shallow crossing still makes the crossing there") {
  // Wire A (plane z = 0) crosses x = 0 transversally at y = -0.05 and, near the top, at a shallow
  // slope (1:100) through a vertex V 9.6 um from x = 0 (inside the 10 um tolerance): the wire meets
  // the plane at y = 0.11 exactly, 0.96 mm along the line from V. Wire B (plane x = 0) crosses
  // z = 0 at y = -0.05 and y = 0.11.
  WireSpec a;
  a.name = "A";
  a.plane = Plane::make({0, 0, 0}, {0, 0, 1});
  a.points = {{-0.05, -0.05, 0}, {0.05, -0.05, 0}, {0.05, 0.05, 0}, {0.0003, 0.08, 0},
              {0.0000096, 0.10904, 0}, {-0.0003, 0.14, 0}, {-0.05, 0.05, 0}};
  WireSpec b;
  b.name = "B";
  b.plane = Plane::make({0, 0, 0}, {1, 0, 0});
  b.points = {{0, -0.05, -0.03}, {0, -0.05, 0.03}, {0, 0.11, 0.03}, {0, 0.11, -0.03}};
  const Network net = build_network({a, b});
  REQUIRE(net.crossings.size() == 2);
  CHECK(net.crossings[0].point.isApprox(Vec3(0, -0.05, 0), 1e-12));
  CHECK((net.crossings[1].point - Vec3(0, 0.11, 0)).norm() < 1e-9);
  // inserted into A as a new vertex on the edge V -> (-0.0003, 0.14); V itself stays
  const Vec3 v = net.wires[0].points[static_cast<std::size_t>(net.crossings[1].vertices[0])];
  CHECK((v - Vec3(0, 0.11, 0)).norm() < 1e-9);
  bool kept = false;
  for (const Vec3& p : net.wires[0].points) kept = kept || (p - Vec3(0.0000096, 0.10904, 0)).norm() < 1e-12;
  CHECK(kept);
}
