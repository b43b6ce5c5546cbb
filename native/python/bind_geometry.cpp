// Plane frames (geometry.hpp): the one definition of a plane's 2D axes, for the add-on's
// core/frames.py; the model's size. Converts, calls the core, converts back.
#include <pybind11/numpy.h>

#include <string>
#include <vector>

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

double largest_box_side(const py::object& polylines) {
  std::vector<Polyline3> all;
  each_item(polylines, "polylines",
            [&](py::handle item, const std::string& where) { all.push_back(to_points<3>(item, where)); });
  return wiresculpt::largest_box_side(all);
}

}  // namespace

void bind_geometry(py::module_& m) {
  m.def("largest_box_side", &largest_box_side, py::arg("polylines"),
        R"(The largest side of the bounding box of all points of `polylines` (a list of (n, 3) arrays,
metres): the model's size as core/design.py model_size measures it, in one call. 0.0 without
points, NaN when a coordinate is NaN.)");
  m.def("plane_frame", &plane_frame, py::arg("normal"),
        R"(The 2D frame of a plane with this normal, as the solver uses it (Plane::make).

normal: 3 numbers, any non-zero length. Returns (n, u, v), float64 arrays of shape (3,): the unit
normal, u the world axis least aligned with n projected into the plane, v = n x u (so u x v = n).
A zero or non-finite normal raises ValueError.)");
}

}  // namespace wiresculpt::python
