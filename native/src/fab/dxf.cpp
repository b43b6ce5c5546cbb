#include "wiresculpt/fab/dxf.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/machine.hpp"

namespace wiresculpt::fab {
namespace {

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

// One group: code right-aligned in 3 columns (as AutoCAD writes it), then the value.
void group(std::string& s, int code, const std::string& value) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%3d\n", code);
  s += buf;
  s += value;
  s += '\n';
}

std::string ascii_text(const std::string& in) {
  std::string out;
  for (char c : in) {
    const unsigned char u = static_cast<unsigned char>(c);
    out += (u >= 0x20 && u < 0x7f) ? c : '?';
  }
  return out;
}

}  // namespace

std::string dxf_layer_name(std::size_t index, const std::string& name) {
  std::string clean;
  for (char c : name) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    clean += ok ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : '_';
  }
  std::string layer = "WIRE_" + std::to_string(index);
  if (!clean.empty()) layer += "_" + clean;
  if (layer.size() > 31) layer.resize(31);
  return layer;
}

std::vector<Polyline2> dxf_placed_mm(const std::vector<TemplateWire>& wires, const DxfOptions& options) {
  if (!(std::isfinite(options.gap_mm) && options.gap_mm >= 0))
    throw InputError("DXF options: gap_mm must be a number of millimetres >= 0");
  std::vector<Polyline2> out;
  double cursor = 0;
  for (std::size_t k = 0; k < wires.size(); ++k) {
    validate(wires[k], k);
    Polyline2 mm;
    for (const Vec2& p : wires[k].points) mm.emplace_back(to_mm(p.x()), to_mm(p.y()));
    Vec2 shift = Vec2::Zero();
    if (options.layout == DxfLayout::start_at_origin) {
      shift = -mm.front();
    } else if (options.layout == DxfLayout::side_by_side) {
      Vec2 lo = mm.front(), hi = mm.front();
      for (const Vec2& p : mm) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }
      shift = Vec2(cursor - lo.x(), -lo.y());
      cursor += (hi.x() - lo.x()) + options.gap_mm;
    }
    for (Vec2& p : mm) p += shift;
    out.push_back(std::move(mm));
  }
  return out;
}

namespace {

// Handles of the fixed objects; entities and per-wire layers count up from kFirstFree.
enum Handle : unsigned {
  kRootDict = 0xC, kGroupDict = 0xD, kVportTable = 0x8, kLtypeTable = 0x5, kLayerTable = 0x2,
  kStyleTable = 0x3, kViewTable = 0x6, kUcsTable = 0x7, kAppidTable = 0x9, kDimstyleTable = 0xA,
  kBlockRecordTable = 0x1, kLtypeByBlock = 0x14, kLtypeByLayer = 0x15, kLtypeContinuous = 0x16,
  kLayer0 = 0x10, kStyleStandard = 0x11, kAppidAcad = 0x12, kDimstyleStandard = 0x27,
  kModelRecord = 0x1F, kPaperRecord = 0x1B, kModelBlock = 0x20, kModelEnd = 0x21, kPaperBlock = 0x1C,
  kPaperEnd = 0x1D, kFirstFree = 0x100,
};

std::string hex(unsigned h) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%X", h);
  return buf;
}

void table_head(std::string& s, const char* name, unsigned handle, std::size_t count) {
  group(s, 0, "TABLE"); group(s, 2, name); group(s, 5, hex(handle)); group(s, 330, "0");
  group(s, 100, "AcDbSymbolTable"); group(s, 70, std::to_string(count));
}

void record_head(std::string& s, const char* type, unsigned handle, unsigned owner, const char* subclass) {
  group(s, 0, type); group(s, 5, hex(handle)); group(s, 330, hex(owner));
  group(s, 100, "AcDbSymbolTableRecord"); group(s, 100, subclass);
}

void ltype(std::string& s, unsigned handle, const char* name, const char* description) {
  record_head(s, "LTYPE", handle, kLtypeTable, "AcDbLinetypeTableRecord");
  group(s, 2, name); group(s, 70, "0"); group(s, 3, description); group(s, 72, "65"); group(s, 73, "0");
  group(s, 40, num(0));
}

void layer(std::string& s, unsigned handle, const std::string& name, int colour) {
  record_head(s, "LAYER", handle, kLayerTable, "AcDbLayerTableRecord");
  group(s, 2, name); group(s, 70, "0"); group(s, 62, std::to_string(colour)); group(s, 6, "Continuous");
  group(s, 370, "-3");
}

void block(std::string& s, unsigned begin, unsigned end, unsigned record, const char* name) {
  group(s, 0, "BLOCK"); group(s, 5, hex(begin)); group(s, 330, hex(record)); group(s, 100, "AcDbEntity");
  group(s, 8, "0"); group(s, 100, "AcDbBlockBegin"); group(s, 2, name); group(s, 70, "0");
  group(s, 10, num(0)); group(s, 20, num(0)); group(s, 30, num(0)); group(s, 3, name); group(s, 1, "");
  group(s, 0, "ENDBLK"); group(s, 5, hex(end)); group(s, 330, hex(record)); group(s, 100, "AcDbEntity");
  group(s, 8, "0"); group(s, 100, "AcDbBlockEnd");
}

}  // namespace

std::string dxf_document(const std::vector<TemplateWire>& wires, const DxfOptions& options) {
  if (wires.empty()) throw InputError("a DXF file needs at least one wire");
  if (!(std::isfinite(options.text_height_mm) && options.text_height_mm > 0))
    throw InputError("DXF options: text_height_mm must be a positive number of millimetres");
  const std::vector<Polyline2> placed = dxf_placed_mm(wires, options);
  Vec2 lo = placed.front().front(), hi = lo;
  for (const Polyline2& w : placed)
    for (const Vec2& p : w) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }

  unsigned next = kFirstFree;
  std::vector<unsigned> layer_handles, entity_handles, text_handles;
  for (std::size_t k = 0; k < wires.size(); ++k) layer_handles.push_back(next++);
  for (std::size_t k = 0; k < wires.size(); ++k) {
    entity_handles.push_back(next++);
    text_handles.push_back(next++);
  }

  std::string s;
  // HEADER
  group(s, 0, "SECTION"); group(s, 2, "HEADER");
  group(s, 9, "$ACADVER"); group(s, 1, "AC1015");
  group(s, 9, "$HANDSEED"); group(s, 5, hex(next));
  group(s, 9, "$INSUNITS"); group(s, 70, "4");
  group(s, 9, "$MEASUREMENT"); group(s, 70, "1");
  group(s, 9, "$INSBASE"); group(s, 10, num(0)); group(s, 20, num(0)); group(s, 30, num(0));
  group(s, 9, "$EXTMIN"); group(s, 10, num(lo.x())); group(s, 20, num(lo.y())); group(s, 30, num(0));
  group(s, 9, "$EXTMAX"); group(s, 10, num(hi.x())); group(s, 20, num(hi.y())); group(s, 30, num(0));
  group(s, 0, "ENDSEC");
  group(s, 0, "SECTION"); group(s, 2, "CLASSES"); group(s, 0, "ENDSEC");
  // TABLES
  group(s, 0, "SECTION"); group(s, 2, "TABLES");
  table_head(s, "VPORT", kVportTable, 0); group(s, 0, "ENDTAB");
  table_head(s, "LTYPE", kLtypeTable, 3);
  ltype(s, kLtypeByBlock, "ByBlock", ""); ltype(s, kLtypeByLayer, "ByLayer", "");
  ltype(s, kLtypeContinuous, "Continuous", "Solid line");
  group(s, 0, "ENDTAB");
  table_head(s, "LAYER", kLayerTable, wires.size() + 1);
  layer(s, kLayer0, "0", 7);
  for (std::size_t k = 0; k < wires.size(); ++k)
    layer(s, layer_handles[k], dxf_layer_name(k, wires[k].name), 1 + static_cast<int>(k % 6));  // colours 1..6
  group(s, 0, "ENDTAB");
  table_head(s, "STYLE", kStyleTable, 1);
  record_head(s, "STYLE", kStyleStandard, kStyleTable, "AcDbTextStyleTableRecord");
  group(s, 2, "Standard"); group(s, 70, "0"); group(s, 40, num(0)); group(s, 41, num(1)); group(s, 50, num(0));
  group(s, 71, "0"); group(s, 42, num(2.5)); group(s, 3, "txt"); group(s, 4, "");
  group(s, 0, "ENDTAB");
  table_head(s, "VIEW", kViewTable, 0); group(s, 0, "ENDTAB");
  table_head(s, "UCS", kUcsTable, 0); group(s, 0, "ENDTAB");
  table_head(s, "APPID", kAppidTable, 1);
  record_head(s, "APPID", kAppidAcad, kAppidTable, "AcDbRegAppTableRecord");
  group(s, 2, "ACAD"); group(s, 70, "0");
  group(s, 0, "ENDTAB");
  table_head(s, "DIMSTYLE", kDimstyleTable, 1); group(s, 100, "AcDbDimStyleTable");
  group(s, 0, "DIMSTYLE"); group(s, 105, hex(kDimstyleStandard)); group(s, 330, hex(kDimstyleTable));
  group(s, 100, "AcDbSymbolTableRecord"); group(s, 100, "AcDbDimStyleTableRecord");
  group(s, 2, "Standard"); group(s, 70, "0");
  group(s, 0, "ENDTAB");
  table_head(s, "BLOCK_RECORD", kBlockRecordTable, 2);
  record_head(s, "BLOCK_RECORD", kModelRecord, kBlockRecordTable, "AcDbBlockTableRecord");
  group(s, 2, "*Model_Space");
  record_head(s, "BLOCK_RECORD", kPaperRecord, kBlockRecordTable, "AcDbBlockTableRecord");
  group(s, 2, "*Paper_Space");
  group(s, 0, "ENDTAB");
  group(s, 0, "ENDSEC");
  // BLOCKS
  group(s, 0, "SECTION"); group(s, 2, "BLOCKS");
  block(s, kModelBlock, kModelEnd, kModelRecord, "*Model_Space");
  block(s, kPaperBlock, kPaperEnd, kPaperRecord, "*Paper_Space");
  group(s, 0, "ENDSEC");
  // ENTITIES: one LWPOLYLINE per wire (open: a closed wire's rest shape has the cut at both ends)
  group(s, 0, "SECTION"); group(s, 2, "ENTITIES");
  for (std::size_t k = 0; k < wires.size(); ++k) {
    const std::string name = dxf_layer_name(k, wires[k].name);
    group(s, 0, "LWPOLYLINE"); group(s, 5, hex(entity_handles[k])); group(s, 330, hex(kModelRecord));
    group(s, 100, "AcDbEntity"); group(s, 8, name); group(s, 100, "AcDbPolyline");
    group(s, 90, std::to_string(placed[k].size())); group(s, 70, "0"); group(s, 43, num(0));
    for (const Vec2& p : placed[k]) { group(s, 10, num(p.x())); group(s, 20, num(p.y())); }
    if (options.labels) {
      const Vec2& p = placed[k].front();
      group(s, 0, "TEXT"); group(s, 5, hex(text_handles[k])); group(s, 330, hex(kModelRecord));
      group(s, 100, "AcDbEntity"); group(s, 8, name); group(s, 100, "AcDbText");
      group(s, 10, num(p.x())); group(s, 20, num(p.y() + options.text_height_mm)); group(s, 30, num(0));
      group(s, 40, num(options.text_height_mm));
      group(s, 1, wires[k].name.empty() ? "wire " + std::to_string(k) : ascii_text(wires[k].name));
      group(s, 7, "Standard"); group(s, 100, "AcDbText");
    }
  }
  group(s, 0, "ENDSEC");
  // OBJECTS: the root dictionary and the (empty) group dictionary every R2000 file has
  group(s, 0, "SECTION"); group(s, 2, "OBJECTS");
  group(s, 0, "DICTIONARY"); group(s, 5, hex(kRootDict)); group(s, 330, "0"); group(s, 100, "AcDbDictionary");
  group(s, 281, "1"); group(s, 3, "ACAD_GROUP"); group(s, 350, hex(kGroupDict));
  group(s, 0, "DICTIONARY"); group(s, 5, hex(kGroupDict)); group(s, 330, hex(kRootDict));
  group(s, 100, "AcDbDictionary"); group(s, 281, "1");
  group(s, 0, "ENDSEC");
  group(s, 0, "EOF");
  return s;
}

}  // namespace wiresculpt::fab
