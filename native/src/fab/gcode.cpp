#include "wiresculpt/fab/gcode.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {
namespace {

std::string num(double v, int decimals = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s == "-0.0000" || s == "-0.000" || s == "-0.0") s.erase(0, 1);
  return s;
}

// Text safe inside a ';' comment: printable ASCII, no realtime characters GRBL would act on.
std::string comment_text(const std::string& in) {
  std::string out;
  for (char c : in) {
    const unsigned char u = static_cast<unsigned char>(c);
    const bool realtime = c == '!' || c == '~' || c == '?';
    out += (u >= 0x20 && u < 0x7f && !realtime) ? c : '_';
  }
  return out;
}

std::string trim(std::string_view s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

}  // namespace

std::string gcode_program(const BendProgram& program, const MachineProfile& profile, const GcodeInfo& info) {
  validate(profile);
  if (program.steps.empty()) throw InputError("the bend program has no steps");
  const AxisMapping& ax = profile.axes;
  const double feed_f = to_mm(profile.feed_speed) * 60.0 * ax.feed_units_per_mm;
  const double bend_f = to_deg(profile.bend_speed) * 60.0 * ax.bend_units_per_deg;
  const double side = profile.left_is_positive ? 1.0 : -1.0;
  const std::string feed_axis(1, ax.feed_axis), bend_axis(1, ax.bend_axis);

  std::string s;
  s += "; wiresculpt bend program\n";
  s += "; wire: " + comment_text(info.wire_name) + "\n";
  s += "; material: " + comment_text(info.material) + "\n";
  s += "; length: " + num(to_mm(program.wire_length), 3) + " mm, bends: " + std::to_string(program.bend_count) +
       ", estimated machine time: " + num(program.machine_seconds, 0) + " s\n";
  s += "; machine: " + comment_text(profile.name) + "; feed " + feed_axis + " (" + num(ax.feed_units_per_mm) +
       "/mm), bend " + bend_axis + " (" + num(ax.bend_units_per_deg) + "/deg), left bend = " +
       (profile.left_is_positive ? "+" : "-") + bend_axis + "\n";
  s += "; spring-back fit: measured = " + num(profile.springback_a) + " * commanded + " +
       num(to_deg(profile.springback_b), 3) + " deg\n";
  s += "G21\nG91\nG94\n";
  // The pin's side of the wire: +1 where a positive head move bends (where every program starts
  // and ends), -1 where a negative one does. The head rests at 0 on the +1 side and at +pin_swing
  // on the -1 side; all moves are relative (G91).
  int pin_side = 1;
  const std::string pin(1, ax.pin_axis ? ax.pin_axis : ' ');
  const double swing = to_deg(ax.pin_swing) * ax.bend_units_per_deg;
  // The duck to the other side: pin down (under the wire), the head swings across it, pin up.
  // From +1 to -1 the head turns the positive way (past the wire, as a positive bend would), back
  // the negative way.
  auto duck = [&](int to_side) {
    s += "G0 " + pin + num(-ax.pin_travel) + "\n";
    s += "G0 " + bend_axis + num(to_side < 0 ? swing : -swing) + "\n";
    s += "G0 " + pin + num(ax.pin_travel) + "\n";
    pin_side = to_side;
  };
  for (std::size_t k = 0; k < program.steps.size(); ++k) {
    const BendStep& st = program.steps[k];
    const bool bends = st.vertex >= 0;
    s += "; step " + std::to_string(k + 1) + ": feed " + num(to_mm(st.feed), 3) + " mm";
    if (bends)
      s += ", bend " + num(to_deg(st.bend), 3) + " deg (commanded " + num(to_deg(st.commanded), 3) + " deg)";
    s += "\n";
    s += "G1 " + feed_axis + num(to_mm(st.feed) * ax.feed_units_per_mm) + " F" + num(feed_f, 1) + "\n";
    if (bends) {
      const double move = side * to_deg(st.commanded) * ax.bend_units_per_deg;
      const int wanted = move >= 0 ? 1 : -1;
      if (ax.pin_axis != '\0' && wanted != pin_side) duck(wanted);
      s += "G1 " + bend_axis + num(move) + " F" + num(bend_f, 1) + "\n";
      s += "G1 " + bend_axis + num(-move) + " F" + num(bend_f, 1) + "\n";
    }
    if (info.sync_each_step) s += "G4 P0\n";
  }
  if (pin_side != 1) {  // the next program starts with the pin on the positive side
    s += "; pin back to the positive side\n";
    duck(1);
  }
  s += "M2\n";
  return s;
}

std::vector<std::string> stream_lines(std::string_view gcode) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos <= gcode.size()) {
    std::size_t end = gcode.find('\n', pos);
    if (end == std::string_view::npos) end = gcode.size();
    std::string_view raw = gcode.substr(pos, end - pos);
    std::string line;
    bool in_paren = false;
    for (char c : raw) {
      if (in_paren) {
        if (c == ')') in_paren = false;
        continue;
      }
      if (c == '(') { in_paren = true; continue; }
      if (c == ';') break;
      line += c;
    }
    line = trim(line);
    if (!line.empty()) out.push_back(line);
    pos = end + 1;
  }
  return out;
}

std::string bend_table_csv(const BendProgram& program) {
  std::string s = "step,feed_mm,bend_deg,commanded_deg\n";
  for (std::size_t k = 0; k < program.steps.size(); ++k) {
    const BendStep& st = program.steps[k];
    s += std::to_string(k + 1) + "," + num(to_mm(st.feed)) + "," + num(to_deg(st.bend)) + "," +
         num(to_deg(st.commanded)) + "\n";
  }
  return s;
}

}  // namespace wiresculpt::fab
