#pragma once
// 1:1 SVG templates a maker prints and lays a bent wire on: width/height in millimetres and a
// viewBox in millimetres, so one user unit is one millimetre on paper (print at 100%, no
// "fit to page"). The wire's 2D frame (x right, y up) is drawn with y pointing up on the page.
//
// Each wire is drawn as <g class="wire" id="wire-K" data-name="..."> holding
//   <polyline class="wire-path">   the centreline, absolute coordinates in mm
//   <line class="bend">            a tick across the wire at each bend point (bisector normal)
//   <circle class="crossing">      a ring at each crossing point
//   <g class="self-crossing">      an orange ring and "crosses itself" where the wire crosses itself
//   <text class="label">           "name  (length mm)" in the wire's top margin
//   <circle class="start">         a dot on the first point: where the bender starts
//   <g class="feed">               an arrow beside the first segment pointing along it (the way the
//                                  wire leaves the bender); data-dx/data-dy its direction on the page
//   <line class="cut">, <text class="cut-label">   a bar across the last point: where it is cut
//   <g class="overlap">              when given: the closing overlap of a closed wire (its last
//                                  `overlap` of path) as a wide translucent band, with its length
//   <polyline class="preview">      when given: the wire the machine is predicted to make, dashed,
//                                  violet, with <g class="legend"> in the bottom margin naming it
//                                  (and its largest distance from the rest shape in mm)
// A wire occupies a cell of (bounding box + 2 * margin) in each direction; the label, ticks and
// rings stay inside the margin when tick_mm, crossing_radius_mm and label_mm are below margin_mm.
#include <string>
#include <vector>

#include "wiresculpt/fab/template_wire.hpp"

namespace wiresculpt::fab {

struct SvgOptions {
  double margin_mm = 10.0;          ///< empty border around each wire's bounding box; default 10 mm
  double stroke_mm = 0.5;           ///< centreline width; default 0.5 mm (thin, to align a wire on)
  double tick_mm = 3.0;             ///< half-length of a bend tick; default 3 mm
  double crossing_radius_mm = 2.0;  ///< radius of a crossing ring; default 2 mm
  double label_mm = 4.0;            ///< label font size; default 4 mm
  double sheet_width_mm = 600.0;    ///< sheet: start a new row past this width; default 600 mm
};

/// Where a wire's cell sits on the sheet: top-left corner, mm, and the cell's size.
struct SheetCell {
  double x_mm = 0.0, y_mm = 0.0, width_mm = 0.0, height_mm = 0.0;
};

/// One wire alone: width = bbox width + 2 margin, height = bbox height + 2 margin (mm).
std::string svg_wire(const TemplateWire& wire, const SvgOptions& options = {});

/// The machine file of one wire: its rest-shape centreline as exactly one <path> (M, then L per
/// point), millimetres, the origin at the wire's first point (where the bender starts), y down as
/// on the template; width/height in mm and a viewBox fitting the path plus stroke_mm. Nothing
/// else is drawn: vector-to-bend importers read every path as a wire.
std::string svg_machine(const TemplateWire& wire, double stroke_mm = 0.5);

/// Cells of the sheet layout: rows left to right, a new row when the next cell would pass
/// sheet_width_mm (a wider cell gets a row of its own). Cells never overlap.
std::vector<SheetCell> sheet_layout(const std::vector<TemplateWire>& wires, const SvgOptions& options = {});

/// All wires on one sheet laid out by sheet_layout; the sheet is as wide as its widest row and
/// as tall as its rows.
std::string svg_sheet(const std::vector<TemplateWire>& wires, const SvgOptions& options = {});

}  // namespace wiresculpt::fab
