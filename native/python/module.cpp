// The _wiresculpt module: error translation and the list of bound concerns. Nothing here
// computes; every function converts arguments, calls the core and converts the result.
#include <pybind11/pybind11.h>

#include <string>

#include "bindings.hpp"
#include "wiresculpt/error.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_wiresculpt, m) {
  m.doc() = "wiresculpt native solver (Miguel et al. 2016, planar-rod structures)";
  m.attr("__version__") = WIRESCULPT_VERSION;

  static py::exception<wiresculpt::Cancelled> cancelled(m, "Cancelled", PyExc_RuntimeError);
  // Every core error reaches Python as an exception with the core's sentence; nothing escapes
  // as std::terminate. Bad input -> ValueError, solver failure -> RuntimeError.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const wiresculpt::Cancelled& e) {
      cancelled(e.what());
    } catch (const wiresculpt::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const py::cast_error& e) {  // a fallback: convert.hpp's readers name the key themselves
      PyErr_SetString(PyExc_ValueError, (std::string("a value has the wrong type: ") + e.what()).c_str());
    } catch (const wiresculpt::Error& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "out of memory in the wiresculpt solver");
    }
  });

  wiresculpt::python::bind_geometry(m);
  wiresculpt::python::bind_slicing(m);
  wiresculpt::python::bind_fab(m);
  wiresculpt::python::bind_layering(m);
  wiresculpt::python::bind_target_shape(m);
  wiresculpt::python::bind_forces(m);
  wiresculpt::python::bind_calibration(m);
  wiresculpt::python::bind_structure3d(m);
}
