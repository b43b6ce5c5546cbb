#include "wiresculpt/fab/machine.hpp"

#include <cctype>
#include <cmath>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw InputError("machine profile: " + what);
}

bool finite_positive(double x) { return std::isfinite(x) && x > 0.0; }

bool axis_letter(char c) {
  return c >= 'A' && c <= 'Z' && c != 'G' && c != 'M' && c != 'F' && c != 'N' && c != 'S' &&
         c != 'P' && c != 'T';
}

}  // namespace

void validate(const MachineProfile& p) {
  // Upper bounds are far beyond any bender; they catch a value in the wrong unit and the huge
  // numbers a hand-edited file can hold. The profile dict's key (edge units) is named too.
  require(finite_positive(p.min_feed) && p.min_feed <= 1.0,
          "min_feed (l_min, key min_segment) must be a positive length of at most 1 m");
  require(finite_positive(p.max_bend) && p.max_bend <= from_deg(180.0),
          "max_bend (key max_bend_deg) must be a positive angle of at most 180 deg");
  require(std::isfinite(p.min_bend) && p.min_bend >= 0.0, "min_bend (key min_bend_deg) must be zero or a positive angle");
  require(p.min_bend < p.max_bend, "min_bend must be smaller than max_bend");
  require(finite_positive(p.max_commanded) && p.max_commanded <= from_deg(360.0),
          "max_commanded (the bending head's range, key max_commanded_deg) must be a positive angle of at most 360 deg");
  require(finite_positive(p.springback_a) && p.springback_a <= 10.0,
          "springback_a (slope of the calibration fit) must be positive and at most 10");
  require(std::isfinite(p.springback_b) && std::abs(p.springback_b) <= from_deg(90.0),
          "springback_b (offset of the calibration fit, key springback_b_deg) must be within +-90 deg");
  require(finite_positive(p.feed_speed) && p.feed_speed <= 10.0,
          "feed_speed (key feed_speed_mm_s) must be positive and at most 10000 mm/s");
  require(finite_positive(p.bend_speed) && p.bend_speed <= from_deg(36000.0),
          "bend_speed (key bend_speed_deg_s) must be positive and at most 36000 deg/s");
  require(std::isfinite(p.seconds_per_bend) && p.seconds_per_bend >= 0.0 && p.seconds_per_bend <= 3600.0,
          "seconds_per_bend must be between 0 and 3600 s");
  const AxisMapping& a = p.axes;
  require(axis_letter(a.feed_axis), std::string("feed axis '") + a.feed_axis + "' is not a G-code axis letter");
  require(axis_letter(a.bend_axis), std::string("bend axis '") + a.bend_axis + "' is not a G-code axis letter");
  require(a.feed_axis != a.bend_axis, "feed and bend axes must be different letters");
  if (a.pin_axis != '\0') {
    require(axis_letter(a.pin_axis), std::string("pin axis '") + a.pin_axis + "' is not a G-code axis letter");
    require(a.pin_axis != a.feed_axis && a.pin_axis != a.bend_axis, "the pin axis must differ from the feed and bend axes");
    require(finite_positive(a.pin_travel) && a.pin_travel <= 1e6, "pin_travel must be positive and at most 1e6 units");
    require(finite_positive(a.pin_swing) && a.pin_swing <= from_deg(180.0),
            "pin_swing (key pin_swing_deg) must be positive and at most 180 deg");
  }
  require(finite_positive(a.feed_units_per_mm) && a.feed_units_per_mm <= 1e6,
          "feed_units_per_mm must be positive and at most 1e6");
  require(finite_positive(a.bend_units_per_deg) && a.bend_units_per_deg <= 1e6,
          "bend_units_per_deg must be positive and at most 1e6");
  const SerialSettings& s = p.serial;
  require(s.baud > 0 && s.baud <= 10000000, "serial baud must be between 1 and 10000000");
  require(s.data_bits >= 5 && s.data_bits <= 8, "serial data_bits must be 5..8");
  require(s.stop_bits == 1 || s.stop_bits == 2, "serial stop_bits must be 1 or 2");
}

}  // namespace wiresculpt::fab
