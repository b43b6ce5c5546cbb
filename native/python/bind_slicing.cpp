#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <tuple>
#include <vector>

#include "bindings.hpp"
#include "wiresculpt/slicing.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

using PlaneSpec = std::tuple<std::string, Vec3, Vec3>;  // name, origin, normal

py::array_t<double> to_array(const Polyline3& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto w = out.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < w.shape(0); ++i)
    for (py::ssize_t k = 0; k < 3; ++k) w(i, k) = points[static_cast<std::size_t>(i)][k];
  return out;
}

py::dict slice_mesh(const MatrixX3d& V, const MatrixX3i& F, const std::vector<PlaneSpec>& planes,
                    double weld_tolerance) {
  TriMesh mesh;
  std::vector<std::vector<Contour>> results;
  {
    py::gil_scoped_release release;
    std::vector<Plane> made;
    for (const auto& [name, origin, normal] : planes) made.push_back(Plane::make(origin, normal, "plane " + name));
    mesh = prepare_mesh(V, F, MeshOptions{weld_tolerance});
    for (const Plane& p : made) results.push_back(slice(mesh, p));
  }
  py::list per_plane;
  for (const auto& contours : results) {
    py::list items;
    for (const Contour& c : contours)
      items.append(py::dict(py::arg("points") = to_array(c.points), py::arg("closed") = c.closed,
                            py::arg("length") = c.length));
    per_plane.append(items);
  }
  py::dict mesh_info(py::arg("vertices") = mesh.V.rows(), py::arg("triangles") = mesh.F.rows(),
                     py::arg("weld_tolerance") = mesh.weld_tolerance,
                     py::arg("welded_vertices") = mesh.welded_vertices,
                     py::arg("dropped_degenerate") = mesh.dropped_degenerate,
                     py::arg("dropped_duplicate") = mesh.dropped_duplicate);
  return py::dict(py::arg("contours") = per_plane, py::arg("mesh") = mesh_info);
}

}  // namespace

void bind_slicing(py::module_& m) {
  m.def("slice_mesh", &slice_mesh, py::arg("vertices"), py::arg("faces"), py::arg("planes"),
        py::arg("weld_tolerance") = -1.0,
        R"(Slice a triangle mesh by planes.

vertices: float64 (#V, 3) in metres; faces: int32 (#F, 3); planes: list of (name, origin, normal).
Returns {"contours": [per plane: [{"points": (n, 3), "closed": bool, "length": m}, ...]],
"mesh": cleaning statistics}. Contours are sorted longest first. Raises ValueError naming the
vertex, triangle or plane at fault.)");
}

}  // namespace wiresculpt::python
