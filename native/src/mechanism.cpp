#include "wiresculpt/mechanism.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include "wire_names.hpp"

namespace wiresculpt {
namespace {

using detail::crossing_list;
using detail::quoted;

std::string names(const Network& net, const std::vector<int>& wires) {
  return (wires.size() == 1 ? "wire " : "wires ") + detail::wire_list(net, wires);
}

Eigen::Matrix3d skew(const Vec3& r) {
  Eigen::Matrix3d m;
  m << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  return m;
}

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// Even-odd rule.
bool inside(const Polyline2& poly, const Vec2& q) {
  bool in = false;
  const std::size_t n = poly.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > q.y()) != (b.y() > q.y()) && q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

std::string direction_text(const Vec3& d) {
  static const char* axis[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    if (std::abs(d[k]) > 1.0 - 1e-6) return std::string(d[k] > 0 ? "+" : "-") + axis[k];
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.3f, %.3f, %.3f)", d.x(), d.y(), d.z());
  return buf;
}

std::string millimetres(double metres) {
  char buf[32];
  std::snprintf(buf, sizeof buf, metres < 0.001 ? "%.2f mm" : "%.0f mm", metres * 1000.0);
  return buf;
}

}  // namespace

Mechanism find_mechanism(const Network& net) {
  Mechanism m;
  const int P = static_cast<int>(net.wires.size());
  const int C = static_cast<int>(net.crossings.size());
  if (P == 0) return m;
  Vec3 o = Vec3::Zero();
  for (const auto& x : net.crossings) o += x.point;
  if (C > 0) o /= static_cast<double>(C);
  double ss = 0.0;
  for (const auto& x : net.crossings) ss += (x.point - o).squaredNorm();
  double L = C > 0 ? std::sqrt(ss / C) : 1.0;
  if (!(L > 1e-12)) L = 1.0;

  Eigen::MatrixXd Cm = Eigen::MatrixXd::Zero(std::max(3 * C, 1), 6 * P);
  for (int c = 0; c < C; ++c) {
    const auto& x = net.crossings[c];
    const Eigen::Matrix3d S = -skew((x.point - o) / L);  // w × r = -[r]× w
    for (int k = 0; k < 2; ++k) {
      const double sign = k == 0 ? 1.0 : -1.0;
      Cm.block(3 * c, 6 * x.wires[k], 3, 3) = sign * Eigen::Matrix3d::Identity();
      Cm.block(3 * c, 6 * x.wires[k] + 3, 3, 3) = sign * S;
    }
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Cm, Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  const double top = sv.size() > 0 ? sv(0) : 0.0;
  int rank = 0;
  for (Eigen::Index k = 0; k < sv.size(); ++k)
    if (sv(k) > 1e-9 * std::max(top, 1.0) * static_cast<double>(6 * P)) ++rank;
  const Eigen::MatrixXd N = svd.matrixV().rightCols(6 * P - rank);  // orthonormal null basis
  m.degrees_of_freedom = std::max(0, static_cast<int>(N.cols()) - 6);

  // Rigid parts: wires whose twists agree in every null vector.
  std::vector<int> parent(P);
  std::iota(parent.begin(), parent.end(), 0);
  for (int i = 0; i < P; ++i)
    for (int j = i + 1; j < P; ++j)
      if ((N.middleRows(6 * i, 6) - N.middleRows(6 * j, 6)).norm() < 1e-6)
        parent[find_root(parent, j)] = find_root(parent, i);
  std::vector<std::vector<int>> parts;
  std::vector<int> part_of(P, -1), index(P, -1);
  for (int w = 0; w < P; ++w) {
    const int r = find_root(parent, w);
    if (index[r] < 0) {
      index[r] = static_cast<int>(parts.size());
      parts.emplace_back();
    }
    parts[index[r]].push_back(w);
    part_of[w] = index[r];
  }
  std::vector<int> inner(parts.size(), 0);
  for (const auto& x : net.crossings)
    if (part_of[x.wires[0]] == part_of[x.wires[1]]) ++inner[part_of[x.wires[0]]];
  std::size_t best = 0;  // parts are ordered by their lowest wire id: ties keep the first
  for (std::size_t k = 1; k < parts.size(); ++k)
    if (parts[k].size() > parts[best].size() || (parts[k].size() == parts[best].size() && inner[k] > inner[best]))
      best = k;
  m.rest = parts[best];

  const double tol = 1e-6 * L + 1e-9;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    if (k == best) continue;
    MovingPart part;
    part.wires = parts[k];
    const int self = static_cast<int>(k), rest = static_cast<int>(best);
    std::vector<Vec3> points, to_rest;
    std::vector<int> neighbours;  // other moving parts joined to this one
    for (int c = 0; c < C; ++c) {
      const auto& x = net.crossings[c];
      const int p0 = part_of[x.wires[0]], p1 = part_of[x.wires[1]];
      if ((p0 == self) == (p1 == self)) continue;
      part.crossings.push_back(c);
      points.push_back(x.point);
      const int other = p0 == self ? p1 : p0;
      if (other == rest) {
        part.to_rest.push_back(c);
        to_rest.push_back(x.point);
      } else {
        neighbours.push_back(other);
      }
    }
    // When the other moving parts it holds hang on it alone (joined to nothing else), they cannot
    // stop it: how it moves against the rest is decided by its joints to the rest.
    bool dangling = !to_rest.empty();
    for (int c = 0; c < C && dangling; ++c) {
      const int p0 = part_of[net.crossings[c].wires[0]], p1 = part_of[net.crossings[c].wires[1]];
      for (int j : neighbours)
        if ((p0 == j && p1 != j && p1 != self) || (p1 == j && p0 != j && p0 != self)) dangling = false;
    }
    if (dangling && to_rest.size() < points.size()) points = to_rest;
    else part.to_rest.clear();
    if (points.empty()) {
      part.kind = MovingPart::Kind::loose;
    } else {
      double far = -1.0;
      for (std::size_t a = 0; a < points.size(); ++a)
        for (std::size_t b = a; b < points.size(); ++b)
          if ((points[a] - points[b]).norm() > far) {
            far = (points[a] - points[b]).norm();
            part.axis_from = points[a];
            part.axis_to = points[b];
          }
      if (far <= tol) {
        part.kind = MovingPart::Kind::pivot;
      } else {
        const Vec3 u = (part.axis_to - part.axis_from) / far;
        bool line = true;
        for (const Vec3& p : points) line = line && (p - part.axis_from - (p - part.axis_from).dot(u) * u).norm() <= tol;
        part.kind = line ? MovingPart::Kind::hinge : MovingPart::Kind::general;
      }
    }
    m.moving.push_back(part);
  }
  return m;
}

PlaneMove plane_move(const Network& net, int wire, const std::vector<int>& joined) {
  PlaneMove move;
  const WireSpec& w = net.wires[wire];
  if (!w.closed || w.points.size() < 3) return move;
  Polyline2 outline;
  for (const Vec3& p : w.points) outline.push_back(w.plane.to_2d(p));
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < static_cast<int>(net.wires.size()); ++k) {
    if (k == wire || std::find(joined.begin(), joined.end(), k) != joined.end()) continue;
    // A wire of a parallel plane is never crossed by moving this plane along its normal.
    if (std::abs(net.wires[k].plane.normal.dot(w.plane.normal)) > 1.0 - 1e-9) continue;
    for (const Vec3& q : net.wires[k].points) {
      const double s = w.plane.signed_distance(q);
      if (std::abs(s) < 1e-9 || std::abs(s) >= best || !inside(outline, w.plane.to_2d(q))) continue;
      best = std::abs(s);
      move.found = true;
      move.towards_wire = k;
      move.direction = s > 0 ? w.plane.normal : Vec3(-w.plane.normal);
      move.distance = best;
    }
  }
  return move;
}

std::string mechanism_message(const Network& net, const Mechanism& m) {
  std::vector<std::string> sentences;
  for (const MovingPart& part : m.moving) {
    const bool one = part.wires.size() == 1;
    const std::string who = names(net, part.wires);
    const std::vector<int>& joints = part.to_rest.empty() ? part.crossings : part.to_rest;
    const std::string held = std::string(one ? " is" : " are") + " held" +
                             (!part.to_rest.empty() ? " to the rest" : one ? "" : " to the other wires") +
                             " only at crossing" + (joints.size() == 1 ? " " : "s ") + crossing_list(joints);
    std::vector<int> hanging;
    for (int c : part.crossings)
      if (std::find(part.to_rest.begin(), part.to_rest.end(), c) == part.to_rest.end()) hanging.push_back(c);
    const std::string also = part.to_rest.empty() ? "" : " (its crossing" + std::string(hanging.size() == 1 ? " " : "s ") +
                                                            crossing_list(hanging) + " hold only wires that hang on it)";
    std::string s;
    switch (part.kind) {
      case MovingPart::Kind::loose:
        s = who + (one ? " is" : " are") + " joined to no other wire";
        break;
      case MovingPart::Kind::pivot:
        s = who + held + (joints.size() == 1 ? "" : ", all at one point") + ", so " + (one ? "it" : "they") +
            " can turn about that point" + also;
        break;
      case MovingPart::Kind::hinge:
        s = who + held + ", which lie on one line, so " + (one ? "it" : "they") +
            " can turn about that line like a hinge" + also;
        break;
      case MovingPart::Kind::general:
        s = who + " can move against the other wires although held at crossings " + crossing_list(part.crossings) +
            ": those joints leave a motion free (a mechanism)";
        break;
    }
    if (one && (part.kind == MovingPart::Kind::hinge || part.kind == MovingPart::Kind::pivot)) {
      std::vector<int> joined;  // every wire it crosses
      for (int c : part.crossings) {
        const auto& x = net.crossings[c];
        joined.push_back(x.wires[0] == part.wires[0] ? x.wires[1] : x.wires[0]);
      }
      const PlaneMove move = plane_move(net, part.wires[0], joined);
      const std::string where = part.kind == MovingPart::Kind::hinge ? "away from that line" : "at another point";
      if (move.found)
        s += "; move the plane of wire " + quoted(net, part.wires[0]) + " about " + millimetres(move.distance) +
             " in the " + direction_text(move.direction) + " direction, towards wire " + quoted(net, move.towards_wire) +
             ", so that it crosses another wire " + where + ", or add a plane that crosses it there";
      else
        s += "; add a plane whose wire crosses it " + where;
    }
    sentences.push_back(s);
  }
  std::string out;
  for (std::size_t k = 0; k < sentences.size(); ++k) out += (k ? "; " : "") + sentences[k];
  return out;
}

}  // namespace wiresculpt
