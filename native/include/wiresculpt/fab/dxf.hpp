#pragma once
// DXF R2000 (AC1015) ASCII, the form CAD programs and vector-to-bend importers read:
// HEADER ($ACADVER AC1015, $HANDSEED, $INSUNITS 4 = millimetres, $MEASUREMENT 1 = metric,
// $EXTMIN/$EXTMAX), an empty CLASSES section, TABLES (VPORT, LTYPE ByBlock/ByLayer/Continuous,
// LAYER "0" and one layer per wire, STYLE Standard, VIEW, UCS, APPID ACAD, DIMSTYLE Standard,
// BLOCK_RECORD *Model_Space/*Paper_Space), BLOCKS (the two layout blocks), ENTITIES with one
// LWPOLYLINE per wire on that wire's layer (plus an optional TEXT label), and OBJECTS (the root
// dictionary and ACAD_GROUP). Every object has a handle and its owner.
// Coordinates are millimetres; where each wire goes is DxfOptions::layout.
#include <cstddef>
#include <string>
#include <vector>

#include "wiresculpt/fab/template_wire.hpp"

namespace wiresculpt::fab {

enum class DxfLayout {
  as_given,         ///< the wires' own 2D coordinates, 1:1 (wires in one frame keep their places)
  start_at_origin,  ///< each wire moved so that its first point (the start of the bend) is (0, 0)
  side_by_side,     ///< left to right on the x axis, bounding boxes gap_mm apart, lowest y at 0
};

struct DxfOptions {
  bool labels = false;                    ///< a TEXT with the wire's name above its first point; default false
  double text_height_mm = 4;              ///< label height; default 4 mm
  DxfLayout layout = DxfLayout::as_given; ///< default: the wires' own coordinates
  double gap_mm = 20;                     ///< side_by_side: space between bounding boxes; default 20 mm
};

/// The layer of wire `index`: "WIRE_<index>_<name>" with characters outside [A-Za-z0-9_-]
/// replaced by '_', at most 31 characters, unique per index.
std::string dxf_layer_name(std::size_t index, const std::string& name);

/// The wires' points in millimetres after DxfOptions::layout (what the DXF's LWPOLYLINEs hold).
std::vector<Polyline2> dxf_placed_mm(const std::vector<TemplateWire>& wires, const DxfOptions& options = {});

std::string dxf_document(const std::vector<TemplateWire>& wires, const DxfOptions& options = {});

}  // namespace wiresculpt::fab
