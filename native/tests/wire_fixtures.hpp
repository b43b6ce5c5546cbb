#pragma once
// Wire networks whose geometry is known exactly: circles cut from one sphere by planes, built as
// polylines directly (no mesh), with the exact points where two circles meet inserted as
// vertices, so the crossings are known by hand.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "wiresculpt/geometry.hpp"
#include "wiresculpt/contact.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/network.hpp"
#include "wiresculpt/rest_shape.hpp"

namespace fixtures {

using wiresculpt::Plane;
using wiresculpt::Polyline3;
using wiresculpt::Vec3;
using wiresculpt::WireSpec;
using wiresculpt::Network;
using wiresculpt::ContactOptions;
using wiresculpt::HookGeometry;
using wiresculpt::hook_geometry;

/// A cut of the sphere of radius R about the origin by the plane {x : n·x = h} (n unit).
struct Cut {
  std::string name;
  Vec3 normal;
  double offset;
};

/// Where two cuts' circles meet: the points of the planes' common line on the sphere (0 or 2).
inline std::vector<Vec3> circle_meets(const Cut& a, const Cut& b, double R) {
  const Vec3 cr = a.normal.cross(b.normal);
  if (cr.norm() < 1e-12) return {};
  const Vec3 d = cr.normalized();
  Eigen::Matrix3d A;
  A.row(0) = a.normal.transpose();
  A.row(1) = b.normal.transpose();
  A.row(2) = d.transpose();
  const Vec3 p0 = A.fullPivLu().solve(Vec3(a.offset, b.offset, 0.0));  // closest point to the origin
  const double rest = R * R - p0.squaredNorm();
  if (rest <= 0) return {};
  const double t = std::sqrt(rest);
  return {p0 - t * d, p0 + t * d};
}

/// The circle of `cut` on the sphere as a closed polyline of n uniform angles (starting at
/// `phase`), plus the given extra points (which must lie on the circle) inserted in angle order.
/// A wire named `name` through `points` in the plane z = 0 (normal +z), open unless `closed`.
inline WireSpec flat_wire(const std::string& name, const Polyline3& points, bool closed = false) {
  WireSpec w;
  w.name = name;
  w.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
  w.points = points;
  w.closed = closed;
  return w;
}

inline WireSpec circle_wire(const Cut& cut, double R, int n, const std::vector<Vec3>& extra = {},
                            double phase = 0.0) {
  const Plane plane = Plane::make(cut.offset * cut.normal, cut.normal);
  const double rho = std::sqrt(R * R - cut.offset * cut.offset);
  const Vec3 centre = cut.offset * cut.normal;
  struct Item {
    double phi;
    Vec3 p;
    bool extra;
  };
  std::vector<Item> pts;
  const double two_pi = 2.0 * std::numbers::pi;
  for (int k = 0; k < n; ++k) {
    const double phi = phase + two_pi * k / n;
    pts.push_back({std::fmod(phi, two_pi), centre + rho * (std::cos(phi) * plane.u + std::sin(phi) * plane.v), false});
  }
  for (const Vec3& p : extra) {
    double phi = std::atan2((p - centre).dot(plane.v), (p - centre).dot(plane.u));
    if (phi < 0) phi += two_pi;
    pts.push_back({phi, p, true});
  }
  std::sort(pts.begin(), pts.end(), [](const Item& x, const Item& y) { return x.phi < y.phi; });
  // Grid points within 20 µm of a meeting point are dropped (and repeated meeting points kept once).
  std::vector<char> keep(pts.size(), 1);
  const std::size_t m = pts.size();
  for (std::size_t k = 0; k < m; ++k) {
    if (!pts[k].extra) continue;
    for (std::size_t q = 0; q < m; ++q)
      if (q != k && keep[q] && (pts[q].p - pts[k].p).norm() < 2e-5 && (!pts[q].extra || q > k)) keep[q] = 0;
  }
  WireSpec w;
  w.name = cut.name;
  w.plane = plane;
  w.closed = true;
  for (std::size_t k = 0; k < m; ++k)
    if (keep[k]) w.points.push_back(pts[k].p);
  return w;
}

/// Circles of every cut on one sphere, each with all its meeting points inserted exactly.
inline std::vector<WireSpec> sphere_wires(const std::vector<Cut>& cuts, double R, int n = 64) {
  std::vector<WireSpec> out;
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    std::vector<Vec3> extra;
    for (std::size_t j = 0; j < cuts.size(); ++j)
      if (j != i)
        for (const Vec3& p : circle_meets(cuts[i], cuts[j], R)) extra.push_back(p);
    out.push_back(circle_wire(cuts[i], R, n, extra));
  }
  return out;
}

/// Three orthogonal great circles: planes x = 0 ("X"), y = 0 ("Y"), z = 0 ("Z").
inline std::vector<Cut> great_circle_cuts() {
  return {{"X", Vec3::UnitX(), 0.0}, {"Y", Vec3::UnitY(), 0.0}, {"Z", Vec3::UnitZ(), 0.0}};
}

/// A random hooked network for solver tests: 3 + attempt % 3 random cuts of the sphere of radius
/// 0.125 m (n points per circle), random hooks, the first two wires assembled first. false when
/// the cuts give no usable network (degenerate, or fewer than 4 crossings).
struct HookedNetwork {
  wiresculpt::Network net;
  std::vector<int> hooks;
  std::vector<std::vector<int>> steps;
};
/// `count` random cuts named A, B, ...: normals uniform in a cube (near-zero ones replaced by z),
/// offsets uniform in [-max_offset, max_offset].
template <class Rng>
std::vector<Cut> random_cuts(Rng& rng, int count, double max_offset) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Cut> cuts;
  for (int k = 0; k < count; ++k) {
    Vec3 nrm(unit(rng), unit(rng), unit(rng));
    if (nrm.norm() < 0.2) nrm = Vec3::UnitZ();
    cuts.push_back({std::string(1, static_cast<char>('A' + k)), nrm.normalized(), max_offset * unit(rng)});
  }
  return cuts;
}

template <class Rng>
bool random_hooked_sphere(Rng& rng, int attempt, int n, HookedNetwork& out) {
  const double R = 0.125;
  const int P = 3 + attempt % 3;
  const std::vector<Cut> cuts = random_cuts(rng, P, 0.5 * R);
  try {
    out.net = wiresculpt::build_network(sphere_wires(cuts, R, n));
  } catch (const wiresculpt::InputError&) {
    return false;
  }
  const int C = static_cast<int>(out.net.crossings.size());
  if (C < 4) return false;
  out.hooks.clear();
  for (int c = 0; c < C; ++c) out.hooks.push_back(rng() % 2 ? 1 : -1);
  out.steps = {{0, 1}};
  for (int w = 2; w < P; ++w) out.steps.push_back({w});
  return true;
}

/// The largest 3D torque |Σ_{k after v} (x_v - x_k) × f_k| over the vertices of closed wire `w`
/// walked from `cut` (the loads after v: those later in the walk), summed directly; with
/// `weight` (N/m, a vector along gravity) every edge after v also carries its weight at its
/// midpoint.
inline double max_torque_3d(const WireSpec& w, int cut, const std::vector<wiresculpt::WireLoad>& loads,
                            const Vec3& weight = Vec3::Zero()) {
  const int n = static_cast<int>(w.points.size());
  double largest = 0.0;
  for (int pv = 0; pv < n; ++pv) {
    const Vec3& xv = w.points[(cut + pv) % n];
    Vec3 t = Vec3::Zero();
    for (const wiresculpt::WireLoad& l : loads)
      if ((l.vertex - cut + n) % n > pv) t += (xv - w.points[l.vertex]).cross(l.force);
    for (int e = pv; e < n; ++e) {  // edge from walk position e to e + 1 (the last one closes)
      const Vec3& p = w.points[(cut + e) % n];
      const Vec3& q = w.points[(cut + e + 1) % n];
      t += (xv - 0.5 * (p + q)).cross((q - p).norm() * weight);
    }
    largest = std::max(largest, t.norm());
  }
  return largest;
}

/// `net` with each hooked crossing's two neighbours on both wires moved to the kink of Fig. 6
/// (hook_geometry), the target shape the force stage expects. Needs wiresculpt/contact.hpp.
inline Network idealise_hooks(const Network& net, const std::vector<int>& hooks, const ContactOptions& co = {}) {
  Network out = net;
  for (std::size_t c = 0; c < net.crossings.size(); ++c) {
    if (hooks[c] == 0) continue;
    const HookGeometry g = hook_geometry(net, static_cast<int>(c), hooks[c], co);
    for (int k = 0; k < 2; ++k) {
      WireSpec& w = out.wires[net.crossings[c].wires[k]];
      const int n = static_cast<int>(w.points.size());
      const int v = net.crossings[c].vertices[k];
      w.points[(v + n - 1) % n] = g.neighbours[k][0];
      w.points[(v + 1) % n] = g.neighbours[k][1];
    }
  }
  return out;
}

}  // namespace fixtures
