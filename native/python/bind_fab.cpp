// Fabrication: bend programs, 1:1 templates (SVG, DXF), G-code, the bend table, serial streaming.
// Degrees and millimetres are the edge units of the profile dict; they become SI right here
// through fab/machine.hpp's helpers (the one conversion place) before anything reaches the core.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cctype>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "progress.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/atomic_file.hpp"
#include "wiresculpt/fab/bend_program.hpp"
#include "wiresculpt/fab/dxf.hpp"
#include "wiresculpt/fab/gcode.hpp"
#include "wiresculpt/fab/machine.hpp"
#include "wiresculpt/fab/serial.hpp"
#include "wiresculpt/fab/svg.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

using namespace wiresculpt::fab;
// `s` quoted for a message on one line: bytes outside printable ASCII as \n, \t, \r or \xNN,
// quote and backslash escaped, at most 40 bytes shown.
std::string quoted(const std::string& s) {
  static const char* hex = "0123456789abcdef";
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c == '\r') out += "\\r";
    else if (c == '\'' || c == '\\') out += std::string("\\") + static_cast<char>(c);
    else if (c < 0x20 || c >= 0x7f) out += std::string("\\x") + hex[c >> 4] + hex[c & 15];
    else out += static_cast<char>(c);
  }
  return out + (s.size() > 40 ? "'... (" + std::to_string(s.size()) + " bytes)" : "'");
}

char axis_letter(py::handle v, const std::string& at) {
  const std::string s = to_text(v, at);
  if (s.size() > 1 || (s.size() == 1 && !std::isalpha(static_cast<unsigned char>(s[0]))))
    wrong(at, "one letter", quoted(s));
  return s.empty() ? '\0' : static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
}

/// The profile dict (edge units, every key optional) -> MachineProfile (SI).
MachineProfile to_profile(py::handle d) {
  MachineProfile p;
  auto degrees = [](double& out) {
    return [&out](py::handle v, const std::string& at) { out = from_deg(to_number(v, at)); };
  };
  auto axis = [](char& out) { return [&out](py::handle v, const std::string& at) { out = axis_letter(v, at); }; };
  read_fields(d, "profile",
              {field::text("name", p.name), field::number("min_segment", p.min_feed),  // metres, as design.json
               field::number("min_feed", p.min_feed), {"max_bend_deg", degrees(p.max_bend)},
               {"min_bend_deg", degrees(p.min_bend)}, {"max_commanded_deg", degrees(p.max_commanded)},
               field::boolean("left_is_positive", p.left_is_positive), field::number("springback_a", p.springback_a),
               {"springback_b_deg", degrees(p.springback_b)},
               {"feed_speed_mm_s", [&](py::handle v, const std::string& at) { p.feed_speed = from_mm(to_number(v, at)); }},
               {"bend_speed_deg_s", degrees(p.bend_speed)}, field::number("seconds_per_bend", p.seconds_per_bend),
               {"feed_axis", axis(p.axes.feed_axis)}, {"bend_axis", axis(p.axes.bend_axis)},
               {"pin_axis", axis(p.axes.pin_axis)},  // "" for none; null is refused as every null is
               field::number("feed_units_per_mm", p.axes.feed_units_per_mm),
               field::number("bend_units_per_deg", p.axes.bend_units_per_deg),
               field::number("pin_travel", p.axes.pin_travel), {"pin_swing_deg", degrees(p.axes.pin_swing)},
               field::integer("baud", p.serial.baud),
               field::integer("data_bits", p.serial.data_bits), field::integer("stop_bits", p.serial.stop_bits),
               field::choice("parity", p.serial.parity,
                             {{"none", SerialSettings::Parity::none},
                              {"odd", SerialSettings::Parity::odd},
                              {"even", SerialSettings::Parity::even}}),
               field::choice("flow_control", p.serial.flow_control,
                             {{"none", SerialSettings::FlowControl::none},
                              {"xon_xoff", SerialSettings::FlowControl::xon_xoff},
                              {"rts_cts", SerialSettings::FlowControl::rts_cts}})});
  validate(p);
  return p;
}

py::dict from_profile(const MachineProfile& p) {
  const char* parity[] = {"none", "odd", "even"};
  const char* flow[] = {"none", "xon_xoff", "rts_cts"};
  return py::dict(
      py::arg("name") = p.name, py::arg("min_segment") = p.min_feed, py::arg("max_bend_deg") = to_deg(p.max_bend),
      py::arg("min_bend_deg") = to_deg(p.min_bend), py::arg("max_commanded_deg") = to_deg(p.max_commanded),
      py::arg("left_is_positive") = p.left_is_positive, py::arg("springback_a") = p.springback_a,
      py::arg("springback_b_deg") = to_deg(p.springback_b), py::arg("feed_speed_mm_s") = to_mm(p.feed_speed),
      py::arg("bend_speed_deg_s") = to_deg(p.bend_speed), py::arg("seconds_per_bend") = p.seconds_per_bend,
      py::arg("feed_axis") = std::string(1, p.axes.feed_axis), py::arg("bend_axis") = std::string(1, p.axes.bend_axis),
      py::arg("pin_axis") = p.axes.pin_axis ? std::string(1, p.axes.pin_axis) : std::string(),
      py::arg("feed_units_per_mm") = p.axes.feed_units_per_mm, py::arg("bend_units_per_deg") = p.axes.bend_units_per_deg,
      py::arg("pin_travel") = p.axes.pin_travel, py::arg("pin_swing_deg") = to_deg(p.axes.pin_swing),
      py::arg("baud") = p.serial.baud,
      py::arg("data_bits") = p.serial.data_bits, py::arg("stop_bits") = p.serial.stop_bits,
      py::arg("parity") = parity[static_cast<int>(p.serial.parity)],
      py::arg("flow_control") = flow[static_cast<int>(p.serial.flow_control)]);
}

/// {"name", "points" (n, 2) m, "bend_points", "crossing_points"} -> TemplateWire.
std::vector<TemplateWire> to_templates(py::handle wires) {
  std::vector<TemplateWire> out;
  each_item(wires, "wires", [&](py::handle item, const std::string& where) {
    TemplateWire w;
    read_fields(item, where,
                {field::text("name", w.name),
                 {"points", [&](py::handle v, const std::string& at) { w.points = to_points<2>(v, at); }},
                 {"bend_points", [&](py::handle v, const std::string& at) { w.bend_points = to_integers<std::size_t>(v, at); }},
                 {"crossing_points",
                  [&](py::handle v, const std::string& at) { w.crossing_points = to_integers<std::size_t>(v, at); }},
                 {"self_crossings", [&](py::handle v, const std::string& at) { w.self_crossings = to_points<2>(v, at); }},
                 {"preview", [&](py::handle v, const std::string& at) { w.preview = to_points<2>(v, at); }},
                 field::number("preview_distance", w.preview_distance), field::number("overlap", w.overlap)});
    out.push_back(std::move(w));
  });
  return out;
}

SvgOptions to_svg_options(py::handle d) {
  SvgOptions o;
  read_fields(d, "options",
              {field::number("margin_mm", o.margin_mm), field::number("stroke_mm", o.stroke_mm),
               field::number("tick_mm", o.tick_mm), field::number("crossing_radius_mm", o.crossing_radius_mm),
               field::number("label_mm", o.label_mm), field::number("sheet_width_mm", o.sheet_width_mm)});
  return o;
}

void maybe_write(const std::optional<std::string>& path, const std::string& text) {
  if (path && !path->empty()) write_file_atomic(*path, text);
}

py::dict program_dict(const BendProgram& p) {
  py::list steps;
  std::vector<double> feeds, bends, commanded;
  for (const BendStep& s : p.steps) {
    steps.append(py::dict(py::arg("feed_mm") = to_mm(s.feed), py::arg("bend_deg") = to_deg(s.bend),
                          py::arg("commanded_deg") = to_deg(s.commanded), py::arg("vertex") = s.vertex));
    feeds.push_back(to_mm(s.feed));
    bends.push_back(to_deg(s.bend));
    commanded.push_back(to_deg(s.commanded));
  }
  return py::dict(py::arg("steps") = steps, py::arg("feeds_mm") = feeds, py::arg("bends_deg") = bends,
                  py::arg("commanded_deg") = commanded, py::arg("wire_length") = p.wire_length,
                  py::arg("bend_count") = p.bend_count, py::arg("machine_seconds") = p.machine_seconds,
                  py::arg("shape_error") = p.shape_error, py::arg("merged_points") = p.merged_points,
                  py::arg("small_turns") = p.small_turns, py::arg("rounded_bends") = p.rounded_bends,
                  py::arg("dropped_turn_deg") = to_deg(p.dropped_turn),
                  py::arg("start") = std::vector<double>{p.start.x(), p.start.y()},
                  py::arg("start_heading_deg") = to_deg(p.start_heading),
                  py::arg("bend_vertices") = bend_vertices(p), py::arg("rebuilt") = to_array(rebuild_polyline(p)));
}

py::dict make_bend_program_py(const py::object& points, const py::object& profile, const py::object& machine) {
  const MachineProfile m = to_profile(profile);
  const MachineProfile made_by = machine.is_none() ? m : to_profile(machine);
  const Polyline2 poly = to_points<2>(points, "points");
  BendProgram p;
  Polyline2 predicted;
  double distance = 0.0;
  {
    py::gil_scoped_release release;
    p = make_bend_program(poly, m);
    predicted = predict_polyline(p, made_by);
    distance = arclength_distance(poly, predicted);
  }
  py::dict out = program_dict(p);
  out["predicted"] = to_array(predicted);
  out["preview_distance"] = distance;
  return out;
}

py::list bend_program_problems_py(const py::object& points, const py::object& profile) {
  const MachineProfile m = to_profile(profile);
  const Polyline2 poly = to_points<2>(points, "points");
  std::vector<BendProblem> problems;
  {
    py::gil_scoped_release release;
    problems = bend_program_problems(poly, m);
  }
  static const char* kinds[] = {"over_bend", "short_feed", "command"};
  py::list out;
  for (const BendProblem& b : problems) {
    const bool feed = b.kind == BendProblem::Kind::short_feed;
    out.append(py::dict(py::arg("kind") = kinds[static_cast<int>(b.kind)], py::arg("number") = b.number,
                        py::arg("from") = b.from, py::arg("to") = b.to, py::arg("at") = b.at,
                        py::arg("value") = feed ? b.value : to_deg(b.value),
                        py::arg("limit") = feed ? b.limit : to_deg(b.limit), py::arg("message") = b.message));
  }
  return out;
}

std::string write_svg(const std::optional<std::string>& path, const py::object& wires, std::optional<bool> sheet,
                      const py::object& options) {
  const std::vector<TemplateWire> w = to_templates(wires);
  const SvgOptions o = to_svg_options(options);
  const bool as_sheet = sheet.value_or(w.size() != 1);
  std::string text;
  {
    py::gil_scoped_release release;
    if (!as_sheet && w.size() != 1)
      throw InputError("an SVG of one wire needs exactly one wire, got " + std::to_string(w.size()));
    text = as_sheet ? svg_sheet(w, o) : svg_wire(w[0], o);
    maybe_write(path, text);
  }
  return text;
}

std::string write_dxf(const std::optional<std::string>& path, const py::object& wires, bool labels,
                      const std::string& layout, double gap_mm) {
  const std::vector<TemplateWire> w = to_templates(wires);
  DxfOptions o;
  o.labels = labels;
  o.gap_mm = gap_mm;
  if (layout == "as_given") o.layout = DxfLayout::as_given;
  else if (layout == "start_at_origin") o.layout = DxfLayout::start_at_origin;
  else if (layout == "side_by_side") o.layout = DxfLayout::side_by_side;
  else throw InputError("DXF layout must be \"as_given\", \"start_at_origin\" or \"side_by_side\", got \"" + layout + "\"");
  std::string text;
  {
    py::gil_scoped_release release;
    text = dxf_document(w, o);
    maybe_write(path, text);
  }
  return text;
}

std::string write_machine_svg(const std::optional<std::string>& path, const py::object& wire, double stroke_mm) {
  py::list one;
  one.append(wire);
  const std::vector<TemplateWire> w = to_templates(one);
  std::string text;
  {
    py::gil_scoped_release release;
    text = svg_machine(w[0], stroke_mm);
    maybe_write(path, text);
  }
  return text;
}

std::string write_gcode(const std::optional<std::string>& path, const py::object& points, const py::object& profile,
                        const std::string& wire_name, const std::string& material, bool sync_each_step) {
  const MachineProfile m = to_profile(profile);
  const Polyline2 poly = to_points<2>(points, "points");
  std::string text;
  {
    py::gil_scoped_release release;
    text = gcode_program(make_bend_program(poly, m), m, GcodeInfo{wire_name, material, sync_each_step});
    maybe_write(path, text);
  }
  return text;
}

std::string write_bend_table(const std::optional<std::string>& path, const py::object& points,
                             const py::object& profile) {
  const MachineProfile m = to_profile(profile);
  const Polyline2 poly = to_points<2>(points, "points");
  std::string text;
  {
    py::gil_scoped_release release;
    text = bend_table_csv(make_bend_program(poly, m));
    maybe_write(path, text);
  }
  return text;
}

// An open serial link that the caller keeps between commands (the Machine panel: status reports,
// jogs, a console line) and that a stream can run on, so GRBL is not reset by reopening the port
// between them (an Arduino-based GRBL restarts when its port opens, and forgets it was homed).
class SerialLink {
 public:
  SerialLink(const std::string& name, const MachineProfile& profile) {
    py::gil_scoped_release release;
    port_ = std::make_unique<SerialPort>(name, profile.serial);
  }
  SerialPort& port() {
    if (!port_) throw InputError("the serial link is closed");
    return *port_;
  }
  bool is_open() const { return static_cast<bool>(port_); }
  std::string name() { return port().name(); }
  bool write(const std::string& bytes, double timeout) {
    SerialPort& p = port();
    py::gil_scoped_release release;
    return p.write(bytes, static_cast<int>(std::clamp(timeout, 0.0, 600.0) * 1000.0));
  }
  // What arrived within `timeout` s (b"" for nothing), or None when the link is lost.
  py::object read(double timeout) {
    SerialPort& p = port();
    char buffer[1024];
    int n;
    {
      py::gil_scoped_release release;
      n = p.read(buffer, sizeof buffer, static_cast<int>(std::clamp(timeout, 0.0, 600.0) * 1000.0));
    }
    if (n < 0) return py::none();
    return py::bytes(buffer, static_cast<std::size_t>(n));
  }
  void close() {
    py::gil_scoped_release release;
    port_.reset();
  }

 private:
  std::unique_ptr<SerialPort> port_;
};

py::dict stream_program_py(const py::object& port, const std::vector<std::string>& lines, const py::object& profile,
                           std::optional<py::dict> state_arg, const py::object& progress, StreamControl* control,
                           bool dry_run, double response_timeout, double settle) {
  const MachineProfile m = to_profile(profile);
  // A fresh dict per call when none is given: a shared default would carry one program's
  // progress into the next and skip its first lines.
  py::dict state = state_arg ? *state_arg : py::dict();
  StreamState s;
  if (state.contains("next_line")) s.next_line = to_integer<std::size_t>(state["next_line"], "state['next_line']");
  // Without "confirmed" the lines before next_line are taken as done (a state set by hand).
  s.confirmed = state.contains("confirmed") ? to_integer<std::size_t>(state["confirmed"], "state['confirmed']")
                                            : s.next_line;
  StreamOptions o;
  o.dry_run = dry_run;
  o.response_timeout = response_timeout;
  o.settle = settle;
  o.control = control;
  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  StreamResult r;
  try {
    if (py::isinstance<SerialLink>(port)) {  // an open link: no settle, GRBL is not restarted
      SerialLink& link = port.cast<SerialLink&>();
      if (dry_run) r = reporter.run([&] { return stream_program(std::string(), lines, m, s, o, fn); });
      else r = reporter.run([&] { return stream_program(link.port(), lines, m, s, o, fn); });
    } else {
      const std::string name = port.cast<std::string>();
      r = reporter.run([&] { return stream_program(name, lines, m, s, o, fn); });
    }
  } catch (...) {
    state["next_line"] = s.next_line;  // resume from here
    state["confirmed"] = s.confirmed;
    throw;
  }
  state["next_line"] = s.next_line;
  state["confirmed"] = s.confirmed;
  return py::dict(py::arg("status") = std::string(to_string(r.status)), py::arg("sent") = r.sent,
                  py::arg("acknowledged") = r.acknowledged, py::arg("last_acknowledged") = r.last_acknowledged,
                  py::arg("failed_line") = r.failed_line, py::arg("code") = r.code, py::arg("message") = r.message,
                  py::arg("next_line") = s.next_line, py::arg("confirmed") = s.confirmed);
}

}  // namespace

void bind_fab(py::module_& m) {
  py::class_<StreamControl>(m, "StreamControl",
                            "Pause / resume / abort switches for a running stream_program (thread-safe).")
      .def(py::init<>())
      .def("pause", [](StreamControl& c) { c.pause = true; })
      .def("resume", [](StreamControl& c) { c.pause = false; })
      .def("abort", [](StreamControl& c) { c.abort = true; })
      .def_property_readonly("paused", [](const StreamControl& c) { return c.pause.load(); })
      .def_property_readonly("aborted", [](const StreamControl& c) { return c.abort.load(); });

  py::class_<SerialLink>(m, "SerialLink",
                         "An open serial port kept between commands (status, jog, console) and streams.")
      .def(py::init([](const std::string& name, const py::object& profile) {
             return new SerialLink(name, to_profile(profile));
           }),
           py::arg("port"), py::arg("profile") = py::dict(),
           "Opens the port with the profile's serial settings (and its lock file); ValueError naming it.")
      .def_property_readonly("name", &SerialLink::name)
      .def_property_readonly("is_open", &SerialLink::is_open)
      .def("write", &SerialLink::write, py::arg("data"), py::arg("timeout") = 2.0,
           "Writes all bytes within timeout s; False when the link is lost or the time passed.")
      .def("read", &SerialLink::read, py::arg("timeout") = 0.0,
           "Bytes that arrived within timeout s (b'' for none), or None when the link is lost.")
      .def("close", &SerialLink::close, "Closes the port and releases its lock file.");

  m.def("default_machine_profile", [] { return from_profile(MachineProfile{}); },
        "The default (DIWire-class) machine profile as a dict of edge units (m, deg, mm/s, deg/s).");
  m.def("validate_machine_profile", [](const py::object& profile) { return from_profile(to_profile(profile)); },
        py::arg("profile"),
        "The profile dict checked (every key optional, the defaults filled in), or ValueError naming the key "
        "at fault: an unknown key, a wrong type or a value out of range.");
  m.def("make_bend_program", &make_bend_program_py, py::arg("points"), py::arg("profile") = py::dict(),
        py::arg("machine") = py::none(),
        R"(Feeds and bends that make a 2D wire.

points: (n, 2) metres, open, starting at the cut. profile: dict (see default_machine_profile()).
machine: the profile whose spring-back line models the real machine for the preview (None: profile).
Also returns "predicted" (k, 2) m, the wire the machine makes (predict_polyline), and
"preview_distance" (m), its largest distance by arc length from points.
Returns {"steps": [{"feed_mm", "bend_deg", "commanded_deg", "vertex"}], "feeds_mm", "bends_deg",
"commanded_deg", "wire_length" (m), "bend_count", "machine_seconds", "shape_error" (m),
"merged_points", "small_turns", "rounded_bends", "dropped_turn_deg", "start", "start_heading_deg",
"bend_vertices", "rebuilt" (k, 2) m}. Raises ValueError naming the bend, step or point.)");
  m.def("bend_program_problems", &bend_program_problems_py, py::arg("points"), py::arg("profile") = py::dict(),
        R"(What keeps a 2D wire from being bent (the problems make_bend_program refuses, all of them).

points, profile: as make_bend_program. Returns [{"kind": "over_bend" | "short_feed" | "command",
"number" (the bend, or the step of a short feed, from 1), "from", "to" (input points: the bend, or
the feed's first and last), "at" (m from the cut to "from"), "value", "limit" (degrees for bends,
metres for feeds), "message"}], empty when the wire can be made. Raises ValueError for bad input.)");
  m.def("write_svg", &write_svg, py::arg("path"), py::arg("wires"), py::arg("sheet") = py::none(),
        py::arg("options") = py::dict(),
        R"(1:1 SVG template (mm). wires: [{"name", "points" (n, 2) m, "bend_points", "crossing_points",
"self_crossings" (k, 2) m, optional}].
sheet: None = a sheet when more than one wire. Writes atomically when path is not None; returns the text.)");
  m.def("write_dxf", &write_dxf, py::arg("path"), py::arg("wires"), py::arg("labels") = false,
        py::arg("layout") = "as_given", py::arg("gap_mm") = 20.0,
        R"(DXF R2000, $INSUNITS mm, one layer and one LWPOLYLINE per wire. layout: "as_given", "start_at_origin"
(each wire's first point at 0,0) or "side_by_side" (bounding boxes gap_mm apart on the x axis).
Writes atomically when path is not None; returns the text.)");
  m.def("write_machine_svg", &write_machine_svg, py::arg("path"), py::arg("wire"), py::arg("stroke_mm") = 0.5,
        R"(The machine SVG of one wire {"name", "points" (n, 2) m}: exactly one path, mm, origin at the first
point. Writes atomically when path is not None; returns the text.)");
  m.def("write_gcode", &write_gcode, py::arg("path"), py::arg("points"), py::arg("profile") = py::dict(),
        py::arg("wire_name") = "", py::arg("material") = "", py::arg("sync_each_step") = true,
        "GRBL G-code for the wire. Writes atomically when path is not None; returns the text.");
  m.def("write_bend_table", &write_bend_table, py::arg("path"), py::arg("points"), py::arg("profile") = py::dict(),
        "CSV step,feed_mm,bend_deg,commanded_deg. Writes atomically when path is not None; returns the text.");
  m.def("write_file_atomic", [](const std::string& path, const std::string& text) {
    py::gil_scoped_release release;
    write_file_atomic(path, text);
  }, py::arg("path"), py::arg("text"), "Temporary file in the same folder, then rename.");
  m.def("stream_lines", [](const std::string& gcode) { return stream_lines(gcode); }, py::arg("gcode"),
        "The lines to stream: comments and blank lines removed.");
  m.def("list_ports", [] {
    std::vector<PortInfo> ports;
    {
      py::gil_scoped_release release;
      ports = list_ports();
    }
    py::list out;
    for (const PortInfo& p : ports) out.append(py::dict(py::arg("name") = p.name, py::arg("description") = p.description));
    return out;
  }, "Serial ports: [{'name', 'description'}].");
  m.def("stream_program", &stream_program_py, py::arg("port"), py::arg("lines"), py::arg("profile") = py::dict(),
        py::arg("state") = py::none(), py::arg("progress") = py::none(), py::arg("control") = nullptr,
        py::arg("dry_run") = false, py::arg("response_timeout") = 30.0, py::arg("settle") = 2.0,
        R"(Stream G-code lines to a GRBL bender (send one line, wait for ok / error:N; ALARM stops).

port: a port's name (opened, settled, closed) or an open SerialLink (streamed on as it is).

state: dict whose "next_line" (0-based: where a call starts) and "confirmed" (the line after the last
step known complete: after the last acknowledged G4/M2) are read and updated in place. GRBL answers
ok when it queues a line; after a stop that can lose queued moves (disconnected, timeout, aborted,
alarm) inside a step, the message names the step and next_line goes back to its first line, so
calling again makes the whole step again; after error or protocol_error it is the first
unacknowledged line. No line is skipped.
progress(stage, fraction) -> False aborts. control: a StreamControl to pause/resume/abort from
another thread. Returns {"status": completed|dry_run|error|alarm|disconnected|timeout|aborted|protocol_error,
"sent", "acknowledged", "last_acknowledged", "failed_line", "code", "message", "next_line", "confirmed"}.)");
}

}  // namespace wiresculpt::python
