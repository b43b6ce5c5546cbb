#pragma once
// The wire-bending machine: its limits (Sec. 4.3's fabrication constraints c_f,length and
// c_f,angle), its spring-back calibration (Sec. 5.1: "we feed the machine with known input angles
// and measure the output angles ... use linear regression and invert this function") and how it
// is driven (G-code axis mapping, serial settings). Defaults describe a DIWire-class 2D bender
// (Pensalabs DIWire, Fig. 9) running GRBL.
//
// Units: SI inside (metres, radians, seconds). Millimetres and degrees appear only at the
// machine's edge (G-code words, CSV, SVG/DXF) and are converted with the helpers below, the one
// place those conversions live.
#include <numbers>
#include <string>

namespace wiresculpt::fab {

// ---- the one place where SI meets the machine's units ------------------------------------
inline constexpr double kMillimetresPerMetre = 1000.0;
inline constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;
inline constexpr double to_mm(double metres) { return metres * kMillimetresPerMetre; }
inline constexpr double from_mm(double millimetres) { return millimetres / kMillimetresPerMetre; }
inline constexpr double to_deg(double radians) { return radians * kDegreesPerRadian; }
inline constexpr double from_deg(double degrees) { return degrees / kDegreesPerRadian; }

/// Serial line settings of the machine's controller (an Arduino running GRBL: 115200 8N1).
struct SerialSettings {
  enum class Parity { none, odd, even };
  enum class FlowControl { none, xon_xoff, rts_cts };
  int baud = 115200;                          ///< bits per second; default 115200 (GRBL 1.1)
  int data_bits = 8;                          ///< 5..8; default 8
  Parity parity = Parity::none;               ///< default none
  int stop_bits = 1;                          ///< 1 or 2; default 1
  FlowControl flow_control = FlowControl::none;  ///< default none (GRBL uses none)
};

/// How bend-program quantities map onto G-code words (GRBL axes).
struct AxisMapping {
  char feed_axis = 'X';        ///< axis that feeds the wire; default 'X'
  char bend_axis = 'Y';        ///< axis that rotates the bending head; default 'Y'
  char pin_axis = 'Z';         ///< axis that ducks the bend pin under the wire to change bend side; default 'Z'
                               ///< ('\0' = none: only for a machine that bends to one side, or has no pin axis)
  double feed_units_per_mm = 1.0;  ///< feed-axis units per millimetre of wire; default 1 (GRBL $100 in steps/mm)
  double bend_units_per_deg = 1.0; ///< bend-axis units per degree of head rotation; default 1
  double pin_travel = 5.0;     ///< pin-axis units to retract (and then re-extend) the pin; default 5
  double pin_swing = from_deg(20.0);  ///< rad of head rotation, pin retracted, from the rest on one side of
                               ///< the wire to the rest on the other (profile key pin_swing_deg); default 20°
};

/// A 2D wire bender: limits, calibration, speeds and how to talk to it.
struct MachineProfile {
  std::string name = "DIWire-class bender (GRBL)";  ///< shown in file headers

  // Limits (Sec. 4.3 fabrication constraints, Sec. 5.1).
  double min_feed = 0.015;  ///< l_min, m: shortest wire feed between two bends; default 0.015 m (15 mm)
  double max_bend = from_deg(120.0);     ///< rad, largest reliable |target bend|; default 120°
  double min_bend = from_deg(1.0);       ///< rad, smallest reliable |target bend|; default 1°
                                                        ///< (smaller turns follow the small-bend rule, bend_program.hpp)
  double max_commanded = from_deg(150.0);  ///< rad, range of the bending head
                                                             ///< (|commanded| after compensation); default 150°

  /// Bend direction convention. Bends are signed as the wire turns walking from the cut, in the
  /// polyline's own 2D frame (x right, y up): positive = counter-clockwise = "left". When true
  /// (default) a left bend is a positive bend-axis move; when false, a negative one.
  bool left_is_positive = true;

  // Spring-back calibration (Sec. 5.1): measured = a * commanded + b, for |angles|.
  double springback_a = 1.0;  ///< slope a (dimensionless, > 0); default 1 (no spring-back)
  double springback_b = 0.0;  ///< offset b, rad; default 0

  // Speeds and time.
  double feed_speed = 0.02;  ///< m/s of wire feed; default 0.02 m/s (1200 mm/min)
  double bend_speed = from_deg(90.0);  ///< rad/s of head rotation; default 90°/s
  double seconds_per_bend = 3.0;  ///< s, least time of one feed-and-bend step; default 3 s (paper, Sec. 6)

  AxisMapping axes;      ///< G-code words
  SerialSettings serial; ///< line settings for streaming
};

/// Throws InputError naming the first field that is out of range (non-finite, non-positive
/// speed, min_bend > max_bend, a <= 0, equal or missing axis letters, bad serial settings, or
/// beyond a generous upper bound: l_min 1 m, bends 180 deg, head range 360 deg, a 10, |b| 90 deg,
/// feed 10 m/s, head 36000 deg/s, 3600 s per bend, 1e6 axis units, 10 Mbaud).
void validate(const MachineProfile& profile);

}  // namespace wiresculpt::fab
