// Plane frames (geometry.hpp): the one definition of a plane's 2D axes, for the add-on's
// core/frames.py. Converts, calls Plane::make, converts back.
#include <pybind11/numpy.h>

#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "wiresculpt/geometry.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

py::tuple plane_frame(const py::object& normal) {
  const Plane p = Plane::make(Vec3::Zero(), to_vector<3>(normal, "normal"), "normal");
  const auto array = [](const Vec3& v) {
    py::array_t<double> out(3);
    auto w = out.mutable_unchecked<1>();
    for (py::ssize_t k = 0; k < 3; ++k) w(k) = v[static_cast<Eigen::Index>(k)];
    return out;
  };
  return py::make_tuple(array(p.normal), array(p.u), array(p.v));
}

}  // namespace

void bind_geometry(py::module_& m) {
  m.def("plane_frame", &plane_frame, py::arg("normal"),
        R"(The 2D frame of a plane with this normal, as the solver uses it (Plane::make).

normal: 3 numbers, any non-zero length. Returns (n, u, v), float64 arrays of shape (3,): the unit
normal, u the world axis least aligned with n projected into the plane, v = n x u (so u x v = n).
A zero or non-finite normal raises ValueError.)");
}

}  // namespace wiresculpt::python
