#pragma once
// The wire network: planar wires and the crossings between them (Sec. 4.1 of Miguel, Lepoutre,
// Bickel 2016, "an intersection between two polylines generates a crossing c"; Fig. 4).
//
// Two wires of different planes can only meet on the line where their planes meet. Wire i
// crosses plane j at points of that line, wire j crosses plane i at points of that line; where
// a point of each agrees (within `tolerance`) the wires cross. The crossing becomes a vertex of
// both polylines at the same 3D point, placed exactly on the planes' common line, and stays
// fixed for every later stage (Sec. 4.3: "we fix the position of the crossing points").
#include <array>
#include <string>
#include <vector>

#include "wiresculpt/geometry.hpp"
#include "wiresculpt/progress.hpp"

namespace wiresculpt {

/// One planar wire. For a closed wire the first point is not repeated at the end.
struct WireSpec {
  std::string name;     ///< shown in every message about this wire
  Plane plane;          ///< the wire's plane (unit normal, see Plane::make)
  Polyline3 points;     ///< #n 3D points on `plane` (n >= 2 open, n >= 3 closed), metres
  bool closed = true;
};

struct NetworkOptions {
  /// Metres. Two points closer than this are the same point: a wire point this close to the
  /// other wire's plane lies on it, two crossing candidates this close along the planes' common
  /// line are one crossing, wire points may lie this far off their own plane (they are projected
  /// onto it), and a crossing this close to an existing vertex replaces that vertex instead of
  /// adding one. Default 1e-5 m (10 µm): contours sliced from one mesh agree to rounding.
  double tolerance = 1e-5;
  /// Metres. The bending machine's minimum distance between bending points (Sec. 5.1,
  /// l_min = 1.5 cm). Crossings closer than this along a wire are reported in
  /// Network::close_crossings (Sec. 7: the model must then be scaled up). Default 0.015 m.
  double min_segment = 0.015;
};

/// A crossing of two wires (Fig. 4). wires[0] < wires[1]; vertices[k] indexes
/// Network::wires[wires[k]].points, and both those points are exactly `point`.
struct Crossing {
  std::array<int, 2> wires{-1, -1};
  std::array<int, 2> vertices{-1, -1};
  Vec3 point = Vec3::Zero();
};

/// Two crossings closer along one wire than NetworkOptions::min_segment.
struct CrossingGap {
  int wire = -1;
  std::array<int, 2> crossings{-1, -1};  ///< crossing ids, in the wire's direction
  double distance = 0.0;                 ///< metres, along the wire
  double scale = 1.0;                    ///< 2 min_segment / distance (detail::gap_scale): the model must grow this much
  std::string message;                   ///< a sentence naming the wire, crossings and sizes
};

struct Network {
  std::vector<WireSpec> wires;          ///< the input wires with every crossing inserted as a vertex
  std::vector<Crossing> crossings;      ///< sorted by (wires[0], wires[1], position on the line)
  std::vector<std::string> warnings;    ///< e.g. a wire touching another without crossing it
  std::vector<CrossingGap> close_crossings;  ///< empty when every gap is >= min_segment
  /// >= 1: the factor by which the model must be scaled up so that no two crossings are closer
  /// than 2 min_segment along a wire, the largest close_crossings' scale (1 when it is empty).
  double min_scale = 1.0;
  /// Metres: the largest side of the bounding box of all wires, now and after scaling by
  /// min_scale.
  double size = 0.0;
  double required_size = 0.0;
  /// Metres: NetworkOptions::min_segment the network was built with (close_crossings' limit).
  double min_segment = 0.0;

  /// Ids of the crossings on `wire`, in the order of their vertices along it.
  std::vector<int> crossings_of(int wire) const;

  /// Two crossings that follow each other along a wire, in its direction, their vertices on
  /// that wire, and the length of the wire between them (metres).
  struct Gap {
    int a = -1, b = -1;
    int va = -1, vb = -1;
    double arc = 0.0;
  };
  /// The gaps between consecutive crossings along `wire` (a closed wire's last one runs over its
  /// end; none with fewer than two crossings).
  std::vector<Gap> gaps_of(int wire) const;
};

/// Finds the crossings of `wires` and inserts them as vertices.
///
/// - Wires of parallel planes never cross. Wires of one plane must not touch: InputError naming
///   both. Three wires through one point: InputError naming the three.
/// - A wire that touches the other wire's plane where that wire is, without passing through it
///   (a tangency, or an open wire's end), makes no crossing; a warning says so.
/// - Consecutive points closer than 1e-12 m are merged; a closed wire whose last point repeats
///   its first has the repeat dropped.
/// Throws InputError naming the wire for too few points, non-finite coordinates or points
/// farther than `tolerance` from the wire's plane.
/// Reports progress as stage "network" once per pair of wires and once per wire, and honours
/// cancellation (throws Cancelled).
Network build_network(const std::vector<WireSpec>& wires, const NetworkOptions& options = {},
                      const ProgressFn& progress = {});

}  // namespace wiresculpt
