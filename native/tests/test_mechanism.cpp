// Mechanisms of networks whose degrees of freedom are known by hand: two great circles turn
// about their common diameter, three are rigid, a wire crossing one other wire at two points is
// a hinge about the line through them.
#include <catch2/catch.hpp>
#include <cmath>

#include "wiresculpt/layering.hpp"
#include "wiresculpt/mechanism.hpp"
#include "wire_fixtures.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;
using fixtures::Cut;

namespace {
constexpr double R = 0.1;
constexpr double H = 0.5 * R;  // height of the hinged wire's plane

// Great circles X, Y, Z, and W: a rectangle in the plane z = H, |x| <= 0.3 R, |y| <= b with
// b = sqrt(R² - H²), whose two long edges pass through X's circle at (0, ±b, H) (inserted into
// X exactly) and which passes the plane y = 0 at x = ±0.3 R, where Y's circle is not (|x| = b):
// W crosses X at two points and nothing else.
Network hinged() {
  const Cut cx{"X", Vec3::UnitX(), 0.0}, cy{"Y", Vec3::UnitY(), 0.0}, cz{"Z", Vec3::UnitZ(), 0.0};
  const Cut cw{"W", Vec3::UnitZ(), H};
  std::vector<Vec3> on_x;
  for (const Cut& other : {cy, cz, cw})
    for (const Vec3& p : fixtures::circle_meets(cx, other, R)) on_x.push_back(p);
  std::vector<WireSpec> wires{fixtures::circle_wire(cx, R, 64, on_x)};
  for (const Cut& c : {cy, cz}) {
    std::vector<Vec3> extra;
    for (const Cut& other : {cx, cy, cz})
      if (other.name != c.name)
        for (const Vec3& p : fixtures::circle_meets(c, other, R)) extra.push_back(p);
    wires.push_back(fixtures::circle_wire(c, R, 64, extra));
  }
  const double a = 0.3 * R, b = std::sqrt(R * R - H * H);
  WireSpec w;
  w.name = "W";
  w.plane = Plane::make({0, 0, H}, Vec3::UnitZ());
  for (const Vec2& q : {Vec2(a, b), Vec2(-a, b), Vec2(-a, -b), Vec2(a, -b)}) w.points.push_back(Vec3(q.x(), q.y(), H));
  wires.push_back(w);
  return build_network(wires);
}
}  // namespace

TEST_CASE("mechanism: two great circles turn about their common diameter, three are rigid") {
  const Network two = build_network(fixtures::sphere_wires({{"X", Vec3::UnitX(), 0.0}, {"Y", Vec3::UnitY(), 0.0}}, R));
  const Mechanism m2 = find_mechanism(two);
  CHECK(m2.degrees_of_freedom == 1);
  REQUIRE(m2.moving.size() == 1);
  CHECK(m2.rest == std::vector<int>{0});
  CHECK(m2.moving[0].wires == std::vector<int>{1});
  CHECK(m2.moving[0].kind == MovingPart::Kind::hinge);
  // The crossings are the poles (0, 0, ±R): the axis is z.
  CHECK(std::abs((m2.moving[0].axis_to - m2.moving[0].axis_from).normalized().z()) == Approx(1.0).margin(1e-9));

  const Network three = build_network(fixtures::sphere_wires(fixtures::great_circle_cuts(), R));
  const Mechanism m3 = find_mechanism(three);
  CHECK(m3.degrees_of_freedom == 0);
  CHECK(m3.moving.empty());
  CHECK(m3.rest.size() == 3);
  CHECK(mechanism_message(three, m3).empty());
}

TEST_CASE("mechanism: a wire crossing one other wire twice is a hinge, named with the plane move") {
  const Network net = hinged();
  REQUIRE(net.wires.size() == 4);
  int on_w = 0;
  for (const auto& x : net.crossings) on_w += (x.wires[0] == 3 || x.wires[1] == 3) ? 1 : 0;
  REQUIRE(on_w == 2);  // W crosses X only
  const Mechanism m = find_mechanism(net);
  CHECK(m.degrees_of_freedom == 1);
  CHECK(m.rest == std::vector<int>{0, 1, 2});
  REQUIRE(m.moving.size() == 1);
  CHECK(m.moving[0].wires == std::vector<int>{3});
  CHECK(m.moving[0].kind == MovingPart::Kind::hinge);
  CHECK(m.moving[0].crossings.size() == 2);
  // The hinge is the line x = 0, z = H: along y.
  const Vec3 axis = (m.moving[0].axis_to - m.moving[0].axis_from).normalized();
  CHECK(std::abs(axis.y()) == Approx(1.0).margin(1e-9));
  CHECK(m.moving[0].axis_from.z() == Approx(H).margin(1e-9));

  // The nearest wire inside W's outline is Y's arc over the top (z >= R cos 17.5°, by hand
  // about 0.0954 m): W's plane must go up by about 45 mm.
  const PlaneMove move = plane_move(net, 3, {0});
  REQUIRE(move.found);
  CHECK(move.towards_wire == 1);
  CHECK(move.direction.z() == Approx(1.0));
  CHECK(move.distance > 0.0954 - H - 1e-3);
  CHECK(move.distance < R - H);

  // A ring in a plane parallel to W's, just above it inside its outline, is nearer but can never
  // be reached by moving W's plane: still Y.
  Network with_ring = net;
  WireSpec ring = fixtures::circle_wire({"P", Vec3::UnitZ(), 0.0}, 0.01, 16);
  for (auto& q : ring.points) q.z() = H + 0.005;
  ring.plane = Plane::make({0, 0, H + 0.005}, Vec3::UnitZ());
  with_ring.wires.push_back(ring);
  CHECK(plane_move(with_ring, 3, {0}).towards_wire == 1);

  // The layering's reason names W as the hinge, not the LP's reference wire.
  const LayeringResult r = layering(net);
  CHECK_FALSE(r.stable);
  CHECK_THAT(r.reason, Contains("no hook configuration") && Contains("wire 'W' is held only at crossings") &&
                           Contains("hinge") && Contains("move the plane of wire 'W'") && Contains("+z") &&
                           Contains("towards wire 'Y'"));
  CHECK_THAT(r.reason, !Contains("wire 'X' is") && !Contains("wire 'Z' is") && !Contains("cannot balance"));
}

TEST_CASE("mechanism: a hinged wire carrying a wire that hangs on it alone is still named a hinge") {
  // D: a rectangle in the plane x = 0.01 whose sides cross W's long edges (nothing else): it
  // hangs on W, which stays hinged on X.
  Network net = hinged();
  std::vector<WireSpec> wires = net.wires;
  const double b = std::sqrt(R * R - H * H);
  WireSpec d;
  d.name = "D";
  d.plane = Plane::make({0.01, 0, 0}, Vec3::UnitX());
  for (const Vec2& q : {Vec2(b, H + 0.01), Vec2(-b, H + 0.01), Vec2(-b, H - 0.01), Vec2(b, H - 0.01)})
    d.points.push_back(Vec3(0.01, q.x(), q.y()));
  wires.push_back(d);
  net = build_network(wires);
  const Mechanism m = find_mechanism(net);
  REQUIRE(m.moving.size() == 2);
  CHECK(m.rest == std::vector<int>{0, 1, 2});
  const MovingPart& w = m.moving[0];
  CHECK(w.wires == std::vector<int>{3});
  CHECK(w.crossings.size() == 4);
  CHECK(w.to_rest.size() == 2);
  CHECK(w.kind == MovingPart::Kind::hinge);
  CHECK(std::abs((w.axis_to - w.axis_from).normalized().y()) == Approx(1.0).margin(1e-9));
  CHECK(m.moving[1].wires == std::vector<int>{4});
  CHECK(m.moving[1].kind == MovingPart::Kind::hinge);
  const std::string text = mechanism_message(net, m);
  CHECK_THAT(text, Contains("wire 'W' is held to the rest only at crossings") && Contains("hang on it") &&
                       Contains("wire 'D' is held only at crossings"));
}
