// The fabrication files: SVG (1:1, mm), DXF R12, G-code, the CSV bend table, and the atomic writer.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <set>
#include <sstream>
#include <algorithm>
#include <csignal>
#include <sys/resource.h>
#include <unistd.h>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/atomic_file.hpp"
#include "wiresculpt/fab/bend_program.hpp"
#include "wiresculpt/fab/dxf.hpp"
#include "wiresculpt/fab/gcode.hpp"
#include "wiresculpt/fab/serial.hpp"
#include "wiresculpt/fab/svg.hpp"

using namespace wiresculpt;
using namespace wiresculpt::fab;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {
constexpr double deg = std::numbers::pi / 180.0;

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

double attribute(const std::string& text, const std::string& name) {
  std::smatch m;
  const std::regex re(" " + name + "=\"([-0-9.]+)(mm)?\"");
  REQUIRE(std::regex_search(text, m, re));
  return std::stod(m[1]);
}

// XML-ish: every tag opened is closed in order (self-closing tags stand alone).
bool balanced_tags(const std::string& text) {
  std::vector<std::string> stack;
  const std::regex tag("<(/?)([a-zA-Z][a-zA-Z0-9]*)[^>]*?(/?)>");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), tag); it != std::sregex_iterator(); ++it) {
    const auto& m = *it;
    if (m[3] == "/") continue;
    if (m[1] == "/") {
      if (stack.empty() || stack.back() != m[2]) return false;
      stack.pop_back();
    } else {
      stack.push_back(m[2]);
    }
  }
  return stack.empty();
}

std::vector<Vec2> polyline_points(const std::string& svg, std::size_t which = 0) {
  const std::regex re("class=\"wire-path\"[^>]*points=\"([^\"]*)\"");
  auto it = std::sregex_iterator(svg.begin(), svg.end(), re);
  for (std::size_t k = 0; k < which; ++k) ++it;
  REQUIRE(it != std::sregex_iterator());
  std::vector<Vec2> out;
  std::istringstream in((*it)[1].str());
  for (std::string pair; in >> pair;) {
    const auto comma = pair.find(',');
    out.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
  }
  return out;
}

TemplateWire square_wire() {
  TemplateWire w;
  w.name = "A/0 <square>";
  w.points = {{0, 0}, {0.08, 0}, {0.08, 0.05}, {0, 0.05}, {0, 0}};
  w.bend_points = {1, 2, 3};
  w.crossing_points = {0, 2};
  return w;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("wiresculpt_fab_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

bool has_temp_files(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}
}  // namespace

TEST_CASE("svg: the template marks the start, the feed direction and the cut", "[fab][svg]") {
  auto number = [](const std::string& text, const std::string& re) {
    std::smatch m;
    REQUIRE(std::regex_search(text, m, std::regex(re)));
    return std::stod(m[1]);
  };
  TemplateWire open;
  open.name = "L";
  open.points = {{0, 0}, {0.03, 0.04}, {0.09, 0.04}};  // first edge 3-4-5 up and right, last edge along +x
  for (const TemplateWire& w : {open, square_wire()}) {
    const std::string svg = svg_wire(w);
    CHECK(balanced_tags(svg));
    CHECK(count(svg, "class=\"start\"") == 1);
    CHECK(count(svg, "class=\"feed\"") == 1);
    CHECK(count(svg, "class=\"cut\"") == 1);
    const auto q = polyline_points(svg);  // page coordinates, y down
    const double cx = number(svg, "class=\"start\" cx=\"([-0-9.]+)\""), cy = number(svg, "class=\"start\"[^>]* cy=\"([-0-9.]+)\"");
    CHECK(cx == Approx(q.front().x()).margin(1e-4));
    CHECK(cy == Approx(q.front().y()).margin(1e-4));
    const Vec2 feed(number(svg, "data-dx=\"([-0-9.]+)\""), number(svg, "data-dy=\"([-0-9.]+)\""));
    CHECK(feed.dot((q[1] - q[0]).normalized()) == Approx(1).margin(1e-4));
    // the arrow's line runs along the feed direction, beside the first segment
    const std::regex line_re("class=\"feed\"[^>]*><line x1=\"([-0-9.]+)\" y1=\"([-0-9.]+)\" x2=\"([-0-9.]+)\" y2=\"([-0-9.]+)\"");
    std::smatch m;
    REQUIRE(std::regex_search(svg, m, line_re));
    const Vec2 a(std::stod(m[1]), std::stod(m[2])), b(std::stod(m[3]), std::stod(m[4]));
    CHECK((b - a).normalized().dot(feed) == Approx(1).margin(1e-3));
    const std::regex cut_re("class=\"cut\" x1=\"([-0-9.]+)\" y1=\"([-0-9.]+)\" x2=\"([-0-9.]+)\" y2=\"([-0-9.]+)\"");
    REQUIRE(std::regex_search(svg, m, cut_re));
    const Vec2 c1(std::stod(m[1]), std::stod(m[2])), c2(std::stod(m[3]), std::stod(m[4]));
    CHECK(((c1 + c2) / 2 - q.back()).norm() == Approx(0).margin(1e-3));  // across the last point
    CHECK(std::abs((c2 - c1).normalized().dot((q.back() - q[q.size() - 2]).normalized())) < 1e-3);
  }
  // the open wire's numbers by hand: feed along (3, -4)/5 on the page (y down), cut across +x
  const std::string svg = svg_wire(open);
  CHECK(number(svg, "data-dx=\"([-0-9.]+)\"") == Approx(0.6).margin(1e-4));
  CHECK(number(svg, "data-dy=\"([-0-9.]+)\"") == Approx(-0.8).margin(1e-4));
}

TEST_CASE("svg: the predicted wire is drawn dashed over the rest shape and named in the legend", "[fab][svg][preview]") {
  TemplateWire w = square_wire();
  CHECK(count(svg_wire(w), "class=\"preview\"") == 0);  // no preview given: none drawn, no legend
  CHECK(count(svg_wire(w), "class=\"legend\"") == 0);
  // the predicted wire 2 mm to the right and 1 mm up of the rest shape (inside its bounding box's width + 2 mm)
  for (const Vec2& p : w.points) w.preview.push_back(p + Vec2(0.002, 0.001));
  w.preview_distance = 0.00224;
  const std::string svg = svg_wire(w);
  CHECK(balanced_tags(svg));
  CHECK(count(svg, "class=\"preview\"") == 1);
  CHECK(count(svg, "stroke-dasharray") == 2);  // the preview and its sample in the legend
  CHECK(count(svg, "class=\"legend\"") == 1);
  CHECK(count(svg, "predicted wire") == 1);
  CHECK(count(svg, "up to 2.2 mm from the rest shape") == 1);
  const auto q = polyline_points(svg);
  const std::regex re("class=\"preview\"[^>]*points=\"([^\"]*)\"");
  std::smatch m;
  REQUIRE(std::regex_search(svg, m, re));
  std::istringstream in(m[1].str());
  std::vector<Vec2> pv;
  for (std::string pair; in >> pair;) {
    const auto comma = pair.find(',');
    pv.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
  }
  REQUIRE(pv.size() == q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {  // 1:1, y down on the page
    CHECK(pv[i].x() - q[i].x() == Approx(2.0).margin(1e-3));
    CHECK(pv[i].y() - q[i].y() == Approx(-1.0).margin(1e-3));
  }
  // the cell grows to hold the preview: 80 + 2 mm wide, 50 + 1 mm tall, plus margins
  CHECK(attribute(svg, "width") == Approx(82.0 + 20.0).margin(1e-3));
  CHECK(attribute(svg, "height") == Approx(51.0 + 20.0).margin(1e-3));
}

TEST_CASE("svg: a closed wire's overlap is drawn over the last stretch of its path", "[fab][svg][overlap]") {
  TemplateWire w = square_wire();  // 80 x 50 mm, walked (0,0) (80,0) (80,50) (0,50) (0,0)
  w.points.push_back({0.0, -0.02});  // 20 mm past the cut, straight on
  w.overlap = 0.03;                  // the band: 20 mm back to the cut, 10 mm more along the last side
  const std::string svg = svg_wire(w);
  CHECK(balanced_tags(svg));
  CHECK(count(svg, "class=\"overlap\"") == 1);
  CHECK(count(svg, "overlap 30.0 mm") == 1);
  const auto q = polyline_points(svg);
  std::smatch m;
  REQUIRE(std::regex_search(svg, m, std::regex("class=\"overlap\"[^>]*><polyline[^>]*points=\"([^\"]*)\"")));
  std::istringstream in(m[1].str());
  std::vector<Vec2> band;
  for (std::string pair; in >> pair;) {
    const auto comma = pair.find(',');
    band.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
  }
  REQUIRE(band.size() == 3);  // the end, the cut, 10 mm before the cut on the last side
  CHECK((band[0] - q.back()).norm() < 1e-3);
  CHECK((band[1] - q[q.size() - 2]).norm() < 1e-3);
  CHECK((band[2] - q[q.size() - 2]).norm() == Approx(10.0).margin(1e-3));
  CHECK((band[2] - q[q.size() - 3]).norm() == Approx(40.0).margin(1e-3));
  w.overlap = -1.0;
  CHECK_THROWS_WITH(svg_wire(w), Contains("overlap"));
}

TEST_CASE("svg: one wire at 1:1 with width and height of the bounding box plus margins", "[fab][svg]") {
  SvgOptions o;
  o.margin_mm = 12.0;
  const std::string svg = svg_wire(square_wire(), o);
  CHECK(svg.rfind("<?xml", 0) == 0);
  CHECK(balanced_tags(svg));
  CHECK(attribute(svg, "width") == Approx(80 + 24));
  CHECK(attribute(svg, "height") == Approx(50 + 24));
  CHECK_THAT(svg, Contains("width=\"104.0000mm\"") && Contains("viewBox=\"0 0 104.0000 74.0000\""));
  CHECK_THAT(svg, Contains("A/0 &lt;square&gt;"));
  CHECK(count(svg, "class=\"bend\"") == 3);
  CHECK(count(svg, "class=\"crossing\"") == 2);
  const auto q = polyline_points(svg);
  REQUIRE(q.size() == 5);
  // 1:1 in mm, y up on paper: point (x, y) m -> (margin + 1000 x, margin + 50 - 1000 y).
  CHECK(q[1].x() == Approx(12 + 80));
  CHECK(q[1].y() == Approx(12 + 50));
  CHECK(q[2].y() == Approx(12));
  // A bend tick crosses the wire at its point: the tick at point 2 (the corner (80, 50) mm) is
  // centred there.
  std::smatch m;
  REQUIRE(std::regex_search(svg, m, std::regex("data-point=\"2\" x1=\"([-0-9.]+)\" y1=\"([-0-9.]+)\" x2=\"([-0-9.]+)\" y2=\"([-0-9.]+)\"")));
  CHECK((std::stod(m[1]) + std::stod(m[3])) / 2 == Approx(92.0));
  CHECK((std::stod(m[2]) + std::stod(m[4])) / 2 == Approx(12.0));
  CHECK(std::hypot(std::stod(m[1]) - std::stod(m[3]), std::stod(m[2]) - std::stod(m[4])) == Approx(2 * o.tick_mm));
}

TEST_CASE("svg: the sheet lays wires out without overlap", "[fab][svg]") {
  std::vector<TemplateWire> wires;
  for (int k = 0; k < 7; ++k) {
    TemplateWire w = square_wire();
    w.name = "W" + std::to_string(k);
    for (auto& p : w.points) p = p * (1.0 + 0.5 * k) + Vec2(0.3 * k, -0.1 * k);  // anywhere in the plane
    wires.push_back(w);
  }
  SvgOptions o;
  o.sheet_width_mm = 400;
  const auto cells = sheet_layout(wires, o);
  REQUIRE(cells.size() == wires.size());
  for (std::size_t a = 0; a < cells.size(); ++a)
    for (std::size_t b = a + 1; b < cells.size(); ++b) {
      const bool apart = cells[a].x_mm + cells[a].width_mm <= cells[b].x_mm + 1e-9 ||
                         cells[b].x_mm + cells[b].width_mm <= cells[a].x_mm + 1e-9 ||
                         cells[a].y_mm + cells[a].height_mm <= cells[b].y_mm + 1e-9 ||
                         cells[b].y_mm + cells[b].height_mm <= cells[a].y_mm + 1e-9;
      CHECK(apart);
    }
  const std::string svg = svg_sheet(wires, o);
  CHECK(balanced_tags(svg));
  CHECK(count(svg, "class=\"wire\"") == 7);
  double width = 0, height = 0;
  for (const auto& c : cells) {
    width = std::max(width, c.x_mm + c.width_mm);
    height = std::max(height, c.y_mm + c.height_mm);
  }
  CHECK(attribute(svg, "width") == Approx(width));
  CHECK(attribute(svg, "height") == Approx(height));
  for (std::size_t k = 0; k < wires.size(); ++k) {
    const auto q = polyline_points(svg, k);
    for (const Vec2& p : q) {
      CHECK(p.x() >= cells[k].x_mm + o.margin_mm - 1e-3);
      CHECK(p.x() <= cells[k].x_mm + cells[k].width_mm - o.margin_mm + 1e-3);
      CHECK(p.y() >= cells[k].y_mm + o.margin_mm - 1e-3);
      CHECK(p.y() <= cells[k].y_mm + cells[k].height_mm - o.margin_mm + 1e-3);
    }
    // The same shape at 1:1: edge lengths in mm equal the wire's in metres * 1000.
    for (std::size_t i = 1; i < q.size(); ++i)
      CHECK((q[i] - q[i - 1]).norm() == Approx(1000 * (wires[k].points[i] - wires[k].points[i - 1]).norm()).margin(1e-3));
  }
  TemplateWire bad = square_wire();
  bad.crossing_points = {9};
  CHECK_THROWS_WITH(svg_sheet({square_wire(), bad}), Contains("wire 1") && Contains("crossing point index 9"));
}

TEST_CASE("dxf: R2000 structure, mm units, one layer and one LWPOLYLINE per wire", "[fab][dxf]") {
  std::vector<TemplateWire> wires{square_wire(), square_wire()};
  wires[1].name = "B/1";
  for (auto& p : wires[1].points) p += Vec2(0.2, 0.0);
  const std::string dxf = dxf_document(wires);
  const auto lines = split_lines(dxf);
  REQUIRE(lines.size() % 2 == 0);
  for (std::size_t i = 0; i < lines.size(); i += 2) {
    INFO("group code line " << i + 1 << ": '" << lines[i] << "'");
    CHECK(std::regex_match(lines[i], std::regex(" *-?[0-9]+")));
  }
  CHECK(lines[lines.size() - 2] == "  0");
  CHECK(lines.back() == "EOF");
  CHECK_THAT(dxf, Contains("$ACADVER\n  1\nAC1015\n"));
  CHECK_THAT(dxf, Contains("$INSUNITS\n 70\n4\n"));
  CHECK(count(dxf, "\nLWPOLYLINE\n") == 2);
  CHECK(count(dxf, "\nPOLYLINE\n") == 0);
  CHECK(count(dxf, "\nTEXT\n") == 0);  // labels are off by default: machine files hold the wire only
  CHECK(dxf_layer_name(0, "A/0 <square>") == "WIRE_0_A_0__SQUARE_");
  CHECK(dxf_layer_name(1, "B/1") == "WIRE_1_B_1");
  CHECK(dxf_layer_name(3, std::string(60, 'x')).size() == 31);
  CHECK(count(dxf, "\n  2\nWIRE_1_B_1\n") == 1);  // the layer table entry
  CHECK(count(dxf, "\n  8\nWIRE_1_B_1\n") == 1);  // the polyline
  CHECK_THAT(dxf, Contains(" 10\n280.000000\n 20\n50.000000\n"));  // (0.28, 0.05) m of wire B
  // handles are unique
  std::set<std::string> handles;
  std::size_t handle_count = 0;
  for (std::size_t i = 0; i + 1 < lines.size(); i += 2)
    if (lines[i] == "  5" || lines[i] == "105") { handles.insert(lines[i + 1]); ++handle_count; }
  CHECK(handles.size() == handle_count);

  DxfOptions labelled;
  labelled.labels = true;
  CHECK(count(dxf_document(wires, labelled), "\nTEXT\n") == 2);
}

TEST_CASE("dxf: layouts move each wire, side by side never overlaps", "[fab][dxf]") {
  std::vector<TemplateWire> wires{square_wire(), square_wire(), square_wire()};
  for (auto& p : wires[1].points) p = Vec2(2 * p.x() - 0.05, p.y());  // wider, overlapping wire 0
  DxfOptions o;
  o.layout = DxfLayout::start_at_origin;
  for (const Polyline2& w : dxf_placed_mm(wires, o)) CHECK(w.front().norm() == Approx(0).margin(1e-12));
  o.layout = DxfLayout::side_by_side;
  o.gap_mm = 15;
  const auto placed = dxf_placed_mm(wires, o);
  double previous_right = -1e9;
  for (std::size_t k = 0; k < placed.size(); ++k) {
    double left = 1e9, right = -1e9, bottom = 1e9;
    for (const Vec2& p : placed[k]) { left = std::min(left, p.x()); right = std::max(right, p.x()); bottom = std::min(bottom, p.y()); }
    if (k > 0) CHECK(left - previous_right == Approx(15).margin(1e-9));
    CHECK(bottom == Approx(0).margin(1e-9));
    previous_right = right;
    for (std::size_t i = 1; i < placed[k].size(); ++i)  // moved, not reshaped
      CHECK((placed[k][i] - placed[k][i - 1]).norm() ==
            Approx(1000 * (wires[k].points[i] - wires[k].points[i - 1]).norm()).margin(1e-9));
  }
  o.gap_mm = -1;
  CHECK_THROWS_WITH(dxf_placed_mm(wires, o), Contains("gap_mm"));
}

TEST_CASE("svg: the machine file is one path from the origin", "[fab][svg]") {
  TemplateWire w = square_wire();
  for (auto& p : w.points) p += Vec2(0.3, -0.1);
  const std::string svg = svg_machine(w);
  CHECK(count(svg, "<path") == 1);
  CHECK(count(svg, "<polyline") + count(svg, "<line") + count(svg, "<circle") + count(svg, "<text") == 0);
  CHECK_THAT(svg, Contains("d=\"M 0.0000 0.0000 L "));
  CHECK_THROWS_WITH(svg_machine(w, 0.0), Contains("stroke_mm"));
}

TEST_CASE("gcode: the default profile ducks its pin at every change of bend side", "[fab][gcode]") {
  // a zigzag whose turn signs are known by construction: + - - + - (left, right, right, left, right)
  const Polyline2 zigzag{{0, 0}, {0.03, 0}, {0.06, 0.03}, {0.09, 0.03}, {0.12, 0}, {0.15, 0.0}, {0.18, -0.03}};
  std::vector<int> sides;
  for (std::size_t i = 1; i + 1 < zigzag.size(); ++i) {
    const Vec2 a = zigzag[i] - zigzag[i - 1], b = zigzag[i + 1] - zigzag[i];
    const double cross = a.x() * b.y() - a.y() * b.x();
    if (std::abs(cross) > 1e-12) sides.push_back(cross > 0 ? 1 : -1);
  }
  int changes = 0, side = 1;  // the pin starts on the positive (left) side
  for (int s : sides) { changes += s != side; side = s; }
  REQUIRE(changes >= 2);
  const MachineProfile m;
  CHECK(m.axes.pin_axis == 'Z');
  const auto lines = stream_lines(gcode_program(make_bend_program(zigzag, m), m, GcodeInfo{"Z", "", true}));
  const int back = side != 1;  // a program ending on the negative side ducks back before M2
  CHECK(std::count(lines.begin(), lines.end(), "G0 Z-5.0000") == changes + back);
  CHECK(std::count(lines.begin(), lines.end(), "G0 Z5.0000") == changes + back);
  for (std::size_t i = 0; i + 2 < lines.size(); ++i)  // between pin down and pin up the head swings across
    if (lines[i] == "G0 Z-5.0000") {
      CHECK((lines[i + 1] == "G0 Y20.0000" || lines[i + 1] == "G0 Y-20.0000"));
      CHECK(lines[i + 2] == "G0 Z5.0000");
    }
}

TEST_CASE("gcode: header, axis mapping, units and the bend table", "[fab][gcode]") {
  MachineProfile m;
  m.springback_a = 0.9;
  m.springback_b = -2 * deg;
  const double a = 0.05;
  const BendProgram prog = make_bend_program(Polyline2{{0, 0}, {a, 0}, {a, a}, {2 * a, a}}, m);  // +90, -90
  REQUIRE(prog.bend_count == 2);
  GcodeInfo info{"A/0", "steel 3 mm", true};
  const std::string g = gcode_program(prog, m, info);
  CHECK_THAT(g, Contains("; wire: A/0\n") && Contains("; material: steel 3 mm\n") && Contains("; length: 150.000 mm"));
  const auto lines = stream_lines(g);
  CHECK_NOTHROW(validate_program(lines, m));
  const double c = (90.0 + 2.0) / 0.9;
  char plus[64], minus[64];
  std::snprintf(plus, sizeof plus, "G1 Y%.4f F5400.0", c);
  std::snprintf(minus, sizeof minus, "G1 Y-%.4f F5400.0", c);
  const std::vector<std::string> expected{"G21", "G91", "G94",
                                          "G1 X50.0000 F1200.0", plus, minus, "G4 P0",
                                          "G1 X50.0000 F1200.0", "G0 Z-5.0000", "G0 Y20.0000", "G0 Z5.0000", minus,
                                          plus, "G4 P0", "G1 X50.0000 F1200.0", "G4 P0",
                                          "G0 Z-5.0000", "G0 Y-20.0000", "G0 Z5.0000", "M2"};
  // the default profile ducks its pin (Z) under the wire, swings the head across (Y, 20 deg) and
  // raises the pin before the bend to the other side, and ducks back to the positive side at the end
  CHECK(lines == expected);

  // A profile without a pin axis (a head that bends both ways) writes what every profile wrote
  // before the pin became the default: the same program without the ducks.
  MachineProfile no_pin = m;
  no_pin.axes.pin_axis = '\0';
  const std::vector<std::string> expected_no_pin{"G21", "G91", "G94",
                                                 "G1 X50.0000 F1200.0", plus, minus, "G4 P0",
                                                 "G1 X50.0000 F1200.0", minus, plus, "G4 P0",
                                                 "G1 X50.0000 F1200.0", "G4 P0", "M2"};
  CHECK(stream_lines(gcode_program(prog, no_pin, info)) == expected_no_pin);

  // Another mapping: feed on A in 0.5 units/mm, bend on B in 2 units/deg, left = negative, a pin on Z.
  m.axes.feed_axis = 'A';
  m.axes.bend_axis = 'B';
  m.axes.pin_axis = 'Z';
  m.axes.feed_units_per_mm = 0.5;
  m.axes.bend_units_per_deg = 2.0;
  m.left_is_positive = false;
  info.sync_each_step = false;
  const auto l2 = stream_lines(gcode_program(prog, m, info));
  CHECK_NOTHROW(validate_program(l2, m));
  CHECK(l2[3] == "G1 A25.0000 F600.0");
  std::snprintf(minus, sizeof minus, "G1 B-%.4f F10800.0", 2 * c);  // left bend, left = negative
  CHECK(l2[4] == "G0 Z-5.0000");  // the pin starts on the positive side: change sides first
  CHECK(l2[5] == "G0 B40.0000");   // the swing, 20 deg at 2 units/deg, the positive way
  CHECK(l2[6] == "G0 Z5.0000");
  CHECK(l2[7] == minus);
  CHECK(std::count_if(l2.begin(), l2.end(), [](const std::string& s) { return s.rfind("G0 Z", 0) == 0; }) == 4);
  CHECK_THROWS_WITH(validate_program({"G1 X5"}, m), Contains("line 1") && Contains("'X'"));
  CHECK_THROWS_WITH(validate_program({"G1 A5", "G1 A5 ; note"}, m), Contains("line 2") && Contains("comment"));
  CHECK_THROWS_WITH(validate_program({"G1 A5", "G1 A5", "G1 A!"}, m), Contains("line 3") && Contains("realtime"));
  CHECK_THROWS_WITH(validate_program({std::string(80, 'G')}, m), Contains("line 1") && Contains("79"));

  const std::string csv = bend_table_csv(prog);
  const auto rows = split_lines(csv);
  REQUIRE(rows.size() == 4);
  CHECK(rows[0] == "step,feed_mm,bend_deg,commanded_deg");
  char row[128];
  std::snprintf(row, sizeof row, "1,50.0000,90.0000,%.4f", c);
  CHECK(rows[1] == row);
  std::snprintf(row, sizeof row, "2,50.0000,-90.0000,-%.4f", c);
  CHECK(rows[2] == row);
  CHECK(rows[3] == "3,50.0000,0.0000,0.0000");
}

TEST_CASE("gcode: stream_lines strips comments and blank lines", "[fab][gcode]") {
  const auto l = stream_lines("; header\n\nG21 (mm)\n  G1 X5 ; feed\r\n(only a comment)\nM2");
  CHECK(l == std::vector<std::string>{"G21", "G1 X5", "M2"});
}

TEST_CASE("atomic file: complete files only, no temporary left behind", "[fab][atomic]") {
  const fs::path dir = fresh_dir("atomic");
  const fs::path target = dir / "wire.svg";
  write_file_atomic(target, "first version\n");
  CHECK(read(target) == "first version\n");
  const std::string big(1 << 20, 'x');
  write_file_atomic(target, big);
  CHECK(read(target) == big);
  CHECK_FALSE(has_temp_files(dir));

  SECTION("a folder that does not exist") {
    CHECK_THROWS_AS(write_file_atomic(dir / "missing" / "a.dxf", "x"), InputError);
    CHECK_THROWS_WITH(write_file_atomic(dir / "missing" / "a.dxf", "x"), Contains("missing/a.dxf"));
    CHECK_FALSE(fs::exists(dir / "missing"));
  }
  SECTION("a 'folder' that is a file") {
    write_file_atomic(dir / "plain", "not a folder");
    CHECK_THROWS_WITH(write_file_atomic(dir / "plain" / "a.dxf", "x"), Contains("plain/a.dxf"));
    CHECK(read(dir / "plain") == "not a folder");
  }
  SECTION("the rename fails: the target is a folder; the temporary file is removed") {
    fs::create_directories(dir / "occupied" / "inner");
    CHECK_THROWS_WITH(write_file_atomic(dir / "occupied", "text"), Contains("occupied"));
    CHECK(fs::is_directory(dir / "occupied" / "inner"));
    CHECK_FALSE(has_temp_files(dir));
    CHECK(read(target) == big);  // other files untouched
  }
  SECTION("a folder nobody may create files in, not even root") {
    CHECK_THROWS_WITH(write_file_atomic("/proc/self/wiresculpt.svg", "x"), Contains("/proc/self/wiresculpt.svg"));
  }
  SECTION("the disk fills up mid-write: no partial file, the old one kept") {
    write_file_atomic(dir / "kept.dxf", "old\n");
    rlimit old{};
    REQUIRE(::getrlimit(RLIMIT_FSIZE, &old) == 0);
    const auto previous = std::signal(SIGXFSZ, SIG_IGN);  // writes past the limit fail with EFBIG
    rlimit small = old;
    small.rlim_cur = 64 * 1024;
    REQUIRE(::setrlimit(RLIMIT_FSIZE, &small) == 0);
    bool threw = false;
    try {
      write_file_atomic(dir / "kept.dxf", big);
    } catch (const InputError& e) {
      threw = std::string(e.what()).find("kept.dxf") != std::string::npos;
    }
    ::setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, previous);
    CHECK(threw);
    CHECK(read(dir / "kept.dxf") == "old\n");
    CHECK_FALSE(has_temp_files(dir));
  }
  SECTION("a read-only folder (only meaningful when not running as root)") {
    const fs::path ro = dir / "readonly";
    fs::create_directories(ro);
    write_file_atomic(ro / "kept.csv", "old\n");
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    if (::geteuid() != 0) {
      CHECK_THROWS_WITH(write_file_atomic(ro / "kept.csv", "new\n"), Contains("kept.csv"));
      CHECK(read(ro / "kept.csv") == "old\n");
    }
    fs::permissions(ro, fs::perms::owner_all);
    CHECK_FALSE(has_temp_files(ro));
  }
  fs::remove_all(dir);
}
