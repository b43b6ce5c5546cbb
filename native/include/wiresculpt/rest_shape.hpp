#pragma once
// Cuts and rest shapes (Sec. 4.4, Eq. 9-12 of Miguel, Lepoutre, Bickel 2016): where a closed wire
// is cut open, how a wire is walked from its cut, and the fabricated (rest) polyline in 2D whose
// elastic bending torques balance the contact forces in the target shape. Method notes, the sign
// convention of the turning angles and the derivation of Eq. 12's sign: docs/method-forces.md.
//
// Walk (docs/formats.md `rest`): a closed wire of n target points cut at `cut` is walked
// cut, cut+1, ..., cut+n-1, cut (mod n): n+1 positions, the cut at both ends. An open wire (cut
// -1) is walked 0 .. n-1. Every per-position array below follows the walk.
#include <numbers>
#include <string>
#include <vector>

#include "wiresculpt/geometry.hpp"
#include "wiresculpt/network.hpp"

namespace wiresculpt {

/// Target indices in walk order: #n+1 (closed, the cut repeated at the end) or #n (open, cut -1).
/// Throws InputError when a closed wire's cut is out of [0, n) or an open wire's is not -1.
std::vector<int> wire_walk(int n, bool closed, int cut, const std::string& wire_name = "wire");

/// The automatic cut of a closed wire (Sec. 4.4: "in the middle of the longest subpolyline"):
/// the sub-polylines between consecutive crossing vertices (cyclically) are measured in arc
/// length; among those with at least one vertex strictly inside, the longest is cut at its
/// interior vertex closest to half its arc length (ties: the lower walk position). A wire
/// without crossings is cut at vertex 0. Returns -1 for an open wire.
///   wire               the target polyline (points, closed)
///   crossing_vertices  indices into wire.points of every crossing on the wire (hooked or null)
/// Throws InputError naming the wire when every sub-polyline is a single edge (no place to cut).
int automatic_cut(const WireSpec& wire, const std::vector<int>& crossing_vertices);

/// One cut per wire of `net` (whose wire points are the target shapes): requested[w] = -1 (or
/// `requested` empty) chooses automatic_cut for closed wires; any other value is a user override,
/// validated: InputError naming the wire when it is out of [0, n), lies on a crossing vertex,
/// or is given for an open wire. Open wires always get -1.
std::vector<int> choose_cuts(const Network& net, const std::vector<int>& requested = {});

/// A contact force on the wire: `force` (N, 3D) acting at target vertex `vertex`.
struct WireLoad {
  int vertex = -1;
  Vec3 force = Vec3::Zero();
};

struct RestShapeOptions {
  /// k_b of Eq. 9, N·m² (Table 1: steel 0.73, brass 0.42; fitted by the paper with this very
  /// energy, Sec. 5.2). Default 0.73.
  double bending_stiffness = 0.73;
  /// Radians: the machine's largest bend (Sec. 4.3 c_f,angle; docs/formats.md `max_bend_deg`). Rest
  /// turning angles beyond it are reported in RestShapeResult::over_bend. Default 2π/3.
  double max_bend = 2.0 * std::numbers::pi / 3.0;
  /// Radians: a rest angle counts as over max_bend only beyond this. The target shape holds its
  /// bends to max_bend within its constraint tolerance, so a vertex the forces leave unloaded can
  /// sit at max_bend plus rounding; flagging it would ask for a needless coupling round.
  /// Default 1e-6 (6e-5 degrees).
  double over_bend_tolerance = 1e-6;
};

struct RestShapeResult {
  std::vector<int> walk;         ///< target index of each position (see wire_walk)
  /// Rest polyline, #walk by 2, metres, in the wire's plane frame (Plane::to_2d): it starts at
  /// the cut's target point and its first edge has the target's first edge direction; edge k has
  /// exactly the length of target edge walk[k] -> walk[k+1].
  Polyline2 rest;
  /// Signed turning angles (radians, counter-clockwise about the plane normal positive, i.e. in
  /// the right-handed (u, v) frame) of the target and of the rest polyline per position; 0 at the
  /// two ends of the walk (a cut or open end is not bent).
  std::vector<double> target_angles;
  std::vector<double> rest_angles;
  /// t_v of Eq. 11 per position (N·m): the plane-normal component of
  /// Σ_{loads after v in the walk} (x_v - x_k) × f_k (only g_k, the in-plane part, contributes).
  std::vector<double> torque;
  /// |the in-plane part of that same 3D torque sum| (N·m): the out-of-plane bending and twist the
  /// planar model ignores (reported, not used).
  std::vector<double> out_of_plane_torque;
  double max_torque = 0.0;      ///< max |torque|, N·m
  int max_torque_vertex = -1;   ///< target index where it occurs (-1 when every torque is 0)
  /// Closed wires: |rest.back() - rest.front()|, metres (the two ends of the cut wire need not
  /// meet before assembly). 0 for open wires.
  double closure_gap = 0.0;
  std::vector<int> over_bend;          ///< target indices whose |rest angle| > max_bend
  std::vector<double> over_bend_angle; ///< those rest angles (radians, signed)
};

/// Turning angles of a 2D polyline walk (signed, CCW positive), 0 at both ends. Exposed for tests.
std::vector<double> turning_angles(const Polyline2& points);

/// A polyline from a start point, a first-edge direction (radians from +u), edge lengths (#m-1)
/// and turning angles (#m, ends ignored). Exposed for tests.
Polyline2 polyline_from_angles(const Vec2& start, double heading, const std::vector<double>& lengths,
                               const std::vector<double>& angles);

/// l̄_v, the length vertex v's bending energy integrates over (Eq. 9), from its two edge lengths:
/// |e_{v-1}| + |e_v|, the Voronoi length of Bergou et al. 2008 (discrete elastic rods), which the
/// paper builds on. The paper prints ½(|e_{v-1}| + |e_v|); with that, a uniform rod of stiffness
/// k_b bends half as much as the continuum rod E·I = k_b (cantilever tip P·L³/(6 k_b) instead of
/// P·L³/(3 k_b)), while Table 1's k_b (steel 0.73, brass 0.42 N·m² for 3 mm wire) are the wires'
/// E·I (0.80 and about 0.42 N·m²). So this model uses the full sum: k_b means E·I, and the
/// presets, the calibration fit (fab/calibration.hpp) and the rest shapes agree.
inline double voronoi_length(double prev_edge, double next_edge) { return prev_edge + next_edge; }

/// Eq. 10: the elastic torque t_int = -(4 k_b / l̄)(tan(α/2) - tan(ᾱ/2))(1 + tan²(α/2)), N·m.
double elastic_torque(double alpha, double rest_alpha, double l_bar, double bending_stiffness);

/// The rest shape of one wire (Eq. 9-12).
///   wire     plane and target points (#n, on the plane), closed flag; name used in messages
///   cut      as wire_walk
///   loads    contact forces on this wire (several may share a vertex); the wire must be in
///            equilibrium under them for the result to be independent of the cut
/// At every interior position v the rest angle solves torque equilibrium,
///   elastic_torque(α_v, ᾱ_v, l̄_v, k_b) = t_v   (Eq. 10 = Eq. 11 with α signed CCW), i.e.
///   ᾱ_v = 2 atan( tan(α_v/2) + t_v / ((4 k_b / l̄_v)(1 + tan²(α_v/2))) ),
/// which is the paper's Eq. 12 with its torque sign taken for counter-clockwise angles (the
/// derivation is in docs/method-forces.md). Throws InputError naming the wire for bad input.
RestShapeResult rest_shape(const WireSpec& wire, int cut, const std::vector<WireLoad>& loads,
                           const RestShapeOptions& options = {});

}  // namespace wiresculpt
