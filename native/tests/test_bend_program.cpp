// Bend programs on polylines known by hand: square, regular polygon, a random polyline; the
// spring-back compensation; the limits; the small-bend rule against closed forms and an
// independent dense-sampling distance.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/bend_program.hpp"

using namespace wiresculpt;
using namespace wiresculpt::fab;
using Catch::Matchers::Contains;
using Catch::Matchers::Equals;

namespace {
constexpr double pi = std::numbers::pi;
constexpr double deg = pi / 180.0;

double max_vertex_distance(const Polyline2& a, const Polyline2& b) {
  REQUIRE(a.size() == b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i] - b[i]).norm());
  return worst;
}

// A polyline from feeds and turns, built here independently of the library.
Polyline2 walk(Vec2 start, double heading, const std::vector<double>& feeds, const std::vector<double>& turns) {
  Polyline2 p{start};
  for (std::size_t i = 0; i < feeds.size(); ++i) {
    start += feeds[i] * Vec2(std::cos(heading), std::sin(heading));
    p.push_back(start);
    if (i < turns.size()) heading += turns[i];
  }
  return p;
}

// Independent distance: both polylines sampled densely by arc length with their own walk.
double dense_distance(const Polyline2& a, const Polyline2& b, int samples) {
  auto at = [](const Polyline2& p, double s) {
    for (std::size_t i = 1; i < p.size(); ++i) {
      const double len = (p[i] - p[i - 1]).norm();
      if (s <= len) return Vec2(p[i - 1] + (s / len) * (p[i] - p[i - 1]));
      s -= len;
    }
    return p.back();
  };
  double total = 0.0;
  for (std::size_t i = 1; i < a.size(); ++i) total += (a[i] - a[i - 1]).norm();
  double worst = 0.0;
  for (int k = 0; k <= samples; ++k) {
    const double s = total * k / samples;
    worst = std::max(worst, (at(a, s) - at(b, s)).norm());
  }
  return worst;
}
}  // namespace

TEST_CASE("bend program: a square walked counter-clockwise", "[fab][bend_program]") {
  const double a = 0.05;
  const Polyline2 square{{0, 0}, {a, 0}, {a, a}, {0, a}, {0, 0}};
  const BendProgram p = make_bend_program(square, MachineProfile{});
  REQUIRE(p.steps.size() == 4);
  CHECK(p.bend_count == 3);
  for (int k = 0; k < 4; ++k) CHECK(p.steps[k].feed == Approx(a).epsilon(1e-12));
  for (int k = 0; k < 3; ++k) {
    CHECK(p.steps[k].bend == Approx(pi / 2).epsilon(1e-12));
    CHECK(p.steps[k].vertex == k + 1);
    CHECK(p.steps[k].commanded == Approx(pi / 2).epsilon(1e-12));  // default fit: a = 1, b = 0
  }
  CHECK(p.steps[3].bend == 0.0);
  CHECK(p.steps[3].vertex == -1);
  CHECK(p.wire_length == Approx(4 * a));
  CHECK(max_vertex_distance(rebuild_polyline(p), square) < 1e-9);
  CHECK(p.shape_error < 1e-9);
  CHECK(bend_vertices(p) == std::vector<std::size_t>{1, 2, 3});
  // Time by hand: per bend max(3 s, 50 mm / 20 mm/s + 2 * 90 deg / 90 deg/s) = 4.5 s; final feed 2.5 s.
  CHECK(p.machine_seconds == Approx(3 * 4.5 + 2.5));

  // Clockwise: the same square mirrored turns right, so every bend is negative.
  const Polyline2 cw{{0, 0}, {a, 0}, {a, -a}, {0, -a}, {0, 0}};
  const BendProgram q = make_bend_program(cw, MachineProfile{});
  for (int k = 0; k < 3; ++k) CHECK(q.steps[k].bend == Approx(-pi / 2).epsilon(1e-12));
  CHECK(max_vertex_distance(rebuild_polyline(q), cw) < 1e-9);
}

TEST_CASE("bend program: a regular polygon has equal feeds and 360/N degree bends", "[fab][bend_program]") {
  for (int N : {5, 12, 24}) {
    const double R = 0.12;
    Polyline2 poly;
    for (int i = 0; i <= N; ++i) poly.emplace_back(R * std::cos(2 * pi * i / N + 0.3), R * std::sin(2 * pi * i / N + 0.3));
    const BendProgram p = make_bend_program(poly, MachineProfile{});
    REQUIRE(p.steps.size() == static_cast<std::size_t>(N));
    for (const BendStep& s : p.steps) CHECK(s.feed == Approx(2 * R * std::sin(pi / N)).epsilon(1e-12));
    for (int k = 0; k + 1 < N; ++k) CHECK(p.steps[k].bend == Approx(2 * pi / N).epsilon(1e-12));
    CHECK(max_vertex_distance(rebuild_polyline(p), poly) < 1e-9);
    // From the origin heading +x: the same shape, rigidly moved.
    const Polyline2 o = rebuild_polyline(p, true);
    CHECK(o[0].norm() < 1e-15);
    CHECK(std::abs(o[1].y()) < 1e-15);
    for (std::size_t i = 1; i < o.size(); ++i)
      CHECK((o[i] - o[i - 1]).norm() == Approx((poly[i] - poly[i - 1]).norm()).epsilon(1e-12));
  }
}

TEST_CASE("bend program: a random polyline with segments >= l_min rebuilds to 1e-9", "[fab][bend_program]") {
  std::mt19937 rng(20160724);
  std::uniform_real_distribution<double> length(0.015, 0.06), turn(2 * deg, 110 * deg), coin(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> feeds, turns;
    const int n = 5 + trial * 3;
    for (int i = 0; i < n; ++i) feeds.push_back(length(rng));
    for (int i = 0; i + 1 < n; ++i) turns.push_back(coin(rng) < 0.5 ? turn(rng) : -turn(rng));
    const Polyline2 poly = walk(Vec2(0.3 * coin(rng), -0.2 * coin(rng)), 2 * pi * coin(rng), feeds, turns);
    const BendProgram p = make_bend_program(poly, MachineProfile{});
    REQUIRE(p.steps.size() == feeds.size());
    for (std::size_t k = 0; k < feeds.size(); ++k) CHECK(p.steps[k].feed == Approx(feeds[k]).epsilon(1e-9));
    for (std::size_t k = 0; k < turns.size(); ++k) CHECK(p.steps[k].bend == Approx(turns[k]).epsilon(1e-9));
    CHECK(max_vertex_distance(rebuild_polyline(p), poly) < 1e-9);
    CHECK(p.merged_points == 0);
    CHECK(p.shape_error < 1e-9);
  }
}

TEST_CASE("bend program: compensation inverts the calibration fit", "[fab][bend_program]") {
  MachineProfile m;
  m.springback_a = 0.9;
  m.springback_b = -2.0 * deg;  // measured = 0.9 * commanded - 2 deg
  m.max_commanded = 150 * deg;
  const Polyline2 zig = walk({0, 0}, 0.0, {0.02, 0.02, 0.02, 0.02}, {30 * deg, -75 * deg, 110 * deg});
  const BendProgram p = make_bend_program(zig, m);
  REQUIRE(p.bend_count == 3);
  for (int k = 0; k < 3; ++k) {
    const BendStep& s = p.steps[k];
    // The fit applied to the command gives the target back (sign kept, magnitudes fitted).
    CHECK(m.springback_a * std::abs(s.commanded) + m.springback_b == Approx(std::abs(s.bend)).epsilon(1e-12));
    CHECK(std::signbit(s.commanded) == std::signbit(s.bend));
  }
  CHECK(to_deg(p.steps[0].commanded) == Approx((30.0 + 2.0) / 0.9));
  CHECK(to_deg(p.steps[1].commanded) == Approx(-(75.0 + 2.0) / 0.9));
  // Compensation does not change the shape: rebuild uses the targets.
  CHECK(max_vertex_distance(rebuild_polyline(p), zig) < 1e-9);
}

TEST_CASE("bend program: the preview through the compensating fit is the input", "[fab][bend_program][preview]") {
  MachineProfile m;
  m.springback_a = 0.9;
  m.springback_b = 1.5 * deg;
  // a regular hexagon of 40 mm sides, open at the cut (6 sides, 5 bends of 60 deg)
  std::vector<double> feeds(6, 0.04), turns(5, 60 * deg);
  const Polyline2 hex = walk({0.01, -0.02}, 0.3, feeds, turns);
  const BendProgram p = make_bend_program(hex, m);
  const Polyline2 made = predict_polyline(p, m);
  REQUIRE(made.size() == hex.size());
  CHECK(max_vertex_distance(made, hex) < 1e-9);
  CHECK(dense_distance(made, hex, 2000) < 1e-4);  // 0.1 mm, the bound, with room
}

TEST_CASE("bend program: a wrong slope shows the drift predicted by hand", "[fab][bend_program][preview]") {
  // One 90 deg bend between arms of 30 mm and 50 mm. The machine keeps 0.9 c; the program was
  // compensated with a slope 5 % too steep (0.945), so it commands 90 / 0.945 deg and the wire
  // keeps 90 * 0.9 / 0.945 = 85.714 deg: an angle error of 4.286 deg. The second arm swings about
  // the bend, so its end is off by the chord 2 * 50 mm * sin(error / 2) and nothing is further off.
  MachineProfile truth;
  truth.springback_a = 0.9;
  MachineProfile wrong = truth;
  wrong.springback_a = 0.9 * 1.05;
  const Polyline2 ell = walk({0, 0}, 0.0, {0.03, 0.05}, {90 * deg});
  const BendProgram p = make_bend_program(ell, wrong);
  const Polyline2 made = predict_polyline(p, truth);
  const double error = 90 * deg - 90 * deg * 0.9 / 0.945;
  CHECK(to_deg(error) == Approx(4.285714).epsilon(1e-6));
  const double chord = 2 * 0.05 * std::sin(error / 2);
  CHECK((made.back() - ell.back()).norm() == Approx(chord).epsilon(1e-9));
  CHECK(dense_distance(made, ell, 4000) == Approx(chord).epsilon(1e-6));
  CHECK(arclength_distance(ell, made) == Approx(chord).epsilon(1e-9));
  // the offset b is the inverse of a compensated offset the same way: machine b = -2 deg,
  // compensated for 0: every bend comes out 2 deg short
  MachineProfile offset = truth;
  offset.springback_b = -2 * deg;
  const Polyline2 short2 = predict_polyline(make_bend_program(ell, truth), offset);
  CHECK((short2.back() - ell.back()).norm() == Approx(2 * 0.05 * std::sin(1 * deg)).epsilon(1e-9));
  // a profile out of range is refused, naming the key
  MachineProfile bad = truth;
  bad.springback_a = -1.0;
  CHECK_THROWS_WITH(predict_polyline(p, bad), Contains("springback_a"));
}

TEST_CASE("bend program: limits are refused with messages naming the bend or step", "[fab][bend_program]") {
  const MachineProfile m;
  SECTION("a bend over the maximum reliable angle") {
    const Polyline2 p = walk({0, 0}, 0, {0.02, 0.02, 0.02}, {40 * deg, 130 * deg});
    CHECK_THROWS_WITH(make_bend_program(p, m), Contains("bend 2") && Contains("40.0 mm from the cut") &&
                                                   Contains("130.00 deg") &&
                                                   Contains("120.00 deg"));
  }
  SECTION("a commanded angle beyond the head's range") {
    MachineProfile soft = m;
    soft.springback_a = 0.7;  // 119 deg needs 170 deg
    const Polyline2 p = walk({0, 0}, 0, {0.02, 0.02}, {119 * deg});
    CHECK_THROWS_AS(make_bend_program(p, soft), InputError);
    CHECK_THROWS_WITH(make_bend_program(p, soft), Contains("bend 1") && Contains("target 119.00 deg") &&
                                                      Contains("170.00 deg") && Contains("150.00 deg"));
  }
  SECTION("a target the fit cannot reach") {
    MachineProfile offset = m;
    offset.springback_b = 5 * deg;  // the head makes at least 5 deg
    const Polyline2 p = walk({0, 0}, 0, {0.02, 0.02}, {3 * deg});
    CHECK_THROWS_WITH(make_bend_program(p, offset), Contains("bend 1") && Contains("3.00 deg"));
  }
  SECTION("a feed shorter than l_min") {
    const Polyline2 p = walk({0, 0}, 0, {0.02, 0.010, 0.02}, {30 * deg, 30 * deg});
    CHECK_THROWS_WITH(make_bend_program(p, m), Contains("step 2") && Contains("10.000 mm") && Contains("15.000 mm") &&
                                                   Contains("between bends 1 and 2, 20.0 mm from the cut"));
  }
  SECTION("a bend 0.1 deg over the limit, and one 0.1 deg under it") {
    CHECK_THROWS_WITH(make_bend_program(walk({0, 0}, 0, {0.02, 0.02}, {120.1 * deg}), m),
                      Contains("bend 1") && Contains("120.10 deg"));
    CHECK(bend_program_problems(walk({0, 0}, 0, {0.02, 0.02}, {-120.1 * deg}), m).size() == 1);
    CHECK(bend_program_problems(walk({0, 0}, 0, {0.02, 0.02}, {119.9 * deg}), m).empty());
    CHECK_NOTHROW(make_bend_program(walk({0, 0}, 0, {0.02, 0.02}, {119.9 * deg}), m));
  }
  SECTION("a bend or a feed just past its limit reads past it: the same decimals, enough of them") {
    // 120.001 deg and 120 deg both read 120.00 with two decimals, the limit 120.0 with one
    CHECK_THROWS_WITH(make_bend_program(walk({0, 0}, 0, {0.02, 0.02}, {120.001 * deg}), m),
                      Contains("turns 120.001 deg, more than the machine's maximum reliable bend of 120.000 deg"));
    CHECK_THROWS_WITH(make_bend_program(walk({0, 0}, 0, {0.02, 0.02}, {-120.001 * deg}), m),
                      Contains("turns -120.001 deg, more than the machine's maximum reliable bend of 120.000 deg"));
    CHECK_THROWS_WITH(make_bend_program(walk({0, 0}, 0, {0.02, 0.02}, {120.1 * deg}), m),
                      Contains("turns 120.10 deg, more than the machine's maximum reliable bend of 120.00 deg"));
    // 14.9999 mm and 15 mm both read 15.000 with three decimals
    CHECK_THROWS_WITH(make_bend_program(walk({0, 0}, 0, {0.02, 0.0149999, 0.02}, {30 * deg, 30 * deg}), m),
                      Contains("step 2 feeds 14.9999 mm") &&
                          Contains("shorter than the machine's minimum feed between bends of 15.0000 mm"));
  }
  SECTION("every problem is listed, with the numbers of make_bend_program's message") {
    // bends 1..4 at 20, 40, 45, 65 mm: bend 2 over, the feed between bends 2 and 3 5 mm, bend 4 over
    const Polyline2 p = walk({0, 0}, 0, {0.02, 0.02, 0.005, 0.02, 0.02},
                             {30 * deg, 125 * deg, 30 * deg, -121 * deg});
    const auto problems = bend_program_problems(p, m);
    REQUIRE(problems.size() == 3);
    CHECK(problems[0].kind == BendProblem::Kind::over_bend);
    CHECK(problems[0].number == 2);
    CHECK(problems[0].from == 2);
    CHECK(problems[0].at == Approx(0.04));
    CHECK(to_deg(problems[0].value) == Approx(125.0));
    CHECK(problems[1].kind == BendProblem::Kind::over_bend);
    CHECK(problems[1].number == 4);
    CHECK(problems[1].at == Approx(0.065));
    CHECK(problems[2].kind == BendProblem::Kind::short_feed);
    CHECK(problems[2].number == 3);
    CHECK(problems[2].from == 2);
    CHECK(problems[2].to == 3);
    CHECK(problems[2].value == Approx(0.005));
    CHECK_THAT(problems[2].message, Contains("between bends 2 and 3"));
    CHECK_THROWS_WITH(make_bend_program(p, m), Equals(problems[0].message));
  }
  SECTION("bad polylines") {
    CHECK_THROWS_AS(make_bend_program(Polyline2{{0, 0}}, m), InputError);
    CHECK_THROWS_WITH(make_bend_program(Polyline2{{0, 0}, {0.02, 0}, {0.02, 0}}, m), Contains("segment 1"));
    CHECK_THROWS_WITH(make_bend_program(Polyline2{{0, 0}, {NAN, 0}}, m), Contains("point 1"));
  }
  SECTION("a bad profile") {
    MachineProfile bad = m;
    bad.springback_a = 0.0;
    CHECK_THROWS_WITH(make_bend_program(walk({0, 0}, 0, {0.02, 0.02}, {10 * deg}), bad), Contains("springback_a"));
  }
}

TEST_CASE("bend program: small turns are accumulated into the next bend", "[fab][bend_program]") {
  const MachineProfile m;  // min_bend = 1 deg
  const double L0 = 0.04, L1 = 0.03, L2 = 0.04;
  const Polyline2 poly = walk({0, 0}, 0, {L0, L1, L2}, {0.4 * deg, 90 * deg});
  const BendProgram p = make_bend_program(poly, m);
  REQUIRE(p.steps.size() == 2);
  CHECK(p.steps[0].feed == Approx(L0 + L1));
  CHECK(p.steps[0].bend == Approx(90.4 * deg));
  CHECK(p.steps[0].vertex == 2);
  CHECK(p.steps[1].feed == Approx(L2));
  CHECK(p.merged_points == 1);
  CHECK(p.small_turns == 1);
  CHECK(p.dropped_turn == 0.0);
  // By hand: the rebuilt wire is straight to point 2, then the headings agree again, so the
  // error is the chord of the 0.4 deg turn over L1: 2 L1 sin(0.2 deg), constant afterwards.
  CHECK(p.shape_error == Approx(2 * L1 * std::sin(0.2 * deg)).epsilon(1e-9));
  CHECK(p.shape_error == Approx(dense_distance(poly, rebuild_polyline(p), 20000)).epsilon(1e-6));
}

TEST_CASE("bend program: a small turn after the last bend is dropped and reported", "[fab][bend_program]") {
  const MachineProfile m;
  const double L2 = 0.05;
  const Polyline2 poly = walk({0, 0}, 0.4, {0.03, 0.03, L2}, {45 * deg, -0.45 * deg});
  const BendProgram p = make_bend_program(poly, m);
  REQUIRE(p.steps.size() == 2);
  CHECK(p.steps[1].feed == Approx(0.03 + L2));
  CHECK(p.dropped_turn == Approx(-0.45 * deg));
  CHECK(p.shape_error == Approx(2 * L2 * std::sin(0.225 * deg)).epsilon(1e-9));
  CHECK(p.shape_error == Approx(dense_distance(poly, rebuild_polyline(p), 20000)).epsilon(1e-6));
}

TEST_CASE("bend program: a gentle arc of sub-degree turns keeps its total turn", "[fab][bend_program]") {
  const MachineProfile m;
  std::vector<double> feeds(40, 0.016), turns(39, 0.4 * deg);
  const Polyline2 poly = walk({0.1, 0.2}, 1.0, feeds, turns);
  const BendProgram p = make_bend_program(poly, m);
  double total = 0.0;
  for (const BendStep& s : p.steps) {
    total += s.bend;
    if (s.vertex >= 0) CHECK(std::abs(s.bend) >= m.min_bend - 1e-12);
  }
  CHECK(total + p.dropped_turn == Approx(39 * 0.4 * deg).epsilon(1e-12));
  // By hand: carries 0.4, 0.8 -> bend 1 (carry -0.2), 0.2, 0.6 -> bend 1 (carry -0.4), 0.0: two
  // bends of exactly 1 deg every five points, the pattern repeating; 39 = 7 * 5 + 4 points give
  // 7 * 2 + 2 = 16 bends, and the last point leaves 0.6 - 1 = -0.4 deg to drop.
  CHECK(p.bend_count == 16);
  CHECK(p.rounded_bends == 16);
  CHECK(p.dropped_turn == Approx(-0.4 * deg));
  for (const BendStep& s : p.steps)
    if (s.vertex >= 0) CHECK(s.bend == Approx(1.0 * deg));
  const double independent = dense_distance(poly, rebuild_polyline(p), 50000);
  CHECK(p.shape_error == Approx(independent).epsilon(1e-4));
  CHECK(p.shape_error == Approx(arclength_distance(poly, rebuild_polyline(p))));
  CHECK(p.shape_error < 0.5e-3);  // well under a millimetre for a 64 cm wire
}

TEST_CASE("bend program: a turn between half and one min_bend is rounded up, the rest carried", "[fab][bend_program]") {
  const MachineProfile m;
  const double L1 = 0.03;
  const Polyline2 poly = walk({0, 0}, 0, {0.02, L1, 0.02}, {0.7 * deg, 30 * deg});
  const BendProgram p = make_bend_program(poly, m);
  REQUIRE(p.bend_count == 2);
  CHECK(p.steps[0].bend == Approx(1.0 * deg));
  CHECK(p.steps[1].bend == Approx(29.7 * deg));
  CHECK(p.rounded_bends == 1);
  // By hand: the segment after point 1 is 0.3 deg too far left; the headings agree after point 2.
  CHECK(p.shape_error == Approx(2 * L1 * std::sin(0.15 * deg)).epsilon(1e-9));
  CHECK(p.shape_error == Approx(dense_distance(poly, rebuild_polyline(p), 20000)).epsilon(1e-6));
}

TEST_CASE("bend program: a carry that would overbend waits for the next point", "[fab][bend_program]") {
  const MachineProfile m;  // max_bend = 120 deg
  const Polyline2 poly = walk({0, 0}, 0, {0.02, 0.02, 0.02, 0.02}, {0.45 * deg, 119.8 * deg, 10 * deg});
  const BendProgram p = make_bend_program(poly, m);
  REQUIRE(p.bend_count == 2);
  CHECK(p.steps[0].bend == Approx(119.8 * deg));
  CHECK(p.steps[1].bend == Approx(10.45 * deg));
  CHECK(p.shape_error == Approx(dense_distance(poly, rebuild_polyline(p), 20000)).epsilon(1e-6));
}

TEST_CASE("bend program: absurd lengths are refused before anything overflows", "[fab]") {
  using Catch::Matchers::Contains;
  const Polyline2 huge{{0, 0}, {1e300, 0}, {1e300, 1e300}};
  CHECK_THROWS_WITH(wiresculpt::fab::make_bend_program(huge, wiresculpt::fab::MachineProfile{}),
                    Contains("segment 0") && Contains("not in metres"));
}

TEST_CASE("machine profile: huge values are refused, naming the profile's key", "[fab][bend_program]") {
  const MachineProfile m;
  CHECK_NOTHROW(validate(m));
  MachineProfile bad = m;
  bad.min_feed = 1e300;  // a hand-edited file's 1e300 m
  CHECK_THROWS_WITH(validate(bad), Contains("min_segment") && Contains("at most 1 m"));
  bad = m;
  bad.max_bend = from_deg(720.0);
  CHECK_THROWS_WITH(validate(bad), Contains("max_bend_deg") && Contains("180 deg"));
  bad = m;
  bad.springback_b = from_deg(-1e9);
  CHECK_THROWS_WITH(validate(bad), Contains("springback_b_deg"));
  bad = m;
  bad.feed_speed = 1e12;
  CHECK_THROWS_WITH(validate(bad), Contains("feed_speed_mm_s"));
  bad = m;
  bad.axes.feed_units_per_mm = 1e7;
  CHECK_THROWS_WITH(validate(bad), Contains("feed_units_per_mm"));
  bad = m;
  bad.serial.baud = 2000000000;
  CHECK_THROWS_WITH(validate(bad), Contains("baud"));
  bad = m;  // the largest values allowed pass
  bad.min_feed = 1.0;
  bad.max_bend = from_deg(180.0);
  bad.max_commanded = from_deg(360.0);
  bad.serial.baud = 10000000;
  CHECK_NOTHROW(validate(bad));
}
