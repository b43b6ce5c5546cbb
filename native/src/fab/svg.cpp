#include "wiresculpt/fab/svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/machine.hpp"

namespace wiresculpt::fab {
namespace {

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t') out += c;  // no control characters in XML
    }
  }
  return out;
}

struct Box {
  double min_x, min_y, max_x, max_y;  // mm
  double width() const { return max_x - min_x; }
  double height() const { return max_y - min_y; }
};

Box bbox_mm(const TemplateWire& w) {
  Box b{to_mm(w.points[0].x()), to_mm(w.points[0].y()), to_mm(w.points[0].x()), to_mm(w.points[0].y())};
  for (const Polyline2* line : {&w.points, &w.preview})
  for (const Vec2& p : *line) {
    b.min_x = std::min(b.min_x, to_mm(p.x()));
    b.max_x = std::max(b.max_x, to_mm(p.x()));
    b.min_y = std::min(b.min_y, to_mm(p.y()));
    b.max_y = std::max(b.max_y, to_mm(p.y()));
  }
  return b;
}

void check_options(const SvgOptions& o) {
  auto ok = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!ok(o.margin_mm) || !ok(o.stroke_mm) || !ok(o.tick_mm) || !ok(o.crossing_radius_mm) ||
      !ok(o.label_mm) || !ok(o.sheet_width_mm))
    throw InputError("SVG options: every size must be a finite, non-negative number of millimetres");
}

double wire_length_mm(const TemplateWire& w) {
  double s = 0.0;
  for (std::size_t i = 1; i < w.points.size(); ++i) s += (w.points[i] - w.points[i - 1]).norm();
  return to_mm(s);
}

// The closing overlap of a loop: the last `overlap` of the path q (page coordinates, mm), a wide band.
std::string overlap_band(const TemplateWire& w, const std::vector<Vec2>& q, const SvgOptions& o) {
  double left = to_mm(w.overlap);
  std::vector<Vec2> band{q.back()};
  for (std::size_t i = q.size() - 1; i > 0 && left > 0.0; --i) {
    const double len = (q[i] - q[i - 1]).norm();
    if (len >= left) {
      band.push_back(q[i] + (left / len) * (q[i - 1] - q[i]));
      left = 0.0;
    } else {
      band.push_back(q[i - 1]);
      left -= len;
    }
  }
  std::string s = "    <g class=\"overlap\" data-mm=\"" + num(to_mm(w.overlap)) +
                  "\"><polyline fill=\"none\" stroke=\"#00a070\" "
                  "stroke-opacity=\"0.45\" stroke-width=\"" + num(4 * o.stroke_mm) + "\" stroke-linecap=\"butt\" points=\"";
  for (std::size_t i = 0; i < band.size(); ++i) {
    if (i) s += ' ';
    s += num(band[i].x());
    s += ',';
    s += num(band[i].y());
  }
  char words[96];
  std::snprintf(words, sizeof words, "overlap %.1f mm past the loop's cut", to_mm(w.overlap));
  const Vec2 at = band.back();
  s += "\"/><text x=\"" + num(at.x() + o.tick_mm) + "\" y=\"" + num(at.y() + o.tick_mm + 0.6 * o.label_mm) +
       "\" font-family=\"sans-serif\" font-size=\"" + num(0.6 * o.label_mm) + "\" fill=\"#00a070\">" + words +
       "</text></g>\n";
  return s;
}

// Where the bender starts (a dot on the first point), which way the wire comes out of it (an
// arrow beside the first segment, pointing along it) and where it is cut (a bar across the
// last point). All in green, away from the black centreline, ticks and rings.
std::string start_and_cut(const std::vector<Vec2>& q, const SvgOptions& o) {
  const std::string mark = "#008060";
  const double sw = o.stroke_mm * 0.6;
  std::string s = "    <circle class=\"start\" cx=\"" + num(q.front().x()) + "\" cy=\"" + num(q.front().y()) +
                  "\" r=\"" + num(1.5 * o.stroke_mm + 0.5) + "\" fill=\"" + mark + "\"/>\n";
  if (q.size() >= 2) {
    std::size_t j = 1;  // the first point apart from the start: the feed direction
    while (j + 1 < q.size() && (q[j] - q[0]).norm() < 1e-9) ++j;
    Vec2 d = q[j] - q[0];
    const double seg = d.norm();
    d = seg > 1e-12 ? Vec2(d / seg) : Vec2(1, 0);
    const Vec2 n(-d.y(), d.x());
    const double along = std::min(10.0, std::max(seg, 4.0));  // arrow length, mm
    const Vec2 a = q[0] + o.tick_mm * n, tip = a + along * d;
    const Vec2 h1 = tip - 1.5 * d + 0.8 * n, h2 = tip - 1.5 * d - 0.8 * n;
    s += "    <g class=\"feed\" data-dx=\"" + num(d.x()) + "\" data-dy=\"" + num(d.y()) + "\">";
    s += "<line x1=\"" + num(a.x()) + "\" y1=\"" + num(a.y()) + "\" x2=\"" + num(tip.x()) + "\" y2=\"" + num(tip.y()) +
         "\" stroke=\"" + mark + "\" stroke-width=\"" + num(sw) + "\"/>";
    s += "<polygon points=\"" + num(tip.x()) + "," + num(tip.y()) + " " + num(h1.x()) + "," + num(h1.y()) + " " +
         num(h2.x()) + "," + num(h2.y()) + "\" fill=\"" + mark + "\"/></g>\n";
    // the cut: a bar across the wire at its last point
    std::size_t k = q.size() - 2;
    while (k > 0 && (q.back() - q[k]).norm() < 1e-9) --k;
    Vec2 e = q.back() - q[k];
    e = e.norm() > 1e-12 ? Vec2(e.normalized()) : Vec2(1, 0);
    const Vec2 en(-e.y(), e.x());
    const Vec2 c1 = q.back() + o.tick_mm * en, c2 = q.back() - o.tick_mm * en;
    s += "    <line class=\"cut\" x1=\"" + num(c1.x()) + "\" y1=\"" + num(c1.y()) + "\" x2=\"" + num(c2.x()) +
         "\" y2=\"" + num(c2.y()) + "\" stroke=\"" + mark + "\" stroke-width=\"" + num(2 * sw) + "\"/>\n";
    const Vec2 t = q.back() + (o.tick_mm + 1.0) * en;
    s += "    <text class=\"cut-label\" x=\"" + num(t.x()) + "\" y=\"" + num(t.y()) +
         "\" font-family=\"sans-serif\" font-size=\"" + num(0.6 * o.label_mm) + "\" fill=\"" + mark + "\">cut</text>\n";
  }
  return s;
}

// The wire's elements with its cell's top-left corner at (ox, oy) on the page.
std::string wire_group(const TemplateWire& w, std::size_t index, double ox, double oy, const SvgOptions& o) {
  const Box b = bbox_mm(w);
  const double m = o.margin_mm;
  std::vector<Vec2> q;  // page coordinates, mm, y down
  q.reserve(w.points.size());
  for (const Vec2& p : w.points) q.emplace_back(ox + m + to_mm(p.x()) - b.min_x, oy + m + b.max_y - to_mm(p.y()));

  std::string s = "  <g class=\"wire\" id=\"wire-" + std::to_string(index) + "\" data-name=\"" +
                  xml_escape(w.name) + "\">\n";
  s += "    <polyline class=\"wire-path\" fill=\"none\" stroke=\"#000000\" stroke-width=\"" + num(o.stroke_mm) +
       "\" stroke-linejoin=\"round\" points=\"";
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (i) s += ' ';
    s += num(q[i].x());
    s += ',';
    s += num(q[i].y());
  }
  s += "\"/>\n";
  if (w.overlap > 0.0 && q.size() >= 2) s += overlap_band(w, q, o);
  const std::string preview_colour = "#8000c0";
  if (w.preview.size() >= 2) {  // the predicted wire: dashed, thinner, violet (named in the legend)
    s += "    <polyline class=\"preview\" fill=\"none\" stroke=\"" + preview_colour + "\" stroke-width=\"" +
         num(o.stroke_mm * 0.6) + "\" stroke-dasharray=\"" + num(4 * o.stroke_mm) + " " + num(3 * o.stroke_mm) +
         "\" stroke-linejoin=\"round\" points=\"";
    for (std::size_t i = 0; i < w.preview.size(); ++i) {
      if (i) s += ' ';
      s += num(ox + m + to_mm(w.preview[i].x()) - b.min_x);
      s += ',';
      s += num(oy + m + b.max_y - to_mm(w.preview[i].y()));
    }
    s += "\"/>\n";
  }
  for (std::size_t i : w.bend_points) {
    Vec2 d = Vec2::Zero();
    if (i > 0 && (q[i] - q[i - 1]).norm() > 0) d += (q[i] - q[i - 1]).normalized();
    if (i + 1 < q.size() && (q[i + 1] - q[i]).norm() > 0) d += (q[i + 1] - q[i]).normalized();
    if (d.norm() < 1e-9) d = (i > 0) ? (q[i] - q[i - 1]) : Vec2(1, 0);
    if (d.norm() < 1e-12) d = Vec2(1, 0);
    d.normalize();
    const Vec2 nrm(-d.y(), d.x());
    const Vec2 a = q[i] + o.tick_mm * nrm, c = q[i] - o.tick_mm * nrm;
    s += "    <line class=\"bend\" data-point=\"" + std::to_string(i) + "\" x1=\"" + num(a.x()) + "\" y1=\"" +
         num(a.y()) + "\" x2=\"" + num(c.x()) + "\" y2=\"" + num(c.y()) +
         "\" stroke=\"#d00000\" stroke-width=\"" + num(o.stroke_mm * 0.6) + "\"/>\n";
  }
  for (std::size_t i : w.crossing_points)
    s += "    <circle class=\"crossing\" data-point=\"" + std::to_string(i) + "\" cx=\"" + num(q[i].x()) +
         "\" cy=\"" + num(q[i].y()) + "\" r=\"" + num(o.crossing_radius_mm) +
         "\" fill=\"none\" stroke=\"#0050d0\" stroke-width=\"" + num(o.stroke_mm * 0.6) + "\"/>\n";
  for (std::size_t k = 0; k < w.self_crossings.size(); ++k) {
    const Vec2& p = w.self_crossings[k];
    const Vec2 c(ox + m + to_mm(p.x()) - b.min_x, oy + m + b.max_y - to_mm(p.y()));
    const double r = 1.5 * o.crossing_radius_mm;
    s += "    <g class=\"self-crossing\" data-index=\"" + std::to_string(k) + "\">\n";
    s += "      <circle cx=\"" + num(c.x()) + "\" cy=\"" + num(c.y()) + "\" r=\"" + num(r) +
         "\" fill=\"none\" stroke=\"#ff8000\" stroke-width=\"" + num(o.stroke_mm) + "\"/>\n";
    s += "      <text x=\"" + num(c.x() + r) + "\" y=\"" + num(c.y() - r) +
         "\" font-family=\"sans-serif\" font-size=\"" + num(0.6 * o.label_mm) +
         "\" fill=\"#ff8000\">crosses itself</text>\n";
    s += "    </g>\n";
  }
  char len[64];
  std::snprintf(len, sizeof len, "%.1f mm", wire_length_mm(w));
  s += "    <text class=\"label\" x=\"" + num(ox + m) + "\" y=\"" + num(oy + 0.75 * m) +
       "\" font-family=\"sans-serif\" font-size=\"" + num(o.label_mm) + "\">" + xml_escape(w.name) + "  (" + len +
       ")</text>\n";
  if (w.preview.size() >= 2) {  // the legend, in the bottom margin: a dashed sample and its name
    const double ly = oy + m + b.height() + 0.6 * m, lx = ox + m;
    s += "    <g class=\"legend\">";
    s += "<line x1=\"" + num(lx) + "\" y1=\"" + num(ly - 0.3 * o.label_mm) + "\" x2=\"" + num(lx + 8.0) + "\" y2=\"" +
         num(ly - 0.3 * o.label_mm) + "\" stroke=\"" + preview_colour + "\" stroke-width=\"" + num(o.stroke_mm * 0.6) +
         "\" stroke-dasharray=\"" + num(4 * o.stroke_mm) + " " + num(3 * o.stroke_mm) + "\"/>";
    std::string words = "predicted wire (the machine's spring-back model)";
    if (w.preview_distance >= 0.0) {
      char dist[64];
      std::snprintf(dist, sizeof dist, "%.1f mm", to_mm(w.preview_distance));
      words += ": up to " + std::string(dist) + " from the rest shape";
    }
    s += "<text x=\"" + num(lx + 10.0) + "\" y=\"" + num(ly) + "\" font-family=\"sans-serif\" font-size=\"" +
         num(0.6 * o.label_mm) + "\" fill=\"" + preview_colour + "\">" + words + "</text></g>\n";
  }
  s += start_and_cut(q, o);
  s += "  </g>\n";
  return s;
}

std::string svg_open(double width, double height) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + num(width) + "mm\" height=\"" +
         num(height) + "mm\" viewBox=\"0 0 " + num(width) + " " + num(height) + "\">\n"
         "  <!-- wiresculpt 1:1 template: one user unit is one millimetre; print at 100% -->\n";
}

}  // namespace

std::string svg_wire(const TemplateWire& wire, const SvgOptions& options) {
  check_options(options);
  validate(wire, 0);
  const Box b = bbox_mm(wire);
  const double w = b.width() + 2 * options.margin_mm, h = b.height() + 2 * options.margin_mm;
  return svg_open(w, h) + wire_group(wire, 0, 0.0, 0.0, options) + "</svg>\n";
}

std::string svg_machine(const TemplateWire& wire, double stroke_mm) {
  validate(wire, 0);
  if (!(std::isfinite(stroke_mm) && stroke_mm > 0))
    throw InputError("machine SVG of wire " + wire.name + ": stroke_mm must be a positive number of millimetres");
  // page coordinates: mm from the first point, y down (the drawing seen from the same side as the template)
  const Vec2 start = wire.points.front();
  std::string d;
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  for (std::size_t i = 0; i < wire.points.size(); ++i) {
    // y = start - point rather than -(point - start): the first point is (0, 0), never "-0.0000"
    const double x = to_mm(wire.points[i].x() - start.x()), y = to_mm(start.y() - wire.points[i].y());
    min_x = std::min(min_x, x); max_x = std::max(max_x, x);
    min_y = std::min(min_y, y); max_y = std::max(max_y, y);
    d += (i == 0 ? "M " : " L ") + num(x) + " " + num(y);
  }
  const double pad = stroke_mm;
  const double w = max_x - min_x + 2 * pad, h = max_y - min_y + 2 * pad;
  return "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + num(w) + "mm\" height=\"" + num(h) +
         "mm\" viewBox=\"" + num(min_x - pad) + " " + num(min_y - pad) + " " + num(w) + " " + num(h) + "\">\n"
         "  <path id=\"" + xml_escape(wire.name) + "\" fill=\"none\" stroke=\"black\" stroke-width=\"" + num(stroke_mm) +
         "\" d=\"" + d + "\"/>\n</svg>\n";
}

std::vector<SheetCell> sheet_layout(const std::vector<TemplateWire>& wires, const SvgOptions& options) {
  check_options(options);
  std::vector<SheetCell> cells;
  double x = 0.0, y = 0.0, row_height = 0.0;
  for (std::size_t k = 0; k < wires.size(); ++k) {
    validate(wires[k], k);
    const Box b = bbox_mm(wires[k]);
    SheetCell c;
    c.width_mm = b.width() + 2 * options.margin_mm;
    c.height_mm = b.height() + 2 * options.margin_mm;
    if (x > 0.0 && x + c.width_mm > options.sheet_width_mm) {  // new row
      y += row_height;
      x = 0.0;
      row_height = 0.0;
    }
    c.x_mm = x;
    c.y_mm = y;
    x += c.width_mm;
    row_height = std::max(row_height, c.height_mm);
    cells.push_back(c);
  }
  return cells;
}

std::string svg_sheet(const std::vector<TemplateWire>& wires, const SvgOptions& options) {
  if (wires.empty()) throw InputError("an SVG sheet needs at least one wire");
  const std::vector<SheetCell> cells = sheet_layout(wires, options);
  double width = 0.0, height = 0.0;
  for (const SheetCell& c : cells) {
    width = std::max(width, c.x_mm + c.width_mm);
    height = std::max(height, c.y_mm + c.height_mm);
  }
  std::string s = svg_open(width, height);
  for (std::size_t k = 0; k < wires.size(); ++k) s += wire_group(wires[k], k, cells[k].x_mm, cells[k].y_mm, options);
  return s + "</svg>\n";
}

}  // namespace wiresculpt::fab
