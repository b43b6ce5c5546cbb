#include "wiresculpt/network.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "figures.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

std::string fmt_point(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.4f, %.4f, %.4f)", p.x(), p.y(), p.z());
  return buf;
}

std::string quoted(const std::string& name) { return "'" + name + "'"; }

// Validates one wire, projects it onto its plane and merges duplicate points.
WireSpec clean_wire(const WireSpec& in, double tolerance) {
  const std::string who = "wire " + quoted(in.name);
  if (!in.plane.origin.allFinite() || !in.plane.normal.allFinite() ||
      std::abs(in.plane.normal.norm() - 1.0) > 1e-9)
    throw InputError(who + ": its plane needs a finite origin and a unit normal (use Plane::make)");
  WireSpec out;
  out.name = in.name;
  out.plane = in.plane;
  out.closed = in.closed;
  for (std::size_t k = 0; k < in.points.size(); ++k) {
    const Vec3& p = in.points[k];
    if (!p.allFinite()) throw InputError(who + ": point " + std::to_string(k) + " has a non-finite coordinate");
    const double off = in.plane.signed_distance(p);
    if (std::abs(off) > tolerance) {
      const auto [shown, limit] = detail::versus(std::abs(off), tolerance, 4, 'g');
      throw InputError(who + ": point " + std::to_string(k) + " is " + shown + " m off the wire's plane (more than the "
                       "tolerance " + limit + " m)");
    }
    const Vec3 q = p - off * in.plane.normal;
    if (!out.points.empty() && (q - out.points.back()).norm() <= 1e-12) continue;
    out.points.push_back(q);
  }
  if (out.closed && out.points.size() > 1 && (out.points.front() - out.points.back()).norm() <= 1e-12)
    out.points.pop_back();
  const std::size_t need = out.closed ? 3 : 2;
  if (out.points.size() < need)
    throw InputError(who + ": needs at least " + std::to_string(need) + " distinct points (" +
                     (out.closed ? "closed" : "open") + " wire), has " + std::to_string(out.points.size()));
  return out;
}

// Where a wire meets another plane. kind: 0 crossing (passes through), 1 tangency (touches and
// stays on one side), 2 an open wire's end on the plane.
struct Event {
  double t = 0.0;   // parameter along the planes' common line
  int kind = 0;
  int vertex = -1;  // the event is this existing vertex ...
  int edge = -1;    // ... or lies inside this edge at fraction `frac`
  double frac = 0.0;
  Vec3 p = Vec3::Zero();
};

std::vector<Event> plane_events(const WireSpec& w, const Plane& other, const Vec3& p0, const Vec3& d,
                                double tolerance, const std::string& other_name) {
  const int n = static_cast<int>(w.points.size());
  std::vector<double> sd(n);
  std::vector<int> s(n);
  for (int k = 0; k < n; ++k) {
    sd[k] = other.signed_distance(w.points[k]);
    s[k] = sd[k] > tolerance ? 1 : (sd[k] < -tolerance ? -1 : 0);
  }
  int start = -1;
  for (int k = 0; k < n; ++k)
    if (s[k] != 0) {
      start = k;
      break;
    }
  if (start < 0)
    throw InputError("wire " + quoted(w.name) + " lies entirely on the plane of wire " + quoted(other_name) +
                     ": all its points are on the line where the two planes meet");
  std::vector<Event> events;
  auto vertex_event = [&](const std::vector<int>& run, int kind) {
    Event e;
    e.kind = kind;
    e.vertex = run[run.size() / 2];
    e.p = w.points[e.vertex];
    if (kind == 0) {
      // A real crossing through vertices within the tolerance of the plane: where the wire
      // actually meets the plane is the exact zero of the signed distance between the vertices
      // before and after the run. At a shallow angle that point lies far along the line from the
      // run's vertices (a 10 um offset at a slope of 1:100 is 1 mm), and the other wire's event
      // is there, so the event goes there too: at a vertex when one is that close, else on an edge.
      const int before = (run.front() - 1 + n) % n, after = (run.back() + 1) % n;
      for (int u = before; u != after; u = (u + 1) % n) {
        const int v = (u + 1) % n;
        if (sd[u] == 0.0) {
          e.vertex = u;
          e.p = w.points[u];
          break;
        }
        if ((sd[u] < 0.0) != (sd[v] < 0.0) && sd[v] != 0.0) {
          const double f = sd[u] / (sd[u] - sd[v]);
          const Vec3 q = w.points[u] + f * (w.points[v] - w.points[u]);
          e.p = q;
          if ((q - w.points[u]).norm() <= tolerance) {
            e.vertex = u;
          } else if ((q - w.points[v]).norm() <= tolerance) {
            e.vertex = v;
          } else {
            e.vertex = -1;
            e.edge = u;
            e.frac = f;
          }
          break;
        }
      }
    }
    e.t = d.dot(e.p - p0);
    events.push_back(e);
  };
  auto edge_event = [&](int a, int b) {
    Event e;
    e.kind = 0;
    e.edge = a;
    e.frac = sd[a] / (sd[a] - sd[b]);
    e.p = w.points[a] + e.frac * (w.points[b] - w.points[a]);
    e.t = d.dot(e.p - p0);
    events.push_back(e);
  };
  std::vector<int> run;
  if (w.closed) {
    int sp = s[start];
    int prev = start;
    for (int m = 1; m <= n; ++m) {
      const int k = (start + m) % n;
      if (s[k] == 0) {
        run.push_back(k);
      } else {
        if (!run.empty()) {
          vertex_event(run, s[k] != sp ? 0 : 1);
          run.clear();
        } else if (s[k] == -sp) {
          edge_event(prev, k);
        }
        sp = s[k];
      }
      prev = k;
    }
  } else {
    int sp = 0;
    for (int k = 0; k < n; ++k) {
      if (s[k] == 0) {
        run.push_back(k);
      } else {
        if (!run.empty()) {
          vertex_event(run, sp == 0 ? 2 : (s[k] != sp ? 0 : 1));
          run.clear();
        } else if (sp != 0 && s[k] == -sp) {
          edge_event(k - 1, k);
        }
        sp = s[k];
      }
    }
    if (!run.empty()) vertex_event(run, 2);
  }
  return events;
}

double seg_point_dist(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

double seg_seg_dist(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& e) {
  const double d1 = cross2(b - a, c - a), d2 = cross2(b - a, e - a);
  const double d3 = cross2(e - c, a - c), d4 = cross2(e - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return 0.0;
  return std::min({seg_point_dist(a, b, c), seg_point_dist(a, b, e), seg_point_dist(c, e, a),
                   seg_point_dist(c, e, b)});
}

// Throws when two wires of one plane come within `tolerance` of each other.
void check_same_plane(const WireSpec& wa, const WireSpec& wb, double tolerance) {
  const Plane& pl = wa.plane;
  auto flat = [&](const WireSpec& w) {
    Polyline2 out;
    for (const auto& p : w.points) out.push_back(pl.to_2d(p));
    return out;
  };
  const Polyline2 a = flat(wa), b = flat(wb);
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  const int ea = wa.closed ? na : na - 1, eb = wb.closed ? nb : nb - 1;
  for (int i = 0; i < ea; ++i) {
    const Vec2& a0 = a[i];
    const Vec2& a1 = a[(i + 1) % na];
    const Vec2 lo = a0.cwiseMin(a1).array() - tolerance, hi = a0.cwiseMax(a1).array() + tolerance;
    for (int j = 0; j < eb; ++j) {
      const Vec2& b0 = b[j];
      const Vec2& b1 = b[(j + 1) % nb];
      if (std::max(b0.x(), b1.x()) < lo.x() || std::min(b0.x(), b1.x()) > hi.x() ||
          std::max(b0.y(), b1.y()) < lo.y() || std::min(b0.y(), b1.y()) > hi.y())
        continue;
      if (seg_seg_dist(a0, a1, b0, b1) <= tolerance)
        throw InputError("wires " + quoted(wa.name) + " and " + quoted(wb.name) +
                         " lie in the same plane and touch near " + fmt_point(wa.points[i]) +
                         "; wires of one plane cannot cross or hook: merge them into one wire or move one");
    }
  }
}

// A crossing before insertion: where it sits on each wire.
struct RawCrossing {
  std::array<int, 2> wires;
  std::array<Event, 2> at;
  double t = 0.0;
  Vec3 point;
};

// The crossings of wires i and j (RawCrossing, into raw), matched one to one along the line
// their planes share; where the two only touch, a warning in net.
void meet(Network& net, int i, int j, double tol, std::vector<RawCrossing>& raw) {
  const WireSpec& wi = net.wires[i];
  const WireSpec& wj = net.wires[j];
  const Vec3 cr = wi.plane.normal.cross(wj.plane.normal);
  if (cr.norm() < 1e-9) {
    if (std::abs(wi.plane.signed_distance(wj.plane.origin)) <= tol) check_same_plane(wi, wj, tol);
    return;  // parallel planes: no crossings
  }
  const Vec3 d = cr.normalized();
  Eigen::Matrix3d A;
  A.row(0) = wi.plane.normal.transpose();
  A.row(1) = wj.plane.normal.transpose();
  A.row(2) = d.transpose();
  const Vec3 rhs(wi.plane.normal.dot(wi.plane.origin), wj.plane.normal.dot(wj.plane.origin), 0.0);
  const Vec3 p0 = A.fullPivLu().solve(rhs);
  const auto ei = plane_events(wi, wj.plane, p0, d, tol, wj.name);
  const auto ej = plane_events(wj, wi.plane, p0, d, tol, wi.name);
  // Greedy one-to-one matching of events closest along the line.
  std::vector<std::tuple<double, int, int>> cand;
  for (int a = 0; a < static_cast<int>(ei.size()); ++a)
    for (int b = 0; b < static_cast<int>(ej.size()); ++b) {
      const double gap = std::abs(ei[a].t - ej[b].t);
      if (gap <= tol) cand.emplace_back(gap, a, b);
    }
  std::sort(cand.begin(), cand.end());
  std::vector<char> used_a(ei.size(), 0), used_b(ej.size(), 0);
  for (const auto& [gap, a, b] : cand) {
    if (used_a[a] || used_b[b]) continue;
    used_a[a] = used_b[b] = 1;
    const Event& x = ei[a];
    const Event& y = ej[b];
    if (x.kind == 0 && y.kind == 0) {
      RawCrossing rc;
      rc.wires = {i, j};
      rc.at = {x, y};
      rc.t = 0.5 * (x.t + y.t);
      rc.point = p0 + rc.t * d;
      raw.push_back(rc);
    } else {
      auto how = [](const Event& e) {
        return e.kind == 1 ? std::string("touches") : (e.kind == 2 ? std::string("ends on") : std::string("crosses"));
      };
      net.warnings.push_back("wires " + quoted(wi.name) + " and " + quoted(wj.name) + " meet at " +
                             fmt_point(x.p) + " without crossing (" + quoted(wi.name) + " " + how(x) +
                             " the plane of " + quoted(wj.name) + ", " + quoted(wj.name) + " " + how(y) +
                             " the plane of " + quoted(wi.name) + "); no crossing is made there");
    }
  }
}

// Three wires through one point: refused, naming them.
void refuse_three_at_a_point(const Network& net, const std::vector<RawCrossing>& raw, double tol) {
  for (std::size_t a = 0; a < raw.size(); ++a)
    for (std::size_t b = a + 1; b < raw.size(); ++b) {
      // Within two tolerances: both could sit on one wire vertex.
      if ((raw[a].point - raw[b].point).norm() > 2 * tol) continue;
      std::set<int> ws{raw[a].wires[0], raw[a].wires[1], raw[b].wires[0], raw[b].wires[1]};
      std::vector<std::string> names;
      for (int w : ws) names.push_back(quoted(net.wires[w].name));
      std::string list;
      for (std::size_t k = 0; k < names.size(); ++k)
        list += (k == 0 ? "" : (k + 1 == names.size() ? " and " : ", ")) + names[k];
      throw InputError("wires " + list + " all pass through one point " + fmt_point(raw[a].point) +
                       "; at most two wires may meet at a point: move one of the planes slightly");
    }
}

// The crossings of wire w (net.crossings, in the order of raw) as vertices of its polyline, and
// each crossing's vertex on it.
void insert_crossings(Network& net, int w, const std::vector<RawCrossing>& raw, double tol) {
  const int C = static_cast<int>(raw.size());
  WireSpec& wire = net.wires[w];
  const int n = static_cast<int>(wire.points.size());
  std::map<int, int> at_vertex;                              // old vertex -> crossing
  std::map<int, std::vector<std::pair<double, int>>> on_edge;  // edge -> (frac, crossing)
  std::vector<std::pair<int, Event>> here;
  for (int c = 0; c < C; ++c)
    for (int k = 0; k < 2; ++k)
      if (raw[c].wires[k] == w) here.push_back({c, raw[c].at[k]});
  for (const auto& [c, e] : here)
    if (e.vertex >= 0) at_vertex[e.vertex] = c;
  for (const auto& [c, e] : here) {
    if (e.vertex >= 0) continue;
    const int a = e.edge, b = (e.edge + 1) % n;
    const double len = (wire.points[b] - wire.points[a]).norm();
    const Vec3& p = net.crossings[c].point;
    auto interior = [&](int v) { return wire.closed || (v != 0 && v != n - 1); };
    if ((p - wire.points[a]).norm() <= tol && interior(a) && !at_vertex.count(a)) {
      at_vertex[a] = c;
    } else if ((p - wire.points[b]).norm() <= tol && interior(b) && !at_vertex.count(b)) {
      at_vertex[b] = c;
    } else {
      on_edge[a].push_back({e.frac * len, c});
    }
  }
  Polyline3 rebuilt;
  for (int k = 0; k < n; ++k) {
    auto it = at_vertex.find(k);
    if (it != at_vertex.end()) {
      const int c = it->second;
      const int side = net.crossings[c].wires[0] == w ? 0 : 1;
      net.crossings[c].vertices[side] = static_cast<int>(rebuilt.size());
      rebuilt.push_back(net.crossings[c].point);
    } else {
      rebuilt.push_back(wire.points[k]);
    }
    auto eit = on_edge.find(k);
    if (eit == on_edge.end()) continue;
    auto list = eit->second;
    std::sort(list.begin(), list.end());
    for (const auto& [s, c] : list) {
      const int side = net.crossings[c].wires[0] == w ? 0 : 1;
      net.crossings[c].vertices[side] = static_cast<int>(rebuilt.size());
      rebuilt.push_back(net.crossings[c].point);
    }
  }
  wire.points = std::move(rebuilt);
}

// Size of the model and crossings too close along a wire.
void size_and_close_crossings(Network& net, const NetworkOptions& options) {
  const int P = static_cast<int>(net.wires.size());
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& w : net.wires)
    for (const auto& p : w.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  net.size = P > 0 ? (hi - lo).maxCoeff() : 0.0;
  net.min_segment = options.min_segment;
  for (int w = 0; w < P; ++w) {
    const WireSpec& wire = net.wires[w];
    for (const Network::Gap& gap : net.gaps_of(w)) {
      const int ca = gap.a, cb = gap.b;
      const double dist = gap.arc;
      if (dist >= options.min_segment) continue;
      CrossingGap g;
      g.wire = w;
      g.crossings = {ca, cb};
      g.distance = dist;
      g.scale = detail::gap_scale(dist, options.min_segment);
      const auto [apart, least] = detail::versus(dist, options.min_segment, 4, 'g');
      g.message = "wire " + quoted(wire.name) + ": crossings " + std::to_string(ca) + " and " + std::to_string(cb) +
                  " are " + apart + " m apart along the wire, less than the machine's minimum segment " + least +
                  " m; a free bending point between them needs twice that: " + detail::scale_words(g.scale, net.size);
      net.min_scale = std::max(net.min_scale, g.scale);
      net.close_crossings.push_back(g);
    }
  }
}

}  // namespace

std::vector<Network::Gap> Network::gaps_of(int w) const {
  const WireSpec& wire = wires.at(static_cast<std::size_t>(w));
  const int n = static_cast<int>(wire.points.size());
  std::vector<double> arc(n, 0.0);
  for (int k = 1; k < n; ++k) arc[k] = arc[k - 1] + (wire.points[k] - wire.points[k - 1]).norm();
  const double total = polyline_length(wire.points, wire.closed);
  const auto list = crossings_of(w);
  const int m = static_cast<int>(list.size());
  const int pairs = wire.closed ? (m >= 2 ? m : 0) : std::max(0, m - 1);
  auto vertex = [&](int c) { return crossings[c].vertices[crossings[c].wires[0] == w ? 0 : 1]; };
  std::vector<Gap> out;
  for (int q = 0; q < pairs; ++q) {
    const int ca = list[q], cb = list[(q + 1) % m];
    const int va = vertex(ca), vb = vertex(cb);
    out.push_back({ca, cb, va, vb, vb > va ? arc[vb] - arc[va] : total - arc[va] + arc[vb]});
  }
  return out;
}

std::vector<int> Network::crossings_of(int wire) const {
  std::vector<std::pair<int, int>> list;
  for (int c = 0; c < static_cast<int>(crossings.size()); ++c)
    for (int k = 0; k < 2; ++k)
      if (crossings[c].wires[k] == wire) list.push_back({crossings[c].vertices[k], c});
  std::sort(list.begin(), list.end());
  std::vector<int> out;
  for (const auto& [v, c] : list) out.push_back(c);
  return out;
}

Network build_network(const std::vector<WireSpec>& input, const NetworkOptions& options, const ProgressFn& progress) {
  if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
    throw InputError("network tolerance must be a positive number of metres");
  if (!(options.min_segment >= 0) || !std::isfinite(options.min_segment))
    throw InputError("min_segment must be a non-negative number of metres");
  const double tol = options.tolerance;
  Network net;
  const int P = static_cast<int>(input.size());
  // Progress: one step per wire cleaned, per pair of wires met, per wire the crossings go into.
  const double work = 2.0 * P + 0.5 * P * (P - 1.0) + 1.0;
  double done = 0.0;
  auto step = [&] { report_progress(progress, "network", done++ / work); };
  for (const auto& w : input) {
    step();
    net.wires.push_back(clean_wire(w, tol));
  }

  std::vector<RawCrossing> raw;
  for (int i = 0; i < P; ++i)
    for (int j = i + 1; j < P; ++j) {
      step();
      meet(net, i, j, tol, raw);
    }

  refuse_three_at_a_point(net, raw, tol);

  // Crossing order: by wire pair, then along the planes' common line.
  std::sort(raw.begin(), raw.end(), [](const RawCrossing& x, const RawCrossing& y) {
    if (x.wires != y.wires) return x.wires < y.wires;
    return x.t < y.t;
  });
  const int C = static_cast<int>(raw.size());
  net.crossings.resize(C);
  for (int c = 0; c < C; ++c) {
    net.crossings[c].wires = raw[c].wires;
    net.crossings[c].point = raw[c].point;
  }

  // Insert the crossings as vertices of both wires.
  for (int w = 0; w < P; ++w) {
    step();
    insert_crossings(net, w, raw, tol);
  }

  size_and_close_crossings(net, options);
  net.required_size = net.size * net.min_scale;
  report_progress(progress, "network", 1.0);
  return net;
}

}  // namespace wiresculpt
