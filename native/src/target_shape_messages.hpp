#pragma once
// Every sentence of the target-shape stage about a crossing it cannot realise, made here from the
// crossing's cause and figures (TargetCrossingStatus::cause, figures), and the number formats its
// other messages share (internal to the core).
#include <string>

#include "wiresculpt/target_shape.hpp"

namespace wiresculpt::detail {

/// `v` with `precision` significant digits, as std::ostream prints it ("9", "0.31", "1.2").
std::string fmt(double v, int precision = 3);
/// Metres as millimetres with three significant digits: "9 mm".
std::string mm(double metres);
/// Radians as degrees with three significant digits: "120°".
std::string deg(double radians);

/// The status a cause gives its crossing: "open_end", "too_close" or "infeasible" ("ok" for none).
const char* cause_status(CrossingCause cause);

/// A crossing's sentence: `message`, whole ("crossing 3 on wire A/0 needs a bend of at least …"),
/// and `words`, what follows its name in "crossing N on wire W: " ("it needs a bend of at least …"),
/// for a caller that names the crossing its own way; a sentence about two crossings (too_close)
/// does not start with one name and is its own words.
struct CrossingSentence {
  std::string message, words;
};
/// The sentence of crossing `crossing` (its index along the wire) of wire `wire` for `cause`
/// (not none) with its figures.
CrossingSentence crossing_sentence(int crossing, const std::string& wire, CrossingCause cause,
                                   const CrossingFigures& figures);

/// Marks `s` as not realised for `cause`: its status, cause, figures and sentence.
void set_cause(TargetCrossingStatus& s, int crossing, const std::string& wire, CrossingCause cause,
               const CrossingFigures& figures);

}  // namespace wiresculpt::detail
