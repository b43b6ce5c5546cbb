// libFuzzer target: arbitrary meshes and planes through prepare_mesh and slice. Any input must
// either slice or throw wiresculpt::Error; a crash, a sanitizer report or a hang is a bug.
#include <fuzzer/FuzzedDataProvider.h>

#include "wiresculpt/error.hpp"
#include "wiresculpt/slicing.hpp"

using namespace wiresculpt;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  const int nv = in.ConsumeIntegralInRange<int>(0, 40);
  const int nf = in.ConsumeIntegralInRange<int>(0, 60);
  // Coordinates mostly small integers (exact coincidences: vertices on the plane, duplicates,
  // degenerate triangles), sometimes raw doubles (NaN, Inf, huge).
  auto coordinate = [&] {
    return in.ConsumeBool() ? static_cast<double>(in.ConsumeIntegralInRange<int>(-3, 3))
                            : in.ConsumeFloatingPoint<double>();
  };
  MatrixX3d V(nv, 3);
  for (int i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) V(i, k) = coordinate();
  MatrixX3i F(nf, 3);
  for (int t = 0; t < nf; ++t)
    for (int k = 0; k < 3; ++k) F(t, k) = in.ConsumeIntegralInRange<int>(-1, nv);
  Vec3 origin, normal;
  for (int k = 0; k < 3; ++k) origin[k] = coordinate();
  for (int k = 0; k < 3; ++k) normal[k] = coordinate();
  try {
    const TriMesh mesh = prepare_mesh(V, F, MeshOptions{in.ConsumeBool() ? -1.0 : in.ConsumeFloatingPoint<double>()});
    const auto contours = slice(mesh, Plane::make(origin, normal));
    for (const auto& c : contours)
      if (c.points.size() < 2 || !(c.length >= 0)) __builtin_trap();  // a malformed contour
  } catch (const Error&) {
  }
  return 0;
}
