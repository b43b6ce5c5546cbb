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
  require(finite_positive(p.min_feed), "min_feed (l_min) must be a positive length in metres");
  require(finite_positive(p.max_bend), "max_bend must be a positive angle");
  require(std::isfinite(p.min_bend) && p.min_bend >= 0.0, "min_bend must be zero or a positive angle");
  require(p.min_bend < p.max_bend, "min_bend must be smaller than max_bend");
  require(finite_positive(p.max_commanded), "max_commanded (the bending head's range) must be a positive angle");
  require(finite_positive(p.springback_a), "springback_a (slope of the calibration fit) must be positive");
  require(std::isfinite(p.springback_b), "springback_b (offset of the calibration fit) must be finite");
  require(finite_positive(p.feed_speed), "feed_speed must be positive");
  require(finite_positive(p.bend_speed), "bend_speed must be positive");
  require(std::isfinite(p.seconds_per_bend) && p.seconds_per_bend >= 0.0, "seconds_per_bend must be >= 0");
  const AxisMapping& a = p.axes;
  require(axis_letter(a.feed_axis), std::string("feed axis '") + a.feed_axis + "' is not a G-code axis letter");
  require(axis_letter(a.bend_axis), std::string("bend axis '") + a.bend_axis + "' is not a G-code axis letter");
  require(a.feed_axis != a.bend_axis, "feed and bend axes must be different letters");
  if (a.pin_axis != '\0') {
    require(axis_letter(a.pin_axis), std::string("pin axis '") + a.pin_axis + "' is not a G-code axis letter");
    require(a.pin_axis != a.feed_axis && a.pin_axis != a.bend_axis, "the pin axis must differ from the feed and bend axes");
    require(finite_positive(a.pin_travel), "pin_travel must be positive");
  }
  require(finite_positive(a.feed_units_per_mm), "feed_units_per_mm must be positive");
  require(finite_positive(a.bend_units_per_deg), "bend_units_per_deg must be positive");
  const SerialSettings& s = p.serial;
  require(s.baud > 0, "serial baud must be positive");
  require(s.data_bits >= 5 && s.data_bits <= 8, "serial data_bits must be 5..8");
  require(s.stop_bits == 1 || s.stop_bits == 2, "serial stop_bits must be 1 or 2");
}

}  // namespace wiresculpt::fab
