// Contact pyramids, hook geometry and the metric of Eq. 2 at crossings worked out by hand.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "wiresculpt/contact.hpp"
#include "wiresculpt/error.hpp"
#include "wire_fixtures.hpp"

using namespace wiresculpt;
using fixtures::Cut;

namespace {
constexpr double pi = std::numbers::pi;
constexpr double R = 0.1;

// Great circles X (plane x = 0) and Y (plane y = 0): crossings at the poles, d = x × y = +z.
Network two_great_circles() {
  return build_network(fixtures::sphere_wires({{"X", Vec3::UnitX(), 0.0}, {"Y", Vec3::UnitY(), 0.0}}, R));
}

int top_crossing(const Network& net) { return net.crossings[0].point.z() > 0 ? 0 : 1; }

bool contains(const std::array<Vec3, 4>& set, const Vec3& v) {
  for (const Vec3& s : set)
    if ((s - v).norm() < 1e-12) return true;
  return false;
}

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }
}  // namespace

TEST_CASE("contact: the common-line direction is n0 x n1") {
  const Network net = two_great_circles();
  REQUIRE(net.crossings.size() == 2);
  for (int c = 0; c < 2; ++c) CHECK((crossing_direction(net, c) - Vec3::UnitZ()).norm() < 1e-15);
}

TEST_CASE("contact: pyramid vectors match the hand formula and the hook sign") {
  const Network net = two_great_circles();
  const int c = top_crossing(net);
  ContactOptions o;  // mu = 0.32, contact angle 120 degrees
  const double beta = pi / 3 - std::atan(0.32);
  const double sb = std::sin(beta), cb = std::cos(beta);
  // t0 = n0 x d = x × z = -y, t1 = n1 x d = y × z = +x.
  const auto plus = contact_pyramid(net, c, 1, o);
  CHECK(contains(plus, Vec3(0, -cb, -sb)));
  CHECK(contains(plus, Vec3(0, cb, -sb)));
  CHECK(contains(plus, Vec3(cb, 0, -sb)));
  CHECK(contains(plus, Vec3(-cb, 0, -sb)));
  // Hook +1: wire 0 sits on the -d side, so the force on it from wire 1 points along -d.
  for (const Vec3& v : plus) {
    CHECK(v.z() < 0);
    CHECK(v.norm() == Approx(1.0));
  }
  const auto minus = contact_pyramid(net, c, -1, o);
  for (const Vec3& v : minus) CHECK(v.z() > 0);
  CHECK(contains(minus, Vec3(0, cb, sb)));
  // Without friction and with straight wires (contact angle pi) the only force is along -d.
  ContactOptions straight;
  straight.friction = 0.0;
  straight.contact_angle = pi;
  for (const Vec3& v : contact_pyramid(net, c, 1, straight)) CHECK((v - Vec3(0, 0, -1)).norm() < 1e-12);
  CHECK_THROWS_AS(contact_pyramid(net, c, 0, o), InputError);
}

TEST_CASE("contact: friction widens each edge normal by atan(mu) in the wire's own plane") {
  const Network net = two_great_circles();
  const int c = top_crossing(net);
  for (double mu : {0.0, 0.23, 0.32}) {
    ContactOptions o;
    o.friction = mu;
    for (int hook : {-1, 1}) {
      const HookGeometry g = hook_geometry(net, c, hook, o);
      const auto pyr = contact_pyramid(net, c, hook, o);
      // Wire 0: the pushes on its edges are its outward in-plane edge normals (away from its
      // bisector), each turned by atan(mu) away from the other. Pyramid vectors 0, 1 lie in
      // plane 0; vectors 2, 3 are the negated pushes on wire 1's edges, in plane 1.
      for (int k = 0; k < 2; ++k) {
        const Vec3 n = net.wires[net.crossings[c].wires[k]].plane.normal;
        for (int e = 0; e < 2; ++e) {
          const Vec3 arm = g.edge_dirs[k][e];
          Vec3 out = n.cross(arm).normalized();
          if (out.dot(g.bisector[k]) > 0) out = -out;  // outward: away from the kink's opening
          const Vec3 push_on_k = out;                  // what the other wire does to wire k
          const Vec3 expect_on_0 = k == 0 ? push_on_k : Vec3(-push_on_k);
          // Some pyramid vector of the same plane makes exactly atan(mu) with it.
          double best = 10.0;
          for (int v = 2 * k; v < 2 * k + 2; ++v) {
            CHECK(std::abs(pyr[v].dot(n)) < 1e-12);
            best = std::min(best, angle(pyr[v], expect_on_0));
          }
          CHECK(best == Approx(std::atan(mu)).margin(1e-12));
        }
      }
    }
  }
}

TEST_CASE("contact: hook geometry puts each wire's edges symmetric about +-d at the contact angle") {
  const Network net = two_great_circles();
  const int c = top_crossing(net);
  ContactOptions o;
  o.contact_angle = 100.0 * pi / 180.0;
  for (int hook : {-1, 1}) {
    const HookGeometry g = hook_geometry(net, c, hook, o);
    CHECK((g.bisector[0] - hook * Vec3::UnitZ()).norm() < 1e-15);
    CHECK((g.bisector[1] + hook * Vec3::UnitZ()).norm() < 1e-15);
    for (int k = 0; k < 2; ++k) {
      const auto& w = net.wires[net.crossings[c].wires[k]];
      const int v = net.crossings[c].vertices[k];
      const int n = static_cast<int>(w.points.size());
      const Vec3 prev = w.points[(v + n - 1) % n], next = w.points[(v + 1) % n], p = w.points[v];
      for (int e = 0; e < 2; ++e) {
        CHECK(std::abs(g.edge_dirs[k][e].dot(w.plane.normal)) < 1e-15);
        CHECK(angle(g.edge_dirs[k][e], g.bisector[k]) == Approx(o.contact_angle / 2));
      }
      CHECK(angle(g.edge_dirs[k][0], g.edge_dirs[k][1]) == Approx(o.contact_angle));
      // Edge lengths kept, each neighbour stays on its side of the common line.
      CHECK((g.neighbours[k][0] - p).norm() == Approx((prev - p).norm()));
      CHECK((g.neighbours[k][1] - p).norm() == Approx((next - p).norm()));
      const Vec3 t = w.plane.normal.cross(Vec3::UnitZ());
      CHECK((g.neighbours[k][0] - p).dot(t) * (prev - p).dot(t) > 0);
      CHECK((g.neighbours[k][1] - p).dot(t) * (next - p).dot(t) > 0);
    }
  }
  const HookGeometry null = hook_geometry(net, c, 0, o);
  CHECK(null.metric == 0.0);
  CHECK(null.bisector[0].norm() == 0.0);
}

TEST_CASE("contact: metric of Eq. 2 for two great circles is 2 for both hooks") {
  // At the top pole both circles bend towards the centre: h̄ = -z for both, d = +z.
  // Hook +1: (1 - z·(-z)) + (1 - (-z)·(-z)) = 2; hook -1: (1 - 1) + (1 + 1) = 2.
  const Network net = two_great_circles();
  for (int c = 0; c < 2; ++c) {
    CHECK(hook_metric(net, c, 1) == Approx(2.0));
    CHECK(hook_metric(net, c, -1) == Approx(2.0));
    CHECK(hook_metric(net, c, 0) == 0.0);
  }
  const auto hbar = input_bisector(net, 0, net.crossings[top_crossing(net)].vertices[0]);
  REQUIRE(hbar);
  CHECK((*hbar + Vec3::UnitZ()).norm() < 1e-3);  // -z up to the polygon's asymmetry at the pole
}

TEST_CASE("contact: metric of Eq. 2 prefers the hook matching opposite input bends") {
  // Circle A (x = 0, radius R about the origin) and circle B (y = 0, radius r about (0, 0, R + r))
  // meet at (0, 0, R): A bends towards -z there, B towards +z; d = +z.
  // Hook -1 wants h_A = -z, h_B = +z: e = 0. Hook +1 flips both: e = 2 + 2 = 4.
  const double r = 0.04;
  WireSpec a = fixtures::circle_wire({"A", Vec3::UnitX(), 0.0}, R, 72, {Vec3(0, 0, R)});
  WireSpec b;
  b.name = "B";
  b.plane = Plane::make({0, 0, 0}, Vec3::UnitY());
  for (int k = 0; k < 72; ++k) {
    const double phi = -pi / 2 + 2 * pi * k / 72;  // k = 0: the bottom (0, 0, R)
    b.points.push_back(Vec3(r * std::cos(phi), 0, R + r + r * std::sin(phi)));
  }
  b.points[0] = Vec3(0, 0, R);
  const Network net = build_network({a, b});
  REQUIRE(net.crossings.size() == 1);
  CHECK(hook_metric(net, 0, -1) == Approx(0.0).margin(1e-4));
  CHECK(hook_metric(net, 0, 1) == Approx(4.0).epsilon(1e-4));
}

TEST_CASE("contact: a straight wire has no bisector and costs 1 per hook") {
  // Open straight wire S along y in plane x = 0; circle B (y = 0) with its bottom at the origin,
  // bending towards +z. d = x × y = +z. Hook +1: 1 (straight) + (1 - (-z)·z) = 3; hook -1: 1 + 0.
  WireSpec s;
  s.name = "S";
  s.plane = Plane::make({0, 0, 0}, Vec3::UnitX());
  s.closed = false;
  for (int k = -5; k <= 5; ++k) s.points.push_back(Vec3(0, 0.01 * k + 0.003, 0));
  WireSpec b;
  b.name = "B";
  b.plane = Plane::make({0, 0, 0}, Vec3::UnitY());
  const double r = 0.05;
  for (int k = 0; k < 60; ++k) {
    const double phi = -pi / 2 + 2 * pi * k / 60;
    b.points.push_back(Vec3(r * std::cos(phi), 0, r + r * std::sin(phi)));
  }
  b.points[0] = Vec3(0, 0, 0);
  const Network net = build_network({s, b});
  REQUIRE(net.crossings.size() == 1);
  CHECK_FALSE(input_bisector(net, 0, net.crossings[0].vertices[0]));
  CHECK(hook_metric(net, 0, 1) == Approx(3.0).epsilon(1e-6));
  CHECK(hook_metric(net, 0, -1) == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("contact: options are validated") {
  const Network net = two_great_circles();
  ContactOptions o;
  o.friction = -1;
  CHECK_THROWS_AS(validate(o), InputError);
  o = ContactOptions{};
  o.contact_angle = 4.0;
  CHECK_THROWS_AS(validate(o), InputError);
  CHECK_THROWS_AS(hook_metric(net, 7, 1), InputError);
  CHECK_THROWS_AS(hook_metric(net, 0, 2), InputError);
}
