// The cause of every crossing the target shape cannot realise (TargetCrossingStatus::cause), each
// from a wire built to fail that way, and the sentences made from a cause and its figures
// (target_shape_messages.cpp) against texts written out by hand.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "contour_fixtures.hpp"
#include "target_shape_messages.hpp"
#include "wiresculpt/target_shape.hpp"

using namespace wiresculpt;
using fixtures::hairpin;
using fixtures::line;

namespace {
constexpr double pi = std::numbers::pi;

TargetShapeOptions named(const char* wire) {
  TargetShapeOptions o;
  o.wire_name = wire;
  return o;
}
}  // namespace

TEST_CASE("target shape causes: each failure before the solve names its cause", "[target][causes]") {
  const Polyline2 contour = line(0.3, 301);  // 1 mm apart
  const TargetShapeOptions o = named("W");   // μ = 0.32: 2 atan μ = 35.5°; l_min 15 mm; bends <= 120°
  SECTION("an active crossing at an open end") {
    const auto r = optimize_target_shape(contour, false, {{0, Vec2(0, 1), 2 * pi / 3, true}}, o);
    CHECK(r.crossings[0].status == "open_end");
    CHECK(r.crossings[0].cause == CrossingCause::open_end);
    CHECK(r.crossings[0].words == "it is at an end of the open wire, where the wire has no kink to open");
  }
  SECTION("a contact angle of 30°, not wider than 35.5°") {
    const auto r = optimize_target_shape(contour, false, {{150, Vec2(0, 1), pi / 6, true}}, o);
    CHECK(r.crossings[0].status == "infeasible");
    CHECK(r.crossings[0].cause == CrossingCause::contact_vs_friction);
    CHECK(r.crossings[0].figures.contact_angle == Approx(pi / 6));
    CHECK(r.crossings[0].figures.friction_angle == Approx(std::atan(0.32)));
  }
  SECTION("a contact angle of 50°: a bend of 180 - 50 + 35.5 = 165.5° > 120°") {
    const auto r = optimize_target_shape(contour, false, {{150, Vec2(0, 1), 50 * pi / 180, true}}, o);
    CHECK(r.crossings[0].status == "infeasible");
    CHECK(r.crossings[0].cause == CrossingCause::min_bend);
    CHECK(r.crossings[0].figures.bend * 180 / pi == Approx(180.0 - 50.0 + 2 * std::atan(0.32) * 180 / pi));
    CHECK(r.crossings[0].figures.limit == Approx(2 * pi / 3));
  }
  SECTION("crossings 9 mm apart: a straight piece under 15 mm") {
    const auto r = optimize_target_shape(contour, false, {{100, Vec2(0, 1), 2 * pi / 3, true},
                                                          {109, Vec2(0, -1), 2 * pi / 3, true}}, o);
    for (const auto& s : r.crossings) {
      CHECK(s.status == "too_close");
      CHECK(s.cause == CrossingCause::short_piece);
      CHECK(s.figures.first == 0);
      CHECK(s.figures.second == 1);
      CHECK(s.figures.length == Approx(0.009));
      CHECK(s.words == s.message);
    }
  }
  SECTION("crossings 25 mm apart: a fixed piece 90° from h*, outside the 42.3° cone") {
    const auto r = optimize_target_shape(contour, false, {{100, Vec2(0, 1), 2 * pi / 3, true},
                                                          {125, Vec2(0, -1), 2 * pi / 3, false}}, o);
    CHECK(r.crossings[0].status == "too_close");
    CHECK(r.crossings[0].cause == CrossingCause::fixed_edge);
    CHECK(r.crossings[0].scale == Approx(1.2));
    CHECK(r.crossings[1].cause == CrossingCause::none);
  }
  SECTION("a realised crossing has none") {
    const auto r = optimize_target_shape(contour, false, {{150, Vec2(0, 1), 2 * pi / 3, true}}, o);
    CHECK(r.crossings[0].status == "ok");
    CHECK(r.crossings[0].cause == CrossingCause::none);
    CHECK(r.crossings[0].message.empty());
    CHECK(r.crossings[0].words.empty());
  }
}

TEST_CASE("target shape causes: kinks the solve cannot open name their cause", "[target][causes]") {
  SECTION("one free point between two crossings that want it on either side of the wire") {
    const auto r = optimize_target_shape(line(0.3, 301), false, {{100, Vec2(0, 1), 2 * pi / 3, true},
                                                                 {131, Vec2(0, -1), 2 * pi / 3, true}}, named("C"));
    int failed = 0;
    for (const auto& s : r.crossings) {
      if (s.status == "ok") continue;
      ++failed;
      CHECK(s.cause == CrossingCause::cone_missed);
      CHECK(s.figures.violation == s.contact_violation);
    }
    CHECK(failed >= 1);
  }
  SECTION("a hairpin 18 mm after the kink: the free point next to it bends over 120°") {
    // along +x to the kink at the origin, 18 mm on, back by 140° and 21 mm to a null crossing
    const auto [contour, a_vertex, b_vertex] = hairpin(0.06);
    TargetShapeOptions o = named("H");
    o.friction = 0.0;
    o.angle_tolerance = 0.1 * pi / 180.0;
    o.length_tolerance = 1e-5;
    const auto r = optimize_target_shape(contour, false, {{a_vertex, Vec2(0, 1), 2 * pi / 3, true},
                                                          {b_vertex, Vec2(0, 1), 2 * pi / 3, false}}, o);
    const auto& s = r.crossings[0];
    CHECK(s.status == "infeasible");
    CHECK(s.cause == CrossingCause::neighbour_bend);
    CHECK(s.figures.bend > 2 * pi / 3 + o.angle_tolerance);
    CHECK(s.figures.limit == Approx(2 * pi / 3));
    CHECK(std::abs(s.figures.point - r.crossing_vertices[0]) == 1);
  }
}

TEST_CASE("target shape causes: each cause's sentence from its figures", "[target][causes]") {
  CrossingFigures f;
  f.contact_angle = pi / 6;
  f.friction_angle = 10 * pi / 180;
  auto sentence = [&](CrossingCause cause) { return detail::crossing_sentence(2, "A/0", cause, f); };
  SECTION("a predicate after the name, and its words with \"it\"") {
    const auto s = sentence(CrossingCause::contact_vs_friction);
    CHECK(s.message ==
          "crossing 2 on wire A/0 asks for contact angle 30°, which is not wider than twice the friction angle "
          "atan(μ) = 10°");
    CHECK(s.words == "it asks for contact angle 30°, which is not wider than twice the friction angle atan(μ) = 10°");
  }
  SECTION("the least bend, and the contact angle that fits: 180 - 100 + 20 = 100°") {
    f.bend = pi - f.contact_angle + 2 * f.friction_angle;  // 170°
    f.limit = 100 * pi / 180;
    CHECK(sentence(CrossingCause::min_bend).words ==
          "it needs a bend of at least 170° (180° less the contact angle 30°, plus twice the friction angle 10°) but "
          "the machine bends at most 100°: a contact angle of at least 100° fits");
  }
  SECTION("a clause after a colon keeps no \"it\"") {
    f.point = 5;
    f.length = 0.0142;
    f.limit = 0.015;
    const auto s = sentence(CrossingCause::neighbour_segment);
    CHECK(s.message ==
          "crossing 2 on wire A/0: its kink cannot be made within the machine's limits: next to it, at point 5, the "
          "wire has a segment of 14.20 mm, less than 15.00 mm");
    CHECK(s.words ==
          "its kink cannot be made within the machine's limits: next to it, at point 5, the wire has a segment of "
          "14.20 mm, less than 15.00 mm");
  }
  SECTION("two crossings too close: the scale, the size and the short piece") {
    f.first = 3;
    f.second = 4;
    f.length = 0.009;
    f.limit = 0.015;
    f.scale = 30.0 / 9.0;
    f.model_size = 0.093;
    const auto s = sentence(CrossingCause::short_piece);
    CHECK(s.message ==
          "crossings 3 and 4 on wire A/0 are 9 mm apart along the wire, the straight piece between them shorter than the "
          "minimum segment; a free bending point between them needs 30 mm: scale the model up at least 3.33 times "
          "(largest side 0.093 m -> 0.31 m)");
    CHECK(s.words == s.message);
  }
  SECTION("every cause has its own name") {
    CHECK(std::string(cause_name(CrossingCause::short_piece)) == "short_piece");
    CHECK(std::string(cause_name(CrossingCause::contact_vs_friction)) == "contact_vs_friction");
    CHECK(std::string(cause_name(CrossingCause::neighbour_segment)) == "neighbour_segment");
    CHECK(std::string(cause_name(CrossingCause::none)) == "none");
  }
}
