#include "target_shape_messages.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "figures.hpp"

namespace wiresculpt::detail {
namespace {
constexpr double pi = std::numbers::pi;

std::string crossing_name(int crossing, const std::string& wire) {
  return "crossing " + std::to_string(crossing) + " on wire " + wire;
}

// A contact angle wide enough for the machine, when one is: the bend is 180° less the contact
// angle, plus twice the friction angle, so a contact angle of at least 180° - max_bend + 2 atan(μ)
// fits (rounded up where it is shown, so that the figure given does fit; none from 180° on: then
// only a larger bend helps).
std::string fitting_contact_angle(const CrossingFigures& f) {
  const double fits = (pi - f.limit + 2.0 * f.friction_angle) * 180.0 / pi;
  const double step = fits >= 100.0 ? 1.0 : fits >= 10.0 ? 0.1 : 0.01;  // deg()'s 3 digits
  return fits < 180.0 ? ": a contact angle of at least " + fmt(std::ceil(fits / step - 1e-9) * step, 3) + "° fits"
                      : std::string();
}

// Two crossings with no room for a free bending point between them, and the scale that makes room.
// `what`: a clause on the piece between them, after a comma, or empty.
std::string gap_sentence(const std::string& wire, const CrossingFigures& f, const std::string& what = {}) {
  std::string msg = "crossings " + std::to_string(f.first) + " and " + std::to_string(f.second) + " on wire " + wire +
                    " are " + mm(f.length) + " apart along the wire" + (what.empty() ? "" : ", " + what) +
                    "; a free bending point between them needs " +
                    mm(2.0 * f.limit) + ": " + scale_words(f.scale, f.model_size);
  return msg;
}
}  // namespace

std::string fmt(double v, int precision) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}
std::string mm(double metres) { return fmt(metres * 1000.0, 3) + " mm"; }
std::string deg(double radians) { return fmt(radians * 180.0 / pi, 3) + "°"; }

}  // namespace wiresculpt::detail

namespace wiresculpt {
const char* cause_name(CrossingCause cause) {
  switch (cause) {
    case CrossingCause::none: return "none";
    case CrossingCause::open_end: return "open_end";
    case CrossingCause::contact_vs_friction: return "contact_vs_friction";
    case CrossingCause::min_bend: return "min_bend";
    case CrossingCause::short_piece: return "short_piece";
    case CrossingCause::fixed_edge: return "fixed_edge";
    case CrossingCause::cone_missed: return "cone_missed";
    case CrossingCause::neighbour_bend: return "neighbour_bend";
    case CrossingCause::neighbour_segment: return "neighbour_segment";
  }
  return "none";
}
}  // namespace wiresculpt

namespace wiresculpt::detail {
const char* cause_status(CrossingCause cause) {
  switch (cause) {
    case CrossingCause::none: return "ok";
    case CrossingCause::open_end: return "open_end";
    case CrossingCause::short_piece:
    case CrossingCause::fixed_edge: return "too_close";
    case CrossingCause::contact_vs_friction:
    case CrossingCause::min_bend:
    case CrossingCause::cone_missed:
    case CrossingCause::neighbour_bend:
    case CrossingCause::neighbour_segment: return "infeasible";
  }
  return "infeasible";
}

CrossingSentence crossing_sentence(int crossing, const std::string& wire, CrossingCause cause,
                                   const CrossingFigures& f) {
  // A predicate follows the crossing's name ("crossing 3 on wire W needs …", words "it needs …");
  // a clause follows it after a colon ("crossing 3 on wire W: the kink …", words "the kink …").
  auto predicate = [&](const std::string& rest) {
    return CrossingSentence{crossing_name(crossing, wire) + " " + rest, "it " + rest};
  };
  auto clause = [&](const std::string& rest) { return CrossingSentence{crossing_name(crossing, wire) + ": " + rest, rest}; };
  switch (cause) {
    case CrossingCause::none: return {};
    case CrossingCause::open_end:
      return predicate("is at an end of the open wire, where the wire has no kink to open");
    case CrossingCause::contact_vs_friction:
      return predicate("asks for contact angle " + deg(f.contact_angle) +
                       ", which is not wider than twice the friction angle atan(μ) = " + deg(f.friction_angle));
    case CrossingCause::min_bend:
      return predicate("needs a bend of at least " + deg(f.bend) + " (180° less the contact angle " +
                       deg(f.contact_angle) +
                       (f.friction_angle > 0.0 ? ", plus twice the friction angle " + deg(f.friction_angle)
                                               : std::string()) +
                       ") but the machine bends at most " + deg(f.limit) + fitting_contact_angle(f));
    case CrossingCause::short_piece: {
      // the direct segment is too short to bend: a fabrication problem whatever the hooks
      const std::string msg = gap_sentence(wire, f, "the straight piece between them shorter than the minimum segment");
      return {msg, msg};
    }
    case CrossingCause::fixed_edge: {
      const std::string msg = gap_sentence(wire, f);
      return {msg, msg};
    }
    case CrossingCause::cone_missed:
      return clause("the kink could not be opened towards the desired bisector within the fabrication limits (an edge is " +
                    deg(f.violation) + " outside the contact cone)");
    case CrossingCause::neighbour_bend:
    case CrossingCause::neighbour_segment: {
      // the figure and the limit it breaks with the same decimals, enough to tell them apart
      const bool bend = cause == CrossingCause::neighbour_bend;
      const auto [shown, limit] = bend ? versus(f.bend * 180.0 / pi, f.limit * 180.0 / pi, 1)
                                       : versus(f.length * 1000.0, f.limit * 1000.0, 2);
      return clause("its kink cannot be made within the machine's limits: next to it, at point " +
                    std::to_string(f.point) + ", the wire " +
                    (bend ? "bends " + shown + "°, more than " + limit + "°"
                          : "has a segment of " + shown + " mm, less than " + limit + " mm"));
    }
  }
  return {};
}

void set_cause(TargetCrossingStatus& s, int crossing, const std::string& wire, CrossingCause cause,
               const CrossingFigures& figures) {
  s.status = cause_status(cause);
  s.realised = false;
  s.cause = cause;
  s.figures = figures;
  s.scale = figures.scale;
  CrossingSentence sentence = crossing_sentence(crossing, wire, cause, figures);
  s.message = std::move(sentence.message);
  s.words = std::move(sentence.words);
}

}  // namespace wiresculpt::detail
