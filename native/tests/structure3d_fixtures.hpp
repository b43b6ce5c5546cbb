#pragma once
// Inputs of the 3D rods (structure3d.hpp) that several suites build: options without weight and a
// straight rod.
#include <string>

#include "wiresculpt/geometry.hpp"
#include "wiresculpt/structure3d.hpp"

namespace fixtures {

/// The default options with no weight (linear density 0): only the tests' own loads act.
inline wiresculpt::Structure3dOptions weightless() {
  wiresculpt::Structure3dOptions o;
  o.linear_density = 0.0;
  return o;
}

/// A straight rod of `n` nodes from `from` by `step` each, in a plane of normal z, at rest as it starts.
inline wiresculpt::Structure3dWire straight(const std::string& name, const wiresculpt::Vec3& from,
                                            const wiresculpt::Vec3& step, int n) {
  wiresculpt::Structure3dWire w;
  w.name = name, w.normal = wiresculpt::Vec3::UnitZ();
  for (int k = 0; k < n; ++k) w.start.push_back(from + k * step);
  w.rest = w.start;
  return w;
}

}  // namespace fixtures
