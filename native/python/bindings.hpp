#pragma once
// Shared declarations of the thin pybind11 layer: each bind_*.cpp adds one concern's functions.
#include <pybind11/pybind11.h>

namespace wiresculpt::python {

void bind_geometry(pybind11::module_& m);
void bind_slicing(pybind11::module_& m);
void bind_fab(pybind11::module_& m);
void bind_layering(pybind11::module_& m);
void bind_target_shape(pybind11::module_& m);
void bind_forces(pybind11::module_& m);
void bind_calibration(pybind11::module_& m);
void bind_structure3d(pybind11::module_& m);

}  // namespace wiresculpt::python
