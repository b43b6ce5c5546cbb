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

std::string dxf_document(const std::vector<TemplateWire>& wires, const DxfOptions& options) {
  if (wires.empty()) throw InputError("a DXF file needs at least one wire");
  if (!(std::isfinite(options.text_height_mm) && options.text_height_mm > 0))
    throw InputError("DXF options: text_height_mm must be a positive number of millimetres");
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  bool first = true;
  for (std::size_t k = 0; k < wires.size(); ++k) {
    validate(wires[k], k);
    for (const Vec2& p : wires[k].points) {
      const double x = to_mm(p.x()), y = to_mm(p.y());
      if (first) { min_x = max_x = x; min_y = max_y = y; first = false; }
      min_x = std::min(min_x, x); max_x = std::max(max_x, x);
      min_y = std::min(min_y, y); max_y = std::max(max_y, y);
    }
  }

  std::string s;
  // HEADER
  group(s, 0, "SECTION"); group(s, 2, "HEADER");
  group(s, 9, "$ACADVER"); group(s, 1, "AC1009");
  group(s, 9, "$INSBASE"); group(s, 10, num(0)); group(s, 20, num(0)); group(s, 30, num(0));
  group(s, 9, "$EXTMIN"); group(s, 10, num(min_x)); group(s, 20, num(min_y)); group(s, 30, num(0));
  group(s, 9, "$EXTMAX"); group(s, 10, num(max_x)); group(s, 20, num(max_y)); group(s, 30, num(0));
  group(s, 9, "$LIMMIN"); group(s, 10, num(min_x)); group(s, 20, num(min_y));
  group(s, 9, "$LIMMAX"); group(s, 10, num(max_x)); group(s, 20, num(max_y));
  group(s, 0, "ENDSEC");
  // TABLES
  group(s, 0, "SECTION"); group(s, 2, "TABLES");
  group(s, 0, "TABLE"); group(s, 2, "LTYPE"); group(s, 70, "1");
  group(s, 0, "LTYPE"); group(s, 2, "CONTINUOUS"); group(s, 70, "0"); group(s, 3, "Solid line");
  group(s, 72, "65"); group(s, 73, "0"); group(s, 40, num(0));
  group(s, 0, "ENDTAB");
  group(s, 0, "TABLE"); group(s, 2, "LAYER"); group(s, 70, std::to_string(wires.size() + 1));
  group(s, 0, "LAYER"); group(s, 2, "0"); group(s, 70, "0"); group(s, 62, "7"); group(s, 6, "CONTINUOUS");
  for (std::size_t k = 0; k < wires.size(); ++k) {
    group(s, 0, "LAYER"); group(s, 2, dxf_layer_name(k, wires[k].name)); group(s, 70, "0");
    group(s, 62, std::to_string(1 + static_cast<int>(k % 6)));  // colours 1..6
    group(s, 6, "CONTINUOUS");
  }
  group(s, 0, "ENDTAB");
  group(s, 0, "TABLE"); group(s, 2, "STYLE"); group(s, 70, "1");
  group(s, 0, "STYLE"); group(s, 2, "STANDARD"); group(s, 70, "0"); group(s, 40, num(0)); group(s, 41, num(1));
  group(s, 50, num(0)); group(s, 71, "0"); group(s, 42, num(2.5)); group(s, 3, "txt"); group(s, 4, "");
  group(s, 0, "ENDTAB");
  group(s, 0, "ENDSEC");
  // BLOCKS (empty) and ENTITIES
  group(s, 0, "SECTION"); group(s, 2, "BLOCKS"); group(s, 0, "ENDSEC");
  group(s, 0, "SECTION"); group(s, 2, "ENTITIES");
  for (std::size_t k = 0; k < wires.size(); ++k) {
    const std::string layer = dxf_layer_name(k, wires[k].name);
    group(s, 0, "POLYLINE"); group(s, 8, layer); group(s, 66, "1");
    group(s, 10, num(0)); group(s, 20, num(0)); group(s, 30, num(0)); group(s, 70, "0");
    for (const Vec2& p : wires[k].points) {
      group(s, 0, "VERTEX"); group(s, 8, layer);
      group(s, 10, num(to_mm(p.x()))); group(s, 20, num(to_mm(p.y()))); group(s, 30, num(0));
    }
    group(s, 0, "SEQEND"); group(s, 8, layer);
    if (options.labels) {
      const Vec2& p = wires[k].points.front();
      group(s, 0, "TEXT"); group(s, 8, layer);
      group(s, 10, num(to_mm(p.x()))); group(s, 20, num(to_mm(p.y()) + options.text_height_mm)); group(s, 30, num(0));
      group(s, 40, num(options.text_height_mm)); group(s, 1, wires[k].name.empty() ? "wire " + std::to_string(k) : ascii_text(wires[k].name)); group(s, 7, "STANDARD");
    }
  }
  group(s, 0, "ENDSEC");
  group(s, 0, "EOF");
  return s;
}

}  // namespace wiresculpt::fab
