// Slicing against shapes whose cross-sections are known by hand.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "wiresculpt/error.hpp"
#include "wiresculpt/shapes.hpp"
#include "wiresculpt/slicing.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;

namespace {
constexpr double pi = std::numbers::pi;

std::vector<Contour> cut(const RawMesh& m, Vec3 origin, Vec3 normal) {
  return slice(prepare_mesh(m.V, m.F), Plane::make(origin, normal));
}

Vec3 centroid(const Contour& c) {
  Vec3 s = Vec3::Zero();
  for (const auto& p : c.points) s += p;
  return s / static_cast<double>(c.points.size());
}

// An STL-like triangle soup: every triangle with its own three vertices.
RawMesh unshare(const RawMesh& m) {
  RawMesh soup;
  soup.V.resize(3 * m.F.rows(), 3);
  soup.F.resize(m.F.rows(), 3);
  for (Eigen::Index t = 0; t < m.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      soup.V.row(3 * t + k) = m.V.row(m.F(t, k));
      soup.F(t, k) = static_cast<int>(3 * t + k);
    }
  return soup;
}
}  // namespace

TEST_CASE("slicing: sphere at height z gives one circle of radius sqrt(R^2 - z^2)") {
  const double R = 0.1;
  const RawMesh sphere = uv_sphere(R, 128, 64);
  for (double z : {0.0, 0.031, -0.052, 0.08}) {
    const auto contours = cut(sphere, {0, 0, z}, {0, 0, 1});
    REQUIRE(contours.size() == 1);
    const Contour& c = contours[0];
    CHECK(c.closed);
    const double expected = 2 * pi * std::sqrt(R * R - z * z);
    CHECK(std::abs(c.length - expected) / expected < 0.005);
    for (const auto& p : c.points) CHECK(std::abs(p.z() - z) < 1e-12);
    CHECK(centroid(c).head<2>().norm() < 1e-3 * R);
  }
}

TEST_CASE("slicing: closed contours run counter-clockwise about the plane normal") {
  const RawMesh sphere = uv_sphere(1.0, 32, 16);
  for (Vec3 n : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 2, 3)}) {
    const Plane plane = Plane::make({0.1, 0, 0}, n);
    const auto contours = slice(prepare_mesh(sphere.V, sphere.F), plane);
    REQUIRE(contours.size() == 1);
    Polyline2 flat;
    for (const auto& p : contours[0].points) flat.push_back(plane.to_2d(p));
    CHECK(signed_area(flat) > 0);
  }
}

TEST_CASE("slicing: a torus cut through its axis gives two circles of the tube radius") {
  const double major = 0.3, minor = 0.1;
  const RawMesh t = torus(major, minor, 96, 96);
  const auto contours = cut(t, {0, 0, 0}, {0, 1, 0});
  REQUIRE(contours.size() == 2);
  for (const auto& c : contours) {
    CHECK(c.closed);
    CHECK(std::abs(c.length - 2 * pi * minor) / (2 * pi * minor) < 0.005);
    const Vec3 m = centroid(c);
    CHECK(std::abs(std::abs(m.x()) - major) < 1e-3);
    CHECK(std::abs(m.y()) < 1e-12);
  }
  CHECK(centroid(contours[0]).x() * centroid(contours[1]).x() < 0);
}

TEST_CASE("slicing: a torus cut across its axis gives the two circles R - r and R + r") {
  const RawMesh t = torus(0.3, 0.1, 128, 64);
  const auto contours = cut(t, {0, 0, 0}, {0, 0, 1});
  REQUIRE(contours.size() == 2);
  CHECK(contours[0].length > contours[1].length);  // longest first
  CHECK(std::abs(contours[0].length - 2 * pi * 0.4) / (2 * pi * 0.4) < 0.005);
  CHECK(std::abs(contours[1].length - 2 * pi * 0.2) / (2 * pi * 0.2) < 0.005);
}

TEST_CASE("slicing: a plane through three cube vertices gives the exact triangle") {
  const RawMesh cube = box(1, 1, 1);
  // x + y + z = 1 passes through (1,1,-1), (1,-1,1), (-1,1,1): an equilateral triangle of side 2*sqrt(2).
  const auto contours = cut(cube, {1, 0, 0}, {1, 1, 1});
  REQUIRE(contours.size() == 1);
  CHECK(contours[0].closed);
  CHECK(contours[0].length == Approx(6 * std::sqrt(2.0)).epsilon(1e-12));
}

TEST_CASE("slicing: a plane along two cube edges gives the diagonal rectangle") {
  const RawMesh cube = box(1, 1, 1);
  // x = y contains the edges x = y = +-1 and the diagonals of the z faces.
  const auto contours = cut(cube, {0, 0, 0}, {1, -1, 0});
  REQUIRE(contours.size() == 1);
  CHECK(contours[0].length == Approx(4 + 4 * std::sqrt(2.0)).epsilon(1e-12));
  const auto flipped = cut(cube, {0, 0, 0}, {-1, 1, 0});
  REQUIRE(flipped.size() == 1);
  CHECK(flipped[0].length == Approx(4 + 4 * std::sqrt(2.0)).epsilon(1e-12));
}

TEST_CASE("slicing: a plane that only touches a vertex or an edge gives no contour") {
  const RawMesh cube = box(1, 1, 1);
  CHECK(cut(cube, {1, 1, 1}, {1, 1, 1}).empty());     // corner, cube on the negative side
  CHECK(cut(cube, {-1, -1, -1}, {1, 1, 1}).empty());  // corner, cube on the positive side
  CHECK(cut(cube, {1, 1, 0}, {1, 1, 0}).empty());     // along an edge
  CHECK(cut(cube, {-1, -1, 0}, {1, 1, 0}).empty());
}

TEST_CASE("slicing: a plane that misses gives no contour and no error") {
  CHECK(cut(uv_sphere(1, 16, 8), {0, 0, 5}, {0, 0, 1}).empty());
  CHECK(cut(box(1, 1, 1), {3, 0, 0}, {1, 0, 0}).empty());
}

TEST_CASE("slicing: a triangle soup with duplicated vertices slices like the indexed mesh") {
  const RawMesh sphere = uv_sphere(0.2, 48, 24);
  const RawMesh soup = unshare(sphere);
  const TriMesh welded = prepare_mesh(soup.V, soup.F);
  CHECK(welded.V.rows() == sphere.V.rows());
  const auto a = cut(sphere, {0, 0, 0.05}, {0, 0.3, 1});
  const auto b = cut(soup, {0, 0, 0.05}, {0, 0.3, 1});
  REQUIRE(a.size() == 1);
  REQUIRE(b.size() == 1);
  CHECK(b[0].closed);
  CHECK(b[0].length == Approx(a[0].length).epsilon(1e-12));
}

TEST_CASE("slicing: degenerate and duplicate triangles are dropped") {
  RawMesh m = box(1, 1, 1);
  const Eigen::Index n = m.F.rows();
  m.F.conservativeResize(n + 3, 3);
  m.F.row(n) << 0, 0, 1;                          // collapsed to an edge
  m.F.row(n + 1) = m.F.row(0);                    // exact duplicate
  m.F.row(n + 2) << m.F(1, 2), m.F(1, 0), m.F(1, 1);  // duplicate in another order
  const TriMesh clean = prepare_mesh(m.V, m.F);
  CHECK(clean.dropped_degenerate == 1);
  CHECK(clean.dropped_duplicate == 2);
  const auto contours = slice(clean, Plane::make({0, 0, 0.5}, {0, 0, 1}));
  REQUIRE(contours.size() == 1);
  CHECK(contours[0].length == Approx(8.0).epsilon(1e-12));
}

TEST_CASE("slicing: an open boundary gives an open contour") {
  // Keep the upper half of a sphere: triangles whose vertices all have z >= 0.
  const RawMesh sphere = uv_sphere(1.0, 64, 32);
  RawMesh half;
  half.V = sphere.V;
  std::vector<int> keep;
  for (Eigen::Index t = 0; t < sphere.F.rows(); ++t) {
    bool upper = true;
    for (int k = 0; k < 3; ++k) upper = upper && sphere.V(sphere.F(t, k), 2) >= -1e-12;
    if (upper) keep.push_back(static_cast<int>(t));
  }
  half.F.resize(static_cast<Eigen::Index>(keep.size()), 3);
  for (std::size_t i = 0; i < keep.size(); ++i) half.F.row(static_cast<Eigen::Index>(i)) = sphere.F.row(keep[i]);
  const auto contours = cut(half, {0, 0, 0}, {1, 0, 0});
  REQUIRE(contours.size() == 1);
  CHECK_FALSE(contours[0].closed);
  CHECK(std::abs(contours[0].length - pi) / pi < 0.005);  // a half great circle
  CHECK(contours[0].points.front().y() == Approx(-1.0).margin(1e-9));
  CHECK(contours[0].points.back().y() == Approx(1.0).margin(1e-9));
}

TEST_CASE("slicing: a non-manifold fin does not break the slicer") {
  RawMesh m = box(1, 1, 1);
  const Eigen::Index nv = m.V.rows(), nf = m.F.rows();
  m.V.conservativeResize(nv + 1, 3);
  m.V.row(nv) << 3, 3, 0;  // a fin on the edge x = y = 1
  m.F.conservativeResize(nf + 1, 3);
  m.F.row(nf) << 3, 7, static_cast<int>(nv);  // vertices 3 = (1,1,-1) and 7 = (1,1,1)
  const auto contours = cut(m, {0, 0, 0.25}, {0, 0, 1});
  double total = 0;
  for (const auto& c : contours) total += c.length;
  // The square of perimeter 8 plus the fin's cut from the edge to the fin, walked as chains.
  CHECK(total == Approx(8.0 + 0.75 * 2 * std::sqrt(2.0)).epsilon(1e-9));
}

TEST_CASE("slicing: bad input is refused with a message naming the culprit") {
  RawMesh m = box(1, 1, 1);
  m.V(5, 1) = std::nan("");
  CHECK_THROWS_WITH(prepare_mesh(m.V, m.F), Contains("vertex 5") && Contains("non-finite"));
  RawMesh bad = box(1, 1, 1);
  bad.F(4, 2) = 99;
  CHECK_THROWS_WITH(prepare_mesh(bad.V, bad.F), Contains("triangle 4") && Contains("vertex 99"));
  CHECK_THROWS_AS(Plane::make({0, 0, 0}, {0, 0, 0}, "plane B"), InputError);
  CHECK_THROWS_WITH(Plane::make({0, 0, 0}, {0, 0, 0}, "plane B"), Contains("plane B") && Contains("zero"));
  CHECK_THROWS_WITH(Plane::make({0, INFINITY, 0}, {0, 0, 1}, "plane C"), Contains("plane C"));
  MatrixX3d none(0, 3);
  MatrixX3i nof(0, 3);
  CHECK_THROWS_AS(prepare_mesh(none, nof), InputError);
  const TriMesh faceless = prepare_mesh(box(1, 1, 1).V, nof);  // no faces: valid, nothing to cut
  CHECK(slice(faceless, Plane::make({0, 0, 0}, {0, 0, 1})).empty());
}
