#pragma once
// Analytic test and benchmark meshes, generated in code so their exact answers are known:
// spheres, tori and boxes as indexed triangle meshes (V #V by 3, F #F by 3), outward-facing.
#include "wiresculpt/mesh.hpp"

namespace wiresculpt {

struct RawMesh {
  MatrixX3d V;
  MatrixX3i F;
};

/// A UV sphere of radius `radius` about the origin: `segments` around the z axis, `rings`
/// from pole to pole (rings >= 2, segments >= 3). Vertices lie exactly on the sphere.
RawMesh uv_sphere(double radius, int segments, int rings);

/// A torus about the z axis: ring radius `major`, tube radius `minor`, `nu` steps around the
/// axis and `nv` around the tube (both >= 3).
RawMesh torus(double major, double minor, int nu, int nv);

/// The axis-aligned box [-hx, hx] x [-hy, hy] x [-hz, hz], two triangles per face, each face
/// split along the diagonal through its (-,-) and (+,+) corners.
RawMesh box(double hx, double hy, double hz);

}  // namespace wiresculpt
