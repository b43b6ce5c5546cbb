#pragma once
// G-code for GRBL-based wire benders, and the bend table (CSV).
//
// Dialect (GRBL 1.1 subset): G21 (mm), G91 (relative moves), G94 (units/min feed rate), G1 moves
// on one axis at a time, G4 P0 (wait until every queued move has finished), M2 (program end),
// ';' comments on their own lines. Axis words come from MachineProfile::axes:
//   feed   <feed_axis><feed_mm * feed_units_per_mm>   F = feed_speed in mm/min * feed_units_per_mm
//   bend   <bend_axis><+-commanded_deg * bend_units_per_deg>, then the opposite move returning the
//          head to neutral; + for a left (counter-clockwise) bend when left_is_positive
//          F = bend_speed in deg/min * bend_units_per_deg
//   pin    (only when pin_axis is set) before a bend on the other side from the previous one,
//          the duck: <pin_axis>-pin_travel (the pin under the wire), <bend_axis>+-pin_swing (the
//          head swings across the wire: + from the positive-bend side to the negative, - back),
//          <pin_axis>+pin_travel (the pin up on the other side), each a rapid G0. The pin starts on
//          the positive-bend side, and a program that ends on the other side ducks back before M2.
// Each step ends with "G4 P0" when sync_each_step, so GRBL's "ok" for that line means the step
// has been executed, not just queued (see docs/machine-protocol.md, resume).
//
// CSV bend table: header "step,feed_mm,bend_deg,commanded_deg", one row per step (1-based),
// bend and commanded 0 on the final, feed-only step; '.' decimal point, 4 decimals, '\n' rows.
#include <string>
#include <string_view>
#include <vector>

#include "wiresculpt/fab/bend_program.hpp"
#include "wiresculpt/fab/machine.hpp"

namespace wiresculpt::fab {

struct GcodeInfo {
  std::string wire_name;      ///< named in the header comment
  std::string material;       ///< named in the header comment, e.g. "steel 3 mm"
  bool sync_each_step = true; ///< end every step with G4 P0; default true
};

std::string gcode_program(const BendProgram& program, const MachineProfile& profile, const GcodeInfo& info);

/// The lines to stream: comments ('(...)' and ';...') and surrounding blanks removed, empty
/// lines dropped, in order.
std::vector<std::string> stream_lines(std::string_view gcode);

std::string bend_table_csv(const BendProgram& program);

}  // namespace wiresculpt::fab
