// Out-of-plane deflection (deflection.hpp): the linear frame against closed forms of rod theory.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <vector>

#include "wire_fixtures.hpp"
#include "wiresculpt/deflection.hpp"
#include "wiresculpt/error.hpp"

using namespace wiresculpt;

namespace {
WireSpec open_wire(const Polyline3& points) { return fixtures::flat_wire("test", points); }
}  // namespace

TEST_CASE("deflection: cantilever tip deflection P L^3 / (3 E I) out of plane", "[deflection]") {
  // A straight rod along x in the plane z = 0, clamped at x = 0 (the first point, the cut of an
  // open wire), loaded at its tip by P along the plane normal z: Euler-Bernoulli gives the tip
  // deflection P L³ / (3 E I) and the tip slope P L² / (2 E I) (independent of G: no torsion).
  const double L = 0.3, P = 0.2;
  DeflectionOptions o;
  o.bending_stiffness = 0.73;
  for (int edges : {1, 7, 40}) {
    Polyline3 pts;
    for (int i = 0; i <= edges; ++i) pts.emplace_back(L * i / edges, 0.0, 0.0);
    const DeflectionResult r = wire_deflection(open_wire(pts), -1, {{edges, Vec3(0, 0, P)}}, o);
    INFO(edges << " edges");
    CHECK(r.max_out_of_plane == Approx(P * L * L * L / (3 * o.bending_stiffness)).epsilon(0.01));
    CHECK(r.max_out_of_plane_vertex == edges);
    CHECK(r.displacement.back().z() == Approx(P * L * L * L / (3 * o.bending_stiffness)).epsilon(0.01));
    CHECK(std::abs(r.rotation.back().y()) == Approx(P * L * L / (2 * o.bending_stiffness)).epsilon(0.01));
    CHECK(r.displacement.front().norm() == 0.0);
    // An in-plane load (along y) moves it only in its plane: nothing out of plane.
    const DeflectionResult in_plane = wire_deflection(open_wire(pts), -1, {{edges, Vec3(0, P, 0)}}, o);
    CHECK(in_plane.max_out_of_plane <= 1e-15);
    CHECK(in_plane.displacement.back().y() == Approx(P * L * L * L / (3 * o.bending_stiffness)).epsilon(0.01));
  }
}

TEST_CASE("deflection: quarter ring under an end torque (Castigliano)", "[deflection]") {
  // A quarter circle of radius R in the plane z = 0, x = R cos θ, y = R sin θ, θ from 0 (clamped)
  // to π/2 (free, at (0, R, 0), tangent -x there). The free end carries a couple T about +x.
  // The couple is the same at every section; in the section's tangent t = (-sin θ, cos θ, 0) and
  // radial r = (cos θ, sin θ, 0) directions it is a twist T_t = -T sin θ and an out-of-plane
  // bending moment M_r = T cos θ. A dummy force Q along z at the free end adds, at section θ, the
  // moment (x_end - x(θ)) × Q z = Q R (1 - sin θ, cos θ, 0): twist Q R (1 - sin θ), bending
  // Q R cos θ. With U = ∫ (M_r² / 2EI + T_t² / 2GJ) R dθ, Castigliano's theorem gives the free
  // end's deflection along z,
  //   w = ∂U/∂Q |_{Q=0} = T R² ∫_0^{π/2} [cos²θ / EI + (sin²θ - sin θ) / GJ] dθ
  //     = T R² [ π / (4 EI) + (π/4 - 1) / GJ ],
  // and its rotation about x, φ = ∂U/∂T = T R ∫ [cos²θ / EI + sin²θ / GJ] dθ = (π/4) T R (1/EI + 1/GJ).
  const double R = 0.125, T = 0.05;
  DeflectionOptions o;
  o.bending_stiffness = 0.73;
  o.wire_diameter = 0.003;
  o.shear_modulus = 79.3e9;
  const double GJ = o.shear_modulus * std::numbers::pi * std::pow(o.wire_diameter, 4) / 32;
  const double EI = o.bending_stiffness;
  const double w = T * R * R * (std::numbers::pi / (4 * EI) + (std::numbers::pi / 4 - 1) / GJ);
  const double phi = std::numbers::pi / 4 * T * R * (1 / EI + 1 / GJ);
  const int edges = 90;
  Polyline3 pts;
  for (int i = 0; i <= edges; ++i) {
    const double th = std::numbers::pi / 2 * i / edges;
    pts.emplace_back(R * std::cos(th), R * std::sin(th), 0.0);
  }
  const WireSpec wire = open_wire(pts);
  const DeflectionResult r = wire_deflection(wire, -1, {}, {{edges, Vec3(T, 0, 0)}}, o);
  CHECK(r.displacement.back().z() == Approx(w).epsilon(0.01));
  CHECK(r.rotation.back().x() == Approx(phi).epsilon(0.01));
  // The largest out-of-plane deflection along the ring is not below the end's.
  CHECK(r.max_out_of_plane >= std::abs(w) * 0.99);
  // A stiffer twist (G × 10) changes w by the GJ term alone: the two terms are separated.
  o.shear_modulus *= 10;
  const DeflectionResult stiff = wire_deflection(wire, -1, {}, {{edges, Vec3(T, 0, 0)}}, o);
  CHECK(stiff.displacement.back().z() == Approx(T * R * R * (std::numbers::pi / (4 * EI) + (std::numbers::pi / 4 - 1) / (10 * GJ))).epsilon(0.01));
}

TEST_CASE("deflection: a closed ring is clamped at its cut, and bad input names the wire", "[deflection]") {
  // A closed ring cut at vertex 0 under self-equilibrated out-of-plane forces (±F at 45°, 225° and
  // 135°, 315°: no net force, no net moment): the walk has the cut at both ends, the clamped
  // first node does not move and a load on the clamp moves nothing.
  Polyline3 pts;
  const int n = 48;
  for (int i = 0; i < n; ++i) {
    const double th = 2 * std::numbers::pi * i / n;
    pts.emplace_back(0.1 * std::cos(th), 0.1 * std::sin(th), 0.0);
  }
  WireSpec ring = open_wire(pts);
  ring.closed = true;
  const std::vector<WireLoad> loads = {{6, Vec3(0, 0, 0.1)}, {30, Vec3(0, 0, 0.1)}, {18, Vec3(0, 0, -0.1)}, {42, Vec3(0, 0, -0.1)}};
  const DeflectionResult r = wire_deflection(ring, 0, loads);
  CHECK(r.walk.size() == static_cast<std::size_t>(n + 1));
  CHECK(r.max_out_of_plane > 0.0);
  CHECK(r.displacement.front().norm() == 0.0);
  std::vector<WireLoad> with_clamp = loads;
  with_clamp.push_back({0, Vec3(0, 0, 5.0)});
  const DeflectionResult with_clamp_load = wire_deflection(ring, 0, with_clamp);
  CHECK(with_clamp_load.max_out_of_plane == Approx(r.max_out_of_plane).epsilon(1e-12));
  CHECK_THROWS_WITH(wire_deflection(ring, 0, {{n, Vec3(0, 0, 1)}}), Catch::Matchers::Contains("wire 'test'"));
  DeflectionOptions bad;
  bad.shear_modulus = -1;
  CHECK_THROWS_AS(wire_deflection(ring, 0, {}, bad), InputError);
}
