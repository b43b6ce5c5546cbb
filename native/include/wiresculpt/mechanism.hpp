#pragma once
// Which wires move when no hook configuration can hold the sculpture (Sec. 4.2's necessary
// condition, explained to the user).
//
// With both hook directions allowed at a crossing, its contact cone is all of R^3: the two
// pyramids of contact_pyramid together contain ±d, ±t0 and ±t1 (sums of pairs of their vectors),
// so the crossing holds like a ball joint, transmitting any force and no couple. The relaxed
// check of the layering (both hooks everywhere) then fails exactly when the wires, rigid bodies
// joined by ball joints at the crossing points, can move: when the compatibility matrix
//
//   C (3 rows per crossing c of wires i, j; 6 columns per wire: velocity v, angular velocity w)
//   C_c z = (v_i + w_i × (x_c - o)) - (v_j + w_j × (x_c - o))        (the joint's relative slip)
//
// has a null space larger than the 6 rigid motions of the whole sculpture (C is the transpose of
// the equilibrium matrix of Eq. 1 with the pyramids replaced by their span). The null space is
// computed with an SVD (lengths in units of the crossings' RMS distance from their centroid o);
// two wires belong to one rigid part when their twists agree in every null vector. The largest
// part (most wires, then most crossings inside it, then the lowest wire id) is "the rest"; every
// other part moves against it. A moving part joined to the other wires at points that all lie on
// one line turns about that line like a hinge; at a single point it pivots about it.
//
// This is a diagnosis, not a verdict: the layering's LP decides stability.
#include <string>
#include <vector>

#include "wiresculpt/network.hpp"

namespace wiresculpt {

/// One rigid part that moves against the rest.
struct MovingPart {
  enum class Kind {
    general,  ///< joined at points not on one line, yet not held (several parts move together)
    hinge,    ///< every joining point on one line: it turns about that line
    pivot,    ///< joined at one point: it turns about it
    loose,    ///< joined to nothing outside the part
  };
  Kind kind = Kind::general;
  std::vector<int> wires;      ///< wire ids of the part, ascending
  std::vector<int> crossings;  ///< crossing ids joining the part to wires outside it, ascending
  /// When every other moving part it is joined to hangs on it alone: its crossings with the rest,
  /// which then decide `kind` (empty otherwise: `kind` is decided by all of `crossings`).
  std::vector<int> to_rest;
  /// hinge: two points on the axis (the joining points farthest apart); pivot: the point twice.
  Vec3 axis_from = Vec3::Zero(), axis_to = Vec3::Zero();
};

/// For a part that is one wire hinged or pivoting: a move of its plane that brings it to a wire
/// it does not cross yet (the nearest point of another wire, within the wire's outline seen
/// along the plane's normal; wires of parallel planes never count).
struct PlaneMove {
  bool found = false;
  int towards_wire = -1;   ///< the wire the moved plane would reach
  Vec3 direction = Vec3::Zero();  ///< unit, ± the plane's normal
  double distance = 0.0;   ///< metres, at least this far
};

struct Mechanism {
  /// Degrees of freedom beyond the 6 rigid motions of the whole (0: the ball-joint network is
  /// rigid, which the relaxed LP check then also finds unless the pyramids degenerate).
  int degrees_of_freedom = 0;
  std::vector<int> rest;             ///< wire ids of the largest rigid part
  std::vector<MovingPart> moving;    ///< every other rigid part, ordered by its lowest wire id
};

/// The mechanism of `net` with every crossing a ball joint (see the file comment).
Mechanism find_mechanism(const Network& net);

/// The plane move of PlaneMove for wire `wire`, which crosses only the wires in `joined`.
PlaneMove plane_move(const Network& net, int wire, const std::vector<int>& joined);

/// One sentence naming what moves and how, e.g. "wire 'W' is held only at crossings 3 and 4,
/// which lie on one line, so it turns about that line like a hinge; move its plane about 45 mm
/// along +z, towards wire 'Y', so that it crosses a wire away from that line, or add a plane
/// that crosses it there". Empty when `m` has no moving part.
std::string mechanism_message(const Network& net, const Mechanism& m);

}  // namespace wiresculpt
