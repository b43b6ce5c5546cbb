// Calibration: cantilever (k_b, plastic limit), tilt (friction), spring-back. Grams and degrees
// are the edge units of the captures; they become SI right here (fab/machine.hpp's helpers for
// degrees) before anything reaches the core.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/calibration.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

using namespace wiresculpt::fab;
constexpr double kGramsPerKilogram = 1000.0;

std::vector<int> lines_or_default(const std::optional<std::vector<int>>& lines, std::size_t n) {
  if (!lines) return {};
  if (lines->size() != n)
    throw InputError("lines: expected one line number per row (" + std::to_string(n) + "), got " +
                     std::to_string(lines->size()));
  return *lines;
}

py::dict fit_cantilever_py(const std::vector<double>& load_g, const std::vector<bool>& loaded,
                           const std::vector<double>& s, const std::vector<double>& deflection,
                           const std::optional<std::vector<int>>& lines, double overhang, double linear_density,
                           double plastic_tolerance, double gravity, int nodes, int smoothing_degree,
                           bool noise_correction) {
  const std::size_t n = load_g.size();
  if (loaded.size() != n || s.size() != n || deflection.size() != n)
    throw InputError("cantilever: load_g, loaded, s and deflection must have the same length");
  const std::vector<int> line = lines_or_default(lines, n);
  std::vector<CantileverRecord> rows(n);
  for (std::size_t i = 0; i < n; ++i)
    rows[i] = {load_g[i] / kGramsPerKilogram, loaded[i], s[i], deflection[i], line.empty() ? 0 : line[i]};
  CantileverOptions o;
  o.overhang = overhang;
  o.linear_density = linear_density;
  o.plastic_tolerance = plastic_tolerance;
  o.gravity = gravity;
  o.nodes = nodes;
  o.smoothing_degree = smoothing_degree;
  o.noise_correction = noise_correction;
  CantileverFit fit;
  {
    py::gil_scoped_release release;
    fit = fit_cantilever(rows, o);
  }
  py::list frames;
  for (const CantileverFrame& f : fit.frames)
    frames.append(py::dict(py::arg("load_g") = f.load * kGramsPerKilogram, py::arg("loaded") = f.loaded,
                           py::arg("line") = f.line, py::arg("used") = f.used, py::arg("s") = f.s,
                           py::arg("deflection") = f.deflection, py::arg("x") = f.x, py::arg("simulated") = f.simulated,
                           py::arg("position_rms") = f.position_rms, py::arg("return_error") = f.return_error,
                           py::arg("clamp_torque") = f.clamp_torque));
  return py::dict(py::arg("bending_stiffness") = fit.bending_stiffness, py::arg("max_torque") = fit.max_torque,
                  py::arg("plastic_load_g") = fit.plastic_load * kGramsPerKilogram,
                  py::arg("plastic_found") = fit.plastic_found, py::arg("plastic_reached") = fit.plastic_reached,
                  py::arg("lever_arm") = fit.lever_arm, py::arg("torque_rms") = fit.torque_rms,
                  py::arg("mark_noise") = fit.mark_noise, py::arg("noise_share") = fit.noise_share,
                  py::arg("position_rms") = fit.position_rms, py::arg("position_max") = fit.position_max,
                  py::arg("frames_used") = fit.frames_used, py::arg("frames") = frames);
}

py::array_t<double> simulate_cantilever_py(double kb, double length, double tip_load_g, double linear_density,
                                           double gravity, int segments) {
  Polyline2 rod;
  {
    py::gil_scoped_release release;
    rod = simulate_cantilever(kb, length, tip_load_g / kGramsPerKilogram * gravity, linear_density * gravity, segments);
  }
  return to_array(rod);
}

py::dict fit_friction_py(const std::vector<double>& angles_deg, const std::optional<std::vector<int>>& lines) {
  std::vector<double> a;
  for (double d : angles_deg) a.push_back(from_deg(d));
  const FrictionFit f = fit_friction(a, lines_or_default(lines, a.size()));
  return py::dict(py::arg("friction") = f.friction, py::arg("spread") = f.spread, py::arg("min") = f.min,
                  py::arg("max") = f.max, py::arg("mean_angle_deg") = to_deg(f.mean_angle),
                  py::arg("repeats") = f.repeats);
}

py::dict fit_springback_py(const std::vector<double>& commanded_deg, const std::vector<double>& measured_deg,
                           const std::optional<std::vector<int>>& lines) {
  std::vector<double> c, m;
  for (double d : commanded_deg) c.push_back(from_deg(d));
  for (double d : measured_deg) m.push_back(from_deg(d));
  const SpringbackFit f = fit_springback(c, m, lines_or_default(lines, c.size()));
  return py::dict(py::arg("springback_a") = f.a, py::arg("springback_b_deg") = to_deg(f.b),
                  py::arg("rms_deg") = to_deg(f.rms), py::arg("max_residual_deg") = to_deg(f.max_residual),
                  py::arg("samples") = f.samples);
}

}  // namespace

void bind_calibration(py::module_& m) {
  m.def("fit_cantilever", &fit_cantilever_py, py::arg("load_g"), py::arg("loaded"), py::arg("s"),
        py::arg("deflection"), py::arg("lines") = py::none(), py::arg("overhang") = 0.30,
        py::arg("linear_density") = 0.0, py::arg("plastic_tolerance") = 0.001, py::arg("gravity") = 9.81,
        py::arg("nodes") = 31, py::arg("smoothing_degree") = 6, py::arg("noise_correction") = false,
        R"(Bending stiffness (Eq. 13) and plastic limit from a cantilever capture (Sec. 5.2).

One entry per CSV row: load_g (grams at the tip), loaded (False: after unloading), s (m from the
clamp), deflection (m, down); lines: source line numbers for messages. overhang m, linear_density
kg/m (0: the wire's weight ignored), plastic_tolerance m. Returns {"bending_stiffness" (N m^2),
"max_torque" (N m), "plastic_load_g", "plastic_found", "plastic_reached", "lever_arm" (m),
"torque_rms" (N m), "mark_noise" (m), "noise_share", "position_rms", "position_max" (m), "frames_used", "frames": [{"load_g",
"loaded", "line", "used", "s", "deflection", "x", "simulated", "position_rms", "return_error",
"clamp_torque"}]}. Raises ValueError naming the line.)");
  m.def("simulate_cantilever", &simulate_cantilever_py, py::arg("bending_stiffness"), py::arg("length") = 0.30,
        py::arg("tip_load_g") = 0.0, py::arg("linear_density") = 0.0, py::arg("gravity") = 9.81,
        py::arg("segments") = 150,
        "The rod model (Eq. 9) clamped horizontally at the origin under a tip load: (segments+1, 2) m, y up.");
  m.def("fit_friction", &fit_friction_py, py::arg("angles_deg"), py::arg("lines") = py::none(),
        "mu = tan(alpha) over the tilt repeats: {'friction', 'spread', 'min', 'max', 'mean_angle_deg', 'repeats'}.");
  m.def("fit_springback", &fit_springback_py, py::arg("commanded_deg"), py::arg("measured_deg"),
        py::arg("lines") = py::none(),
        "measured = a * commanded + b (|angles|): {'springback_a', 'springback_b_deg', 'rms_deg', "
        "'max_residual_deg', 'samples'} (keys as the machine profile dict).");
}

}  // namespace wiresculpt::python
