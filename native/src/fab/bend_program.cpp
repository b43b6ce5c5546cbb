#include "wiresculpt/fab/bend_program.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "../figures.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {
namespace {

constexpr double kFeedSlack = 1e-9;   // m: numerical slack on l_min (an optimiser's active bound)
constexpr double kAngleSlack = 1e-12; // rad

std::string fmt(double value, int decimals = 1) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

std::vector<double> cumulative_length(const Polyline2& p) {
  std::vector<double> s(p.size(), 0.0);
  for (std::size_t i = 1; i < p.size(); ++i) s[i] = s[i - 1] + (p[i] - p[i - 1]).norm();
  return s;
}

// No machine feeds more than this in one go; longer segments mean the units are wrong (and
// past ~1e154 m the lengths overflow).
constexpr double kMaxSegment = 1000.0;

Vec2 point_at(const Polyline2& p, const std::vector<double>& s, double t) {
  if (p.size() == 1 || !(t > 0.0)) return p.front();  // also NaN
  if (!(t < s.back())) return p.back();
  const auto it = std::upper_bound(s.begin(), s.end(), t);
  const std::size_t i = static_cast<std::size_t>(it - s.begin());  // s[i-1] <= t < s[i]
  const double len = s[i] - s[i - 1];
  const double u = len > 0.0 ? (t - s[i - 1]) / len : 0.0;
  return (1.0 - u) * p[i - 1] + u * p[i];
}

}  // namespace

double compensate(double target, const MachineProfile& profile, int bend_number) {
  const double magnitude = (std::abs(target) - profile.springback_b) / profile.springback_a;
  const std::string which = "bend " + std::to_string(bend_number) + " (target " +
                            fmt(to_deg(target), 2) + " deg)";
  if (!(magnitude > 0.0))
    throw InputError(which + " is below what the calibration fit can make: measured = " +
                     fmt(profile.springback_a, 4) + " * commanded + " +
                     fmt(to_deg(profile.springback_b), 3) + " deg gives no positive command");
  if (magnitude > profile.max_commanded + kAngleSlack)
    throw InputError(which + " needs a commanded angle of " + fmt(to_deg(magnitude), 2) +
                     " deg after spring-back compensation, beyond the bending head's range of " +
                     fmt(to_deg(profile.max_commanded), 2) + " deg");
  return std::copysign(magnitude, target);
}

namespace {

std::string from_cut(double metres) { return fmt(to_mm(metres), 1) + " mm from the cut"; }

// Feeds: every one must reach l_min. Step k feeds the wire before bend k (the G-code's and the
// bend table's numbering), so a feed is named by the bends around it. s_at: arc length from the
// cut at each input point; feed_start: the input point where each step's feed starts.
void check_feeds(const BendProgram& prog, const MachineProfile& profile, const std::vector<double>& s_at,
                 const std::vector<std::size_t>& feed_start, std::vector<BendProblem>& problems) {
  const std::size_t n = s_at.size();
  const int bends = static_cast<int>(prog.steps.size()) - 1;
  for (std::size_t k = 0; k < prog.steps.size(); ++k) {
    const BendStep& s = prog.steps[k];
    if (s.feed + kFeedSlack < profile.min_feed) {
      const int step = static_cast<int>(k) + 1;
      const std::size_t to = s.vertex >= 0 ? static_cast<std::size_t>(s.vertex) : n - 1;
      const std::string where = step == 1 ? (bends > 0 ? "from the cut to bend 1" : "the whole wire")
                                : s.vertex < 0 ? "after bend " + std::to_string(bends) + ", to the end"
                                               : "between bends " + std::to_string(step - 1) + " and " +
                                                     std::to_string(step);
      const auto [fed, least] = detail::versus(to_mm(s.feed), to_mm(profile.min_feed), 3);
      problems.push_back({BendProblem::Kind::short_feed, step, static_cast<int>(feed_start[k]), static_cast<int>(to),
                          s_at[feed_start[k]], s.feed, profile.min_feed,
                          "step " + std::to_string(step) + " feeds " + fed + " mm (" + where + ", " +
                              from_cut(s_at[feed_start[k]]) +
                              "), shorter than the machine's minimum feed between bends of " + least + " mm"});
    }
  }
}

// The commanded angles (spring-back compensation) and the machine time of every step.
void compensate_and_time(BendProgram& prog, const MachineProfile& profile, const std::vector<double>& s_at,
                         std::vector<BendProblem>& problems) {
  for (std::size_t k = 0; k < prog.steps.size(); ++k) {
    BendStep& s = prog.steps[k];
    prog.wire_length += s.feed;
    if (s.vertex < 0) {
      prog.machine_seconds += s.feed / profile.feed_speed;
      continue;
    }
    if (std::abs(s.bend) > profile.max_bend + kAngleSlack) continue;  // already a problem: over the limit
    try {
      s.commanded = compensate(s.bend, profile, static_cast<int>(k + 1));
    } catch (const InputError& e) {
      problems.push_back({BendProblem::Kind::command, static_cast<int>(k) + 1, s.vertex, s.vertex,
                          s_at[static_cast<std::size_t>(s.vertex)], std::abs(s.bend), profile.max_commanded,
                          e.what()});
      continue;
    }
    prog.machine_seconds += std::max(profile.seconds_per_bend,
                                     s.feed / profile.feed_speed + 2.0 * std::abs(s.commanded) / profile.bend_speed);
  }
}

// The program and everything that keeps it from being made (bend_program.hpp); input errors throw.
BendProgram build(const Polyline2& points, const MachineProfile& profile, std::vector<BendProblem>& problems) {
  validate(profile);
  const std::size_t n = points.size();
  if (n < 2)
    throw InputError("a wire needs at least 2 points to make a bend program, got " + std::to_string(n));
  for (std::size_t i = 0; i < n; ++i)
    if (!points[i].allFinite())
      throw InputError("point " + std::to_string(i) + " of the wire has a non-finite coordinate");
  std::vector<double> L(n - 1);
  std::vector<double> s_at(n, 0.0);  // arc length from the cut at each input point
  for (std::size_t i = 0; i + 1 < n; ++i) {
    L[i] = (points[i + 1] - points[i]).norm();
    if (!(L[i] > 1e-12))
      throw InputError("segment " + std::to_string(i) + " (points " + std::to_string(i) + " and " +
                       std::to_string(i + 1) + ") has zero length; remove the repeated point");
    if (!(L[i] < kMaxSegment))
      throw InputError("segment " + std::to_string(i) + " (points " + std::to_string(i) + " and " +
                       std::to_string(i + 1) + ") is longer than " + fmt(kMaxSegment, 0) +
                       " m: the points are not in metres");
    s_at[i + 1] = s_at[i] + L[i];
  }

  BendProgram prog;
  prog.start = points[0];
  const Vec2 e0 = points[1] - points[0];
  prog.start_heading = std::atan2(e0.y(), e0.x());
  prog.input_points = n;

  // The small-bend rule (header): accumulate small turns into the next bend, merging feeds.
  double feed = L[0];
  double carry = 0.0;
  std::size_t feed_from = 0;  // input point where the current feed starts
  std::vector<std::size_t> feed_start;
  for (std::size_t j = 1; j + 1 < n; ++j) {
    const Vec2 a = points[j] - points[j - 1];
    const Vec2 b = points[j + 1] - points[j];
    const double theta = std::atan2(cross(a, b), a.dot(b));
    const double t = theta + carry;
    const double at = std::abs(t);
    if (at + kAngleSlack >= 0.5 * profile.min_bend && at > 0.0) {
      double made = t;
      if (at + kAngleSlack < profile.min_bend) {  // round up to the smallest reliable bend
        made = std::copysign(profile.min_bend, t);
        carry = t - made;
        ++prog.rounded_bends;
      } else if (at > profile.max_bend + kAngleSlack) {
        if (std::abs(theta) > profile.max_bend + kAngleSlack) {
          const int bend = static_cast<int>(prog.steps.size()) + 1;
          const auto [turn, most] = detail::versus(to_deg(theta), to_deg(profile.max_bend), 2);
          problems.push_back({BendProblem::Kind::over_bend, bend, static_cast<int>(j), static_cast<int>(j),
                              s_at[j], std::abs(theta), profile.max_bend,
                              "bend " + std::to_string(bend) + " (" + from_cut(s_at[j]) + ") turns " + turn +
                                  " deg, more than the machine's maximum reliable bend of " + most + " deg"});
          carry = 0.0;  // made as asked, to go on listing what else keeps the wire from being made
        } else {
          made = theta;  // keep the carry for the next point rather than overbend here
        }
      } else {
        carry = 0.0;
      }
      BendStep step;
      step.feed = feed;
      step.bend = made;
      step.vertex = static_cast<int>(j);
      prog.steps.push_back(step);
      feed_start.push_back(feed_from);
      feed = L[j];
      feed_from = j;
    } else {
      carry = t;
      feed += L[j];
      ++prog.merged_points;
      if (std::abs(theta) > kAngleSlack) ++prog.small_turns;
    }
  }
  BendStep last;
  last.feed = feed;
  prog.steps.push_back(last);
  feed_start.push_back(feed_from);
  prog.dropped_turn = carry;
  prog.bend_count = static_cast<int>(prog.steps.size()) - 1;

  check_feeds(prog, profile, s_at, feed_start, problems);
  compensate_and_time(prog, profile, s_at, problems);

  prog.shape_error = arclength_distance(points, rebuild_polyline(prog));
  return prog;
}

}  // namespace

BendProgram make_bend_program(const Polyline2& points, const MachineProfile& profile) {
  std::vector<BendProblem> problems;
  BendProgram prog = build(points, profile, problems);
  if (!problems.empty()) throw InputError(problems.front().message);
  return prog;
}

std::vector<BendProblem> bend_program_problems(const Polyline2& points, const MachineProfile& profile) {
  std::vector<BendProblem> problems;
  build(points, profile, problems);
  return problems;
}

Polyline2 rebuild_polyline(const BendProgram& program, bool from_origin) {
  Polyline2 out;
  Vec2 p = from_origin ? Vec2::Zero() : program.start;
  double heading = from_origin ? 0.0 : program.start_heading;
  out.push_back(p);
  for (const BendStep& s : program.steps) {
    p += s.feed * Vec2(std::cos(heading), std::sin(heading));
    out.push_back(p);
    heading += s.bend;
  }
  return out;
}

Polyline2 predict_polyline(const BendProgram& program, const MachineProfile& machine) {
  validate(machine);
  Polyline2 out;
  Vec2 p = program.start;
  double heading = program.start_heading;
  out.push_back(p);
  for (const BendStep& s : program.steps) {
    p += s.feed * Vec2(std::cos(heading), std::sin(heading));
    out.push_back(p);
    if (s.vertex >= 0 && s.commanded != 0.0)
      heading += std::copysign(machine.springback_a * std::abs(s.commanded) + machine.springback_b, s.commanded);
  }
  return out;
}

std::vector<std::size_t> bend_vertices(const BendProgram& program) {
  std::vector<std::size_t> out;
  for (const BendStep& s : program.steps)
    if (s.vertex >= 0) out.push_back(static_cast<std::size_t>(s.vertex));
  return out;
}

double arclength_distance(const Polyline2& a, const Polyline2& b) {
  if (a.empty() || b.empty()) return 0.0;
  const std::vector<double> sa = cumulative_length(a), sb = cumulative_length(b);
  double worst = 0.0;
  for (double t : sa) worst = std::max(worst, (point_at(a, sa, t) - point_at(b, sb, t)).norm());
  for (double t : sb) worst = std::max(worst, (point_at(a, sa, t) - point_at(b, sb, t)).norm());
  return worst;
}

}  // namespace wiresculpt::fab
