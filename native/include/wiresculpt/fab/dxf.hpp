#pragma once
// DXF R12 (AC1009) ASCII: HEADER ($ACADVER, $INSBASE, $EXTMIN/$EXTMAX, $LIMMIN/$LIMMAX; R12 has no
// units variable, the numbers are millimetres by convention), TABLES (LTYPE CONTINUOUS, LAYER "0" and one layer per wire,
// STYLE STANDARD), empty BLOCKS, and ENTITIES with one 2D POLYLINE/VERTEX/SEQEND per wire plus
// an optional TEXT label, on that wire's layer. Coordinates are the wires' own 2D coordinates in
// millimetres (1:1, no offset, no flip): wires given in one frame keep their relative positions.
#include <cstddef>
#include <string>
#include <vector>

#include "wiresculpt/fab/template_wire.hpp"

namespace wiresculpt::fab {

struct DxfOptions {
  bool labels = true;         ///< a TEXT with the wire's name at its first point; default true
  double text_height_mm = 4;  ///< label height; default 4 mm
};

/// The layer of wire `index`: "WIRE_<index>_<name>" with characters outside [A-Za-z0-9_-]
/// replaced by '_', at most 31 characters (R12's limit), unique per index.
std::string dxf_layer_name(std::size_t index, const std::string& name);

std::string dxf_document(const std::vector<TemplateWire>& wires, const DxfOptions& options = {});

}  // namespace wiresculpt::fab
