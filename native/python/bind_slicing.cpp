#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "wiresculpt/slicing.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

struct PlaneSpec {
  std::string name;
  Vec3 origin, normal;
};

/// planes: [(name, origin, normal)]. A bad origin or normal is named with its plane's name:
/// "planes[0] (plane 'Z') origin: ...".
std::vector<PlaneSpec> to_planes(py::handle planes) {
  std::vector<PlaneSpec> out;
  each_item(planes, "planes", [&](py::handle item, const std::string& where) {
    PlaneSpec p;
    std::size_t k = 0;
    each_item(item, where, [&](py::handle v, const std::string& at) {
      const std::string named = where + " (plane '" + p.name + "')";
      if (k == 0) p.name = to_text(v, at);
      else if (k == 1) p.origin = to_vector<3>(v, named + " origin");
      else if (k == 2) p.normal = to_vector<3>(v, named + " normal");
      ++k;
    });
    if (k != 3) wrong(where, "(name, origin, normal)", std::to_string(k) + " items");
    out.push_back(std::move(p));
  });
  return out;
}

py::dict slice_mesh(const MatrixX3d& V, const MatrixX3i& F, const py::object& plane_list, double weld_tolerance) {
  const std::vector<PlaneSpec> planes = to_planes(plane_list);
  TriMesh mesh;
  std::vector<std::vector<Contour>> results;
  {
    py::gil_scoped_release release;
    std::vector<Plane> made;
    for (const PlaneSpec& p : planes) made.push_back(Plane::make(p.origin, p.normal, "plane " + p.name));
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
