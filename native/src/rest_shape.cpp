#include "wiresculpt/rest_shape.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

std::string quoted(const std::string& name) { return "wire '" + name + "'"; }

}  // namespace

std::vector<int> wire_walk(int n, bool closed, int cut, const std::string& wire_name) {
  std::vector<int> walk;
  if (closed) {
    if (cut < 0 || cut >= n)
      throw InputError(quoted(wire_name) + ": cut " + std::to_string(cut) + " is outside its " + std::to_string(n) +
                       " target points");
    for (int k = 0; k <= n; ++k) walk.push_back((cut + k) % n);
  } else {
    if (cut != -1)
      throw InputError(quoted(wire_name) + " is open: its cut must be -1, not " + std::to_string(cut));
    for (int k = 0; k < n; ++k) walk.push_back(k);
  }
  return walk;
}

int automatic_cut(const WireSpec& wire, const std::vector<int>& crossing_vertices) {
  if (!wire.closed) return -1;
  const int n = static_cast<int>(wire.points.size());
  std::vector<int> xs = crossing_vertices;
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  for (int v : xs)
    if (v < 0 || v >= n)
      throw InputError(quoted(wire.name) + ": crossing vertex " + std::to_string(v) + " is outside its " +
                       std::to_string(n) + " target points");
  if (xs.empty()) return 0;
  const auto edge = [&](int i) { return (wire.points[(i + 1) % n] - wire.points[i]).norm(); };
  int best = -1;
  double best_length = -1.0;
  for (std::size_t s = 0; s < xs.size(); ++s) {
    const int a = xs[s];
    const int b = s + 1 < xs.size() ? xs[s + 1] : xs[0] + n;  // one crossing: all the way round
    if (b - a < 2) continue;                                   // a single edge: nowhere to cut
    double total = 0.0;
    for (int i = a; i < b; ++i) total += edge(i % n);
    if (total <= best_length) continue;
    // The interior vertex closest to half the arc length.
    double run = 0.0, closest = 1e300;
    int pick = -1;
    for (int i = a + 1; i < b; ++i) {
      run += edge((i - 1) % n);
      const double off = std::abs(run - 0.5 * total);
      if (off < closest - 1e-12 * total) {
        closest = off;
        pick = i % n;
      }
    }
    best_length = total;
    best = pick;
  }
  if (best < 0)
    throw InputError(quoted(wire.name) + ": every piece between two crossings is a single edge, so there is no "
                     "vertex to cut the wire at; give the target shape more points");
  return best;
}

std::vector<int> choose_cuts(const Network& net, const std::vector<int>& requested) {
  const std::size_t P = net.wires.size();
  if (!requested.empty() && requested.size() != P)
    throw InputError("cuts: expected one cut per wire (" + std::to_string(P) + "), got " +
                     std::to_string(requested.size()));
  std::vector<std::vector<int>> on_wire(P);
  for (const Crossing& c : net.crossings)
    for (int k = 0; k < 2; ++k) on_wire[c.wires[k]].push_back(c.vertices[k]);
  std::vector<int> cuts(P, -1);
  for (std::size_t w = 0; w < P; ++w) {
    const WireSpec& wire = net.wires[w];
    const int want = requested.empty() ? -1 : requested[w];
    const int n = static_cast<int>(wire.points.size());
    if (!wire.closed) {
      if (want != -1)
        throw InputError(quoted(wire.name) + " is open and is not cut: its cut must be -1, not " +
                         std::to_string(want));
      continue;
    }
    if (want == -1) {
      cuts[w] = automatic_cut(wire, on_wire[w]);
      continue;
    }
    if (want < 0 || want >= n)
      throw InputError(quoted(wire.name) + ": cut " + std::to_string(want) + " is outside its target points 0.." +
                       std::to_string(n - 1));
    if (std::find(on_wire[w].begin(), on_wire[w].end(), want) != on_wire[w].end())
      throw InputError(quoted(wire.name) + ": cut " + std::to_string(want) +
                       " is a crossing; cut the wire between two crossings");
    cuts[w] = want;
  }
  return cuts;
}

std::vector<double> turning_angles(const Polyline2& p) {
  const std::size_t m = p.size();
  std::vector<double> a(m, 0.0);
  for (std::size_t k = 1; k + 1 < m; ++k) {
    const Vec2 e0 = p[k] - p[k - 1], e1 = p[k + 1] - p[k];
    a[k] = std::atan2(cross2(e0, e1), e0.dot(e1));
  }
  return a;
}

Polyline2 polyline_from_angles(const Vec2& start, double heading, const std::vector<double>& lengths,
                               const std::vector<double>& angles) {
  Polyline2 out{start};
  double theta = heading;
  for (std::size_t k = 0; k < lengths.size(); ++k) {
    if (k > 0) theta += angles[k];
    out.push_back(out.back() + lengths[k] * Vec2(std::cos(theta), std::sin(theta)));
  }
  return out;
}

double elastic_torque(double alpha, double rest_alpha, double l_bar, double kb) {
  const double t = std::tan(0.5 * alpha);
  return -(4.0 / l_bar) * kb * (t - std::tan(0.5 * rest_alpha)) * (1.0 + t * t);
}

RestShapeResult rest_shape(const WireSpec& wire, int cut, const std::vector<WireLoad>& loads,
                           const RestShapeOptions& options) {
  const int n = static_cast<int>(wire.points.size());
  if (n < (wire.closed ? 3 : 2))
    throw InputError(quoted(wire.name) + ": too few target points for a rest shape");
  if (!(options.bending_stiffness > 0) || !std::isfinite(options.bending_stiffness))
    throw InputError("bending_stiffness must be a finite number of N m^2 > 0");
  if (!(options.max_bend > 0) || !std::isfinite(options.max_bend))
    throw InputError("max_bend must be a finite angle > 0 radians");
  RestShapeResult r;
  r.walk = wire_walk(n, wire.closed, cut, wire.name);
  const int m = static_cast<int>(r.walk.size());
  std::vector<int> position(n, -1);  // first walk position of each target index
  for (int k = m - 1; k >= 0; --k) position[r.walk[k]] = k;
  // Loads by walk position (a load at the cut acts at position 0: the start of the walk).
  std::vector<Vec3> force(m, Vec3::Zero());
  for (const WireLoad& l : loads) {
    if (l.vertex < 0 || l.vertex >= n || !l.force.allFinite())
      throw InputError(quoted(wire.name) + ": a contact load is at vertex " + std::to_string(l.vertex) +
                       " (outside 0.." + std::to_string(n - 1) + ") or not finite");
    force[position[l.vertex]] += l.force;
  }
  Polyline2 p;
  for (int idx : r.walk) p.push_back(wire.plane.to_2d(wire.points[idx]));
  std::vector<double> lengths(m - 1);
  for (int k = 0; k + 1 < m; ++k) {
    lengths[k] = (wire.points[r.walk[k + 1]] - wire.points[r.walk[k]]).norm();
    if (!(lengths[k] > 0))
      throw InputError(quoted(wire.name) + ": target points " + std::to_string(r.walk[k]) + " and " +
                       std::to_string(r.walk[k + 1]) + " coincide");
  }
  r.target_angles = turning_angles(p);
  // Eq. 11 for every position: suffix sums of forces and of x_k × f_k give t_v in O(m).
  r.torque.assign(m, 0.0);
  r.out_of_plane_torque.assign(m, 0.0);
  Vec3 sum_f = Vec3::Zero(), sum_xf = Vec3::Zero();
  const Vec3& nrm = wire.plane.normal;
  for (int k = m - 1; k >= 0; --k) {
    const Vec3& x = wire.points[r.walk[k]];
    // torque at position k: Σ_{j > k} (x_k - x_j) × f_j = x_k × Σf - Σ x_j × f_j
    const Vec3 t = x.cross(sum_f) - sum_xf;
    r.torque[k] = t.dot(nrm);
    r.out_of_plane_torque[k] = (t - t.dot(nrm) * nrm).norm();
    sum_f += force[k];
    sum_xf += x.cross(force[k]);
  }
  r.rest_angles = r.target_angles;
  for (int k = 1; k + 1 < m; ++k) {
    const double l_bar = voronoi_length(lengths[k - 1], lengths[k]);
    const double th = std::tan(0.5 * r.target_angles[k]);
    const double K = 4.0 * options.bending_stiffness / l_bar;
    r.rest_angles[k] = 2.0 * std::atan(th + r.torque[k] / (K * (1.0 + th * th)));
    if (std::abs(r.rest_angles[k]) > options.max_bend + options.over_bend_tolerance) {
      r.over_bend.push_back(r.walk[k]);
      r.over_bend_angle.push_back(r.rest_angles[k]);
    }
  }
  for (int k = 0; k < m; ++k)
    if (std::abs(r.torque[k]) > r.max_torque) {
      r.max_torque = std::abs(r.torque[k]);
      r.max_torque_vertex = r.walk[k];
    }
  const Vec2 e0 = p[1] - p[0];
  r.rest = polyline_from_angles(p[0], std::atan2(e0.y(), e0.x()), lengths, r.rest_angles);
  if (wire.closed) r.closure_gap = (r.rest.back() - r.rest.front()).norm();
  return r;
}

}  // namespace wiresculpt
