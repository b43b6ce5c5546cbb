// Cuts and rest shapes (Sec. 4.4, Eq. 9-12) on wires whose answers are known by hand: no load
// (rest = target), a cantilever (closed-form angles and the sign of the bend), a loaded closed
// wire (edge lengths, torque equilibrium at every vertex), and cut placement and validation.
#include <catch2/catch.hpp>
#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "wire_fixtures.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/rest_shape.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;

namespace {
constexpr double pi = std::numbers::pi;

// A closed, irregular polygon in the plane z = 0.1 (normal +z), n points.
WireSpec blob(int n) {
  WireSpec w;
  w.name = "blob";
  w.plane = Plane::make(Vec3(0, 0, 0.1), Vec3::UnitZ());
  w.closed = true;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    const double r = 0.1 + 0.02 * std::cos(3 * t) + 0.005 * std::sin(5 * t);
    w.points.emplace_back(r * std::cos(t), r * std::sin(t), 0.1);
  }
  return w;
}

double edge(const Polyline2& p, int k) { return (p[k + 1] - p[k]).norm(); }
}  // namespace

TEST_CASE("rest: without contact forces the rest shape is the target", "[rest]") {
  const WireSpec w = blob(40);
  for (int cut : {0, 7, 39}) {
    const RestShapeResult r = rest_shape(w, cut, {});
    REQUIRE(r.rest.size() == 41);
    for (int k = 0; k <= 40; ++k) {
      const Vec2 t = w.plane.to_2d(w.points[(cut + k) % 40]);
      CHECK((r.rest[k] - t).norm() < 1e-12);
      CHECK(r.rest_angles[k] == Approx(r.target_angles[k]).margin(1e-15));
      CHECK(r.torque[k] == 0.0);
    }
    CHECK(r.closure_gap < 1e-12);
    CHECK(r.max_torque_vertex == -1);
  }
}

TEST_CASE("rest: a polyline rebuilt from its own turning angles is the polyline", "[rest]") {
  Polyline2 p;
  for (int k = 0; k < 30; ++k) p.emplace_back(0.01 * k + 0.003 * std::sin(k), 0.02 * std::cos(0.4 * k));
  const auto a = turning_angles(p);
  std::vector<double> len;
  for (int k = 0; k + 1 < 30; ++k) len.push_back(edge(p, k));
  const Vec2 e0 = p[1] - p[0];
  const Polyline2 q = polyline_from_angles(p[0], std::atan2(e0.y(), e0.x()), len, a);
  REQUIRE(q.size() == p.size());
  for (int k = 0; k < 30; ++k) CHECK((q[k] - p[k]).norm() < 1e-12);
}

TEST_CASE("rest: a cantilever bends back against its load (closed form)", "[rest]") {
  // Open straight wire along +x in the plane z = 0, force +y at the free end x = L. Walked from
  // x = 0: t_v = ((x_v - x_L) × F)·z = -(L - x_v) F; straight target (α = 0), so Eq. 12 with
  // counter-clockwise angles gives ᾱ_v = 2 atan(t_v l̄ / (4 k_b)) < 0: fabricated bent clockwise,
  // the load straightens it.
  WireSpec w;
  w.name = "rod";
  w.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
  w.closed = false;
  const int n = 11;
  const double L = 0.2, F = 3.0, kb = 0.73;
  for (int k = 0; k < n; ++k) w.points.emplace_back(L * k / (n - 1), 0.0, 0.0);
  RestShapeOptions o;
  o.bending_stiffness = kb;
  const RestShapeResult r = rest_shape(w, -1, {{n - 1, Vec3(0, F, 0)}}, o);
  const double l_bar = L / (n - 1);
  for (int k = 1; k < n - 1; ++k) {
    const double x = L * k / (n - 1);
    CHECK(r.torque[k] == Approx(-(L - x) * F).epsilon(1e-12));
    // Eq. 12 with l̄ = 2h (voronoi_length): 2 atan(M h / (2 k_b)), the continuum turn M h / E·I
    // to first order.
    CHECK(r.rest_angles[k] == Approx(2 * std::atan(-(L - x) * F * (2 * l_bar) / (4 * kb))).epsilon(1e-12));
    CHECK(r.rest_angles[k] < 0);
  }
  CHECK(r.max_torque == Approx(L * F));
  CHECK(r.max_torque_vertex == 0);
  CHECK(r.closure_gap == 0.0);
}

namespace {
// An independent forward model of a clamped cantilever (clamp at the origin along +x, N edges of
// length h, a load (0, -P) at the free end), solved by minimising the total potential
//   Π(φ) = Σ_v 4 k_b / l̄_v tan²(φ_v / 2) + P y_tip(φ)
// (Eq. 9 with a straight rest shape and the Voronoi length l̄ = |e_{v-1}| + |e_v|, a ghost edge
// of length 0 at the clamp) over the turning angles φ, with Newton steps whose gradient and
// Hessian are central finite differences of Π itself: nothing of Eq. 10-12 is used.
struct Cantilever {
  int N;
  double L, kb;
  double h() const { return L / N; }
  std::vector<Vec3> nodes(const Eigen::VectorXd& phi) const {
    std::vector<Vec3> x{Vec3::Zero()};
    double theta = 0;
    for (int k = 0; k < N; ++k) {
      theta += phi(k);
      x.push_back(x.back() + h() * Vec3(std::cos(theta), std::sin(theta), 0));
    }
    return x;
  }
  double potential(const Eigen::VectorXd& phi, double P) const {
    double e = 0;
    for (int v = 0; v < N; ++v) {
      const double l_bar = (v == 0 ? 0.0 : h()) + h();
      e += 4 * kb / l_bar * std::pow(std::tan(phi(v) / 2), 2);
    }
    return e + P * nodes(phi).back().y();
  }
  Eigen::VectorXd gradient(const Eigen::VectorXd& phi, double P) const {
    Eigen::VectorXd g(N);
    const double s = 1e-6;
    for (int k = 0; k < N; ++k) {
      Eigen::VectorXd a = phi, b = phi;
      a(k) += s;
      b(k) -= s;
      g(k) = (potential(a, P) - potential(b, P)) / (2 * s);
    }
    return g;
  }
  Eigen::VectorXd solve(double P, Eigen::VectorXd phi) const {
    for (int it = 0; it < 50; ++it) {
      const Eigen::VectorXd g = gradient(phi, P);
      if (g.norm() < 1e-10) break;
      Eigen::MatrixXd H(N, N);
      const double s = 1e-4;
      for (int k = 0; k < N; ++k) {
        Eigen::VectorXd a = phi, b = phi;
        a(k) += s;
        b(k) -= s;
        H.col(k) = (gradient(a, P) - gradient(b, P)) / (2 * s);
      }
      phi -= H.ldlt().solve(g);
    }
    return phi;
  }
};
}  // namespace

TEST_CASE("rest: an independent cantilever (finite differences) checks the stiffness scale and Eq. 12",
          "[rest][cantilever]") {
  const Cantilever c{40, 0.3, 0.73};
  // Small load: the discrete rod must deflect as the continuum rod of E·I = k_b, P L³ / (3 k_b)
  // (with the printed l̄ = ½(|e_{v-1}| + |e_v|) it would deflect half as much). The discrete sum
  // is the trapezoid rule of ∫ P (L - x)² / k_b dx: relative error 1 / (2 N²) = 3e-4.
  const double P0 = 0.1;
  const Eigen::VectorXd small = c.solve(P0, Eigen::VectorXd::Zero(c.N));
  const double tip = -c.nodes(small).back().y();
  CHECK(tip == Approx(P0 * std::pow(c.L, 3) / (3 * c.kb)).epsilon(1e-3));
  // Large load (tip deflection about a third of the length): the deformed rod as the target, its
  // load on the free end, and rest_shape must give back the straight rod at every interior vertex.
  Eigen::VectorXd phi = small;
  const double P = 8.0;
  for (int step = 1; step <= 8; ++step) phi = c.solve(P * step / 8, phi);
  const std::vector<Vec3> x = c.nodes(phi);
  REQUIRE(-x.back().y() > 0.25 * c.L);
  const WireSpec w = fixtures::flat_wire("cantilever", x);
  RestShapeOptions o;
  o.bending_stiffness = c.kb;
  const RestShapeResult r = rest_shape(w, -1, {{c.N, Vec3(0, -P, 0)}}, o);
  for (int v = 1; v < c.N; ++v) {
    INFO("vertex " << v << ": target turn " << r.target_angles[v]);
    CHECK(std::abs(r.target_angles[v]) > 1e-4);  // really bent
    CHECK(r.rest_angles[v] == Approx(0.0).margin(1e-7));
  }
}

TEST_CASE("rest: loaded closed wire keeps its edge lengths and every vertex in equilibrium", "[rest]") {
  const WireSpec w = blob(48);
  // Self-equilibrated loads: three forces meeting at the origin summing to zero, plus an
  // out-of-plane pair that only the out-of-plane torque sees.
  std::vector<WireLoad> loads;
  const int v1 = 5, v2 = 21, v3 = 37;
  // Forces through the centre (0,0,z): torques of each about it vanish in z when they are radial.
  auto radial = [&](int v, double mag) { return Vec3(mag * Vec3(w.points[v].x(), w.points[v].y(), 0).normalized()); };
  const Vec3 g1 = radial(v1, 1.0), g2 = radial(v2, 1.3);
  // third force balancing the first two and their moment (all radial through the centre => no moment)
  const Vec3 g3 = -(g1 + g2);
  loads = {{v1, g1}, {v2, g2}, {v3, g3}};
  // The third force is not radial at v3: add a fourth at the centre-line to cancel the moment.
  const Vec3 m = (w.points[v3] - Vec3(0, 0, 0.1)).cross(g3);
  // a couple from two opposite forces at v=13 and v=29 along ±y to cancel m_z
  const Vec3 a = w.points[13], b = w.points[29];
  const Vec3 dir = Vec3::UnitY();
  const double s = -m.z() / ((a - b).cross(dir)).z();
  loads.push_back({13, s * dir});
  loads.push_back({29, -s * dir});
  loads.push_back({9, Vec3(0, 0, 0.4)});  // out of plane
  loads.push_back({30, Vec3(0, 0, -0.4)});
  Vec3 sum_f = Vec3::Zero(), sum_m = Vec3::Zero();
  for (const auto& l : loads) {
    sum_f += l.force;
    sum_m += w.points[l.vertex].cross(l.force);
  }
  REQUIRE(sum_f.norm() < 1e-12);
  REQUIRE(std::abs(sum_m.z()) < 1e-12);
  RestShapeOptions o;
  o.bending_stiffness = 0.42;
  const RestShapeResult r = rest_shape(w, 3, loads, o);
  const int m_pts = static_cast<int>(r.rest.size());
  REQUIRE(m_pts == 49);
  double worst_out = 0;
  for (int k = 0; k + 1 < m_pts; ++k) {
    const double target_len = (w.points[r.walk[k + 1]] - w.points[r.walk[k]]).norm();
    CHECK(std::abs(edge(r.rest, k) - target_len) < 1e-12);
  }
  for (int k = 1; k + 1 < m_pts; ++k) {
    const double l_bar = voronoi_length((w.points[r.walk[k]] - w.points[r.walk[k - 1]]).norm(),
                                        (w.points[r.walk[k + 1]] - w.points[r.walk[k]]).norm());
    const double t_int = elastic_torque(r.target_angles[k], r.rest_angles[k], l_bar, o.bending_stiffness);
    CHECK(std::abs(t_int - r.torque[k]) <= 1e-9 * std::max(1e-3, std::abs(r.torque[k])));
    worst_out = std::max(worst_out, r.out_of_plane_torque[k]);
  }
  // The measured rest angles are the rest polyline's own turning angles.
  const auto own = turning_angles(r.rest);
  for (int k = 1; k + 1 < m_pts; ++k) CHECK(own[k] == Approx(r.rest_angles[k]).margin(1e-10));
  CHECK(worst_out > 0.0);
  CHECK(r.closure_gap > 1e-4);  // loaded: the cut ends do not meet
  // Equilibrium: the torque at the cut (all loads after it) vanishes.
  CHECK(std::abs(r.torque[0]) < 1e-12);
}

TEST_CASE("rest: rest bends beyond the machine's limit are reported", "[rest]") {
  WireSpec w;
  w.name = "rod";
  w.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
  w.closed = false;
  for (int k = 0; k < 5; ++k) w.points.emplace_back(0.02 * k, 0.0, 0.0);
  RestShapeOptions o;
  o.bending_stiffness = 1e-4;  // so soft that the load needs a huge pre-bend
  o.max_bend = pi / 6;
  const RestShapeResult r = rest_shape(w, -1, {{4, Vec3(0, 1.0, 0)}}, o);
  REQUIRE(!r.over_bend.empty());
  for (std::size_t i = 0; i < r.over_bend.size(); ++i) CHECK(std::abs(r.over_bend_angle[i]) > pi / 6);
}

TEST_CASE("rest: an unloaded bend at the limit is not an over-bend, and one past the tolerance is", "[rest]") {
  // An open rod with one target bend of exactly max_bend (+ rounding) at vertex 2 and no load:
  // the rest angle is the target angle. Built by hand: edges along x, then turned by the angle.
  auto rod = [](double turn) {
    WireSpec w;
    w.name = "rod";
    w.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
    w.closed = false;
    w.points = {Vec3(0, 0, 0), Vec3(0.02, 0, 0), Vec3(0.04, 0, 0),
                Vec3(0.04 + 0.02 * std::cos(turn), 0.02 * std::sin(turn), 0),
                Vec3(0.04 + 0.04 * std::cos(turn), 0.04 * std::sin(turn), 0)};
    return w;
  };
  RestShapeOptions o;
  o.max_bend = pi / 6;
  const RestShapeResult at = rest_shape(rod(pi / 6 * (1 + 1e-14)), -1, {}, o);
  CHECK(std::abs(std::abs(at.rest_angles[2]) - pi / 6) < 1e-12);
  CHECK(at.over_bend.empty());
  const RestShapeResult past = rest_shape(rod(pi / 6 + 10 * o.over_bend_tolerance), -1, {}, o);
  REQUIRE(past.over_bend.size() == 1);
  CHECK(past.over_bend[0] == 2);
}

TEST_CASE("rest: automatic cut in the middle of the longest piece between crossings", "[rest][cut]") {
  // A 12-gon with unit-ish edges; crossings at 0, 3, 5: pieces 0-3 (3 edges), 3-5 (2), 5-12 (7).
  WireSpec w;
  w.name = "ring";
  w.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
  for (int k = 0; k < 12; ++k) w.points.emplace_back(std::cos(2 * pi * k / 12), std::sin(2 * pi * k / 12), 0.0);
  // The longest piece 5 -> 12 has 7 equal edges: its middle (3.5 edges) is nearest to vertices 8
  // and 9 equally; the lower walk position wins: 8.
  CHECK(automatic_cut(w, {0, 3, 5}) == 8);
  // Stretch the edge 8-9 (move vertex 9 outward is in-plane): now the arc midpoint moves to 9.
  WireSpec u = w;
  u.points[10] = 1.6 * u.points[10];
  CHECK(automatic_cut(u, {0, 3, 5}) == 9);
  // One crossing: the piece goes all the way round; cut opposite.
  CHECK(automatic_cut(w, {2}) == 8);
  CHECK(automatic_cut(w, {}) == 0);
  WireSpec open = w;
  open.closed = false;
  CHECK(automatic_cut(open, {3}) == -1);
}

TEST_CASE("rest: user cuts are validated and name the wire", "[rest][cut]") {
  Network net;
  WireSpec a;
  a.name = "A/0";
  a.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
  for (int k = 0; k < 8; ++k) a.points.emplace_back(std::cos(2 * pi * k / 8), std::sin(2 * pi * k / 8), 0.0);
  WireSpec b;
  b.name = "B/0";
  b.closed = false;
  b.plane = Plane::make(Vec3::Zero(), Vec3::UnitX());
  b.points = {Vec3(0, 1, -1), Vec3(0, 1, 0), Vec3(0, 1, 1)};
  a.points[2] = Vec3(0, 1, 0);
  net.wires = {a, b};
  Crossing c;
  c.wires = {0, 1};
  c.vertices = {2, 1};
  c.point = Vec3(0, 1, 0);
  net.crossings = {c};
  CHECK(choose_cuts(net) == std::vector<int>{6, -1});
  CHECK(choose_cuts(net, {5, -1}) == std::vector<int>{5, -1});
  CHECK_THROWS_AS(choose_cuts(net, {8, -1}), InputError);
  CHECK_THROWS_WITH(choose_cuts(net, {8, -1}), Contains("A/0") && Contains("outside"));
  CHECK_THROWS_WITH(choose_cuts(net, {2, -1}), Contains("A/0") && Contains("crossing"));
  CHECK_THROWS_WITH(choose_cuts(net, {5, 1}), Contains("B/0") && Contains("open"));
  CHECK_THROWS_AS(choose_cuts(net, {5}), InputError);
}
