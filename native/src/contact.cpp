#include "wiresculpt/contact.hpp"

#include <cmath>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

void check_crossing(const Network& net, int c) {
  if (c < 0 || c >= static_cast<int>(net.crossings.size()))
    throw InputError("crossing " + std::to_string(c) + " does not exist (the network has " +
                     std::to_string(net.crossings.size()) + " crossings)");
}

void check_hook(int hook, int c) {
  if (hook < -1 || hook > 1)
    throw InputError("crossing " + std::to_string(c) + ": hook must be -1, 0 or 1, not " + std::to_string(hook));
}

// Adjacent vertex indices of `v` on `w` (-1 past an open end).
std::array<int, 2> adjacent(const WireSpec& w, int v) {
  const int n = static_cast<int>(w.points.size());
  int prev = v - 1, next = v + 1;
  if (w.closed) {
    prev = (v + n - 1) % n;
    next = (v + 1) % n;
  } else {
    if (prev < 0) prev = -1;
    if (next >= n) next = -1;
  }
  return {prev, next};
}

}  // namespace

void validate(const ContactOptions& o) {
  if (!std::isfinite(o.friction) || o.friction < 0)
    throw InputError("friction must be a finite number >= 0, not " + std::to_string(o.friction));
  if (!std::isfinite(o.contact_angle) || !(o.contact_angle > 0) || o.contact_angle > std::numbers::pi + 1e-12)
    throw InputError("contact_angle must be in (0, pi] radians, not " + std::to_string(o.contact_angle));
  if (!std::isfinite(o.bisector_span) || o.bisector_span < 0)
    throw InputError("bisector_span must be a finite number of metres >= 0");
  if (!std::isfinite(o.straight_angle) || o.straight_angle < 0)
    throw InputError("straight_angle must be a finite number of radians >= 0");
}

Vec3 crossing_direction(const Network& net, int c) {
  check_crossing(net, c);
  const Crossing& x = net.crossings[c];
  return net.wires[x.wires[0]].plane.normal.cross(net.wires[x.wires[1]].plane.normal).normalized();
}

std::optional<Vec3> input_bisector(const Network& net, int wire, int vertex, const ContactOptions& options) {
  if (wire < 0 || wire >= static_cast<int>(net.wires.size()))
    throw InputError("wire " + std::to_string(wire) + " does not exist");
  const WireSpec& w = net.wires[wire];
  const int n = static_cast<int>(w.points.size());
  if (vertex < 0 || vertex >= n)
    throw InputError("wire '" + w.name + "': vertex " + std::to_string(vertex) + " does not exist");
  std::vector<char> is_crossing(n, 0);
  for (const auto& c : net.crossings)
    for (int k = 0; k < 2; ++k)
      if (c.wires[k] == wire) is_crossing[c.vertices[k]] = 1;
  const Vec3& x = w.points[vertex];
  // Walk one way until the chord is at least bisector_span long, a crossing or an open end.
  auto reach = [&](int step) -> int {
    int v = vertex;
    for (int guard = 0; guard < n; ++guard) {
      const int nv = w.closed ? (v + step + n) % n : v + step;
      if (nv < 0 || nv >= n || nv == vertex) break;
      v = nv;
      if (is_crossing[v] || (w.points[v] - x).norm() >= options.bisector_span) break;
    }
    return v == vertex ? -1 : v;
  };
  const int prev = reach(-1), next = reach(+1);
  if (prev < 0 || next < 0) return std::nullopt;  // an open end: no kink to speak of
  const Vec3 e_prev = (x - w.points[prev]).normalized();  // ê_{r-1}
  const Vec3 e_next = (w.points[next] - x).normalized();  // ê_r
  const double turn = std::atan2(e_prev.cross(e_next).norm(), e_prev.dot(e_next));
  if (turn < options.straight_angle) return std::nullopt;
  return Vec3((e_next - e_prev).normalized());
}

std::array<Vec3, 4> contact_pyramid(const Network& net, int c, int hook, const ContactOptions& options) {
  check_crossing(net, c);
  if (hook != 1 && hook != -1)
    throw InputError("crossing " + std::to_string(c) + ": only hooks -1 and 1 have a contact pyramid");
  const Crossing& x = net.crossings[c];
  const Vec3 d = crossing_direction(net, c);
  const Vec3 t0 = net.wires[x.wires[0]].plane.normal.cross(d).normalized();
  const Vec3 t1 = net.wires[x.wires[1]].plane.normal.cross(d).normalized();
  const double beta = 0.5 * options.contact_angle - std::atan(options.friction);
  const double s = static_cast<double>(hook);
  const Vec3 axial = -s * std::sin(beta) * d;
  const double side = std::cos(beta);
  return {axial + side * t0, axial - side * t0, axial + side * t1, axial - side * t1};
}

HookGeometry hook_geometry(const Network& net, int c, int hook, const ContactOptions& options) {
  check_crossing(net, c);
  check_hook(hook, c);
  const Crossing& x = net.crossings[c];
  const Vec3 d = crossing_direction(net, c);
  HookGeometry g;
  g.hook = hook;
  const double half = 0.5 * options.contact_angle;
  for (int k = 0; k < 2; ++k) {
    const WireSpec& w = net.wires[x.wires[k]];
    const int v = x.vertices[k];
    const auto [prev, next] = adjacent(w, v);
    const Vec3& p = w.points[v];
    const Vec3 u_prev = prev >= 0 ? Vec3((w.points[prev] - p).normalized()) : Vec3::Zero();
    const Vec3 u_next = next >= 0 ? Vec3((w.points[next] - p).normalized()) : Vec3::Zero();
    const double l_prev = prev >= 0 ? (w.points[prev] - p).norm() : 0.0;
    const double l_next = next >= 0 ? (w.points[next] - p).norm() : 0.0;
    if (hook == 0) {
      g.bisector[k] = Vec3::Zero();
      g.edge_dirs[k] = {u_prev, u_next};
      g.neighbours[k] = {prev >= 0 ? w.points[prev] : p, next >= 0 ? w.points[next] : p};
      continue;
    }
    const double s = (k == 0 ? 1.0 : -1.0) * static_cast<double>(hook);
    const Vec3 h = s * d;
    const Vec3 t = w.plane.normal.cross(h).normalized();
    const double side = u_prev.dot(t) >= 0 ? 1.0 : -1.0;  // the previous edge keeps its side
    const Vec3 arm_prev = std::cos(half) * h + side * std::sin(half) * t;
    const Vec3 arm_next = std::cos(half) * h - side * std::sin(half) * t;
    g.bisector[k] = h;
    g.edge_dirs[k] = {arm_prev, arm_next};
    g.neighbours[k] = {p + l_prev * arm_prev, p + l_next * arm_next};
  }
  g.metric = hook_metric(net, c, hook, options);
  return g;
}

double hook_metric(const Network& net, int c, int hook, const ContactOptions& options) {
  check_crossing(net, c);
  check_hook(hook, c);
  if (hook == 0) return 0.0;
  const Crossing& x = net.crossings[c];
  const Vec3 d = crossing_direction(net, c);
  double e = 0.0;
  for (int k = 0; k < 2; ++k) {
    const Vec3 h = (k == 0 ? 1.0 : -1.0) * static_cast<double>(hook) * d;
    const auto hbar = input_bisector(net, x.wires[k], x.vertices[k], options);
    e += hbar ? 1.0 - h.dot(*hbar) : 1.0;
  }
  return e;
}

}  // namespace wiresculpt
