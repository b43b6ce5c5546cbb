#include "wiresculpt/shapes.hpp"

#include <cmath>
#include <numbers>
#include <utility>

#include "wiresculpt/error.hpp"
#include "wiresculpt/geometry.hpp"

namespace wiresculpt {

RawMesh uv_sphere(double radius, int segments, int rings) {
  if (segments < 3 || rings < 2) throw InputError("uv_sphere needs segments >= 3 and rings >= 2");
  const double pi = std::numbers::pi;
  RawMesh m;
  const int inner = rings - 1;  // latitude circles between the poles
  m.V.resize(2 + inner * segments, 3);
  m.V.row(0) << 0, 0, radius;
  for (int r = 1; r <= inner; ++r) {
    const double theta = pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * pi * s / segments;
      m.V.row(1 + (r - 1) * segments + s) << radius * std::sin(theta) * std::cos(phi),
          radius * std::sin(theta) * std::sin(phi), radius * std::cos(theta);
    }
  }
  const int south = 1 + inner * segments;
  m.V.row(south) << 0, 0, -radius;
  auto at = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  m.F.resize(2 * segments + 2 * segments * (inner - 1), 3);
  int f = 0;
  for (int s = 0; s < segments; ++s) m.F.row(f++) << 0, at(1, s), at(1, s + 1);
  for (int r = 1; r < inner; ++r)
    for (int s = 0; s < segments; ++s) {
      m.F.row(f++) << at(r, s), at(r + 1, s), at(r + 1, s + 1);
      m.F.row(f++) << at(r, s), at(r + 1, s + 1), at(r, s + 1);
    }
  for (int s = 0; s < segments; ++s) m.F.row(f++) << south, at(inner, s + 1), at(inner, s);
  return m;
}

RawMesh torus(double major, double minor, int nu, int nv) {
  if (nu < 3 || nv < 3) throw InputError("torus needs nu >= 3 and nv >= 3");
  const double pi = std::numbers::pi;
  RawMesh m;
  m.V.resize(nu * nv, 3);
  m.F.resize(2 * nu * nv, 3);
  auto at = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * pi * i / nu, v = 2 * pi * j / nv;
      const double rho = major + minor * std::cos(v);
      m.V.row(at(i, j)) << rho * std::cos(u), rho * std::sin(u), minor * std::sin(v);
    }
  int f = 0;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.F.row(f++) << at(i, j), at(i + 1, j), at(i + 1, j + 1);
      m.F.row(f++) << at(i, j), at(i + 1, j + 1), at(i, j + 1);
    }
  return m;
}

RawMesh box(double hx, double hy, double hz) {
  RawMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(i) << ((i & 1) ? hx : -hx), ((i & 2) ? hy : -hy), ((i & 4) ? hz : -hz);
  // Each face as a quad (a, b, c, d) with a the (-,-) corner and c the (+,+) corner of the
  // face's own axes, split along a-c; triangles are turned outward below.
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3},   // x = -hx, x = +hx
                           {0, 4, 5, 1}, {2, 3, 7, 6},   // y = -hy, y = +hy
                           {0, 1, 3, 2}, {4, 6, 7, 5}};  // z = -hz, z = +hz
  m.F.resize(12, 3);
  for (int k = 0; k < 6; ++k) {
    const auto& q = faces[k];
    m.F.row(2 * k) << q[0], q[1], q[2];
    m.F.row(2 * k + 1) << q[0], q[2], q[3];
  }
  for (int t = 0; t < 12; ++t) {  // the box is convex about the origin: outward = away from it
    const Eigen::Vector3d a = m.V.row(m.F(t, 0)), b = m.V.row(m.F(t, 1)), c = m.V.row(m.F(t, 2));
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(m.F(t, 1), m.F(t, 2));
  }
  return m;
}

}  // namespace wiresculpt
