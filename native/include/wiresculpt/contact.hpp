#pragma once
// Contact pyramids with friction (Sec. 4.1, Fig. 4) and the hook configurations of a crossing
// with their local geometry (Sec. 4.2, Figs. 5 and 6) and optimality metric e_c (Eq. 2) of
// Miguel, Lepoutre, Bickel 2016. The derivation of the signs is in docs/method-layering.md.
//
// Conventions (docs/formats.md, `hook`): at crossing c with wires i = wires[0], j = wires[1] and plane
// normals n_i, n_j, let d = normalize(n_i × n_j), the direction of the planes' common line.
//   hook = +1: the kink of wire i opens towards +d (bisector h_i = +d) and the kink of wire j
//              opens towards -d (h_j = -d): the wires interlock like chain links, wire i's vertex
//              sits on the -d side of wire j's, and the contact force on wire i (exerted by
//              wire j) has a -d component.
//   hook = -1: the mirror image (h_i = -d, h_j = +d, force on wire i along +d).
//   hook =  0: the null configuration: no contact force, no pyramid, no modification, e_c = 0.
#include <array>
#include <numbers>
#include <optional>

#include "wiresculpt/network.hpp"

namespace wiresculpt {

struct ContactOptions {
  /// Coulomb friction coefficient μ between two wires (Table 1: steel 0.32, brass 0.23).
  /// The pyramid is widened by α(μ) = atan(μ) (see contact_pyramid). Default 0.32.
  double friction = 0.32;
  /// Radians, in (0, π]. The opening angle of a hooked kink: the angle between the wire's two
  /// edges at the crossing, placed symmetrically about the desired bisector ±d (Fig. 6). The
  /// kink turns the wire by π - contact_angle. Default 2π/3 (120°: each edge 60° from the
  /// bisector, a 60° bend, well inside the machine's 120° maximum bend).
  double contact_angle = 2.0 * std::numbers::pi / 3.0;
  /// Metres. The input bisector h̄ of Eq. 2 is measured with chords from the crossing to the
  /// first points at least this far along the wire on each side (stopping at a neighbouring
  /// crossing or an open end), so that a vertex inserted very close to the crossing does not
  /// decide the direction. 0 uses the two adjacent edges exactly as in Sec. 4.1. Default 0.005 m.
  double bisector_span = 0.005;
  /// Radians. When the input turns by less than this at the crossing the input bisector is
  /// undefined (the wire is straight there): each of its terms in Eq. 2 is then 1, as if the
  /// bisector were perpendicular to ±d, the same cost for both hooks. Default 1° (the machine's
  /// smallest reliable bend, Sec. 5.1).
  double straight_angle = std::numbers::pi / 180.0;
};

/// d = normalize(n0 × n1) for crossing `c` (unit, on both planes).
Vec3 crossing_direction(const Network& net, int c);

/// The input bisector h̄ of `wire` at its vertex `vertex` (Sec. 4.1: h = (ê_r - ê_{r-1}) / |…|,
/// pointing into the kink's opening), measured with ContactOptions::bisector_span; nullopt when
/// the wire is straight there (turn < straight_angle).
std::optional<Vec3> input_bisector(const Network& net, int wire, int vertex, const ContactOptions& options = {});

/// The four pyramid vectors of crossing `c` under `hook` (±1): unit forces on wires[0] exerted
/// by wires[1]; wires[1] receives the negatives. With s = hook, β = contact_angle/2 - atan(μ),
/// t_k = n_k × d (unit, in plane k, perpendicular to d):
///   from the edges of wire 0 (their in-plane normals, rotated away from each other by atan μ):
///     -s sinβ d + cosβ t_0,   -s sinβ d - cosβ t_0
///   from the edges of wire 1 (negated: wire 0 pushes wire 1's edges, Newton's third law):
///     -s sinβ d + cosβ t_1,   -s sinβ d - cosβ t_1
/// Throws InputError when hook is not ±1.
std::array<Vec3, 4> contact_pyramid(const Network& net, int c, int hook, const ContactOptions& options = {});

/// The local modification of Fig. 6 that realises a hook, and its cost.
struct HookGeometry {
  int hook = 0;
  std::array<Vec3, 2> bisector;  ///< desired h for wires[0], wires[1]: (+d, -d)·hook; zero for null
  /// Unit directions from the crossing along the previous and next edge of each wire after the
  /// modification (both at contact_angle/2 from the bisector, on the sides of the input
  /// neighbours); the input directions for the null hook.
  std::array<std::array<Vec3, 2>, 2> edge_dirs;
  /// The previous and next vertex of each wire moved onto those directions, keeping edge lengths.
  std::array<std::array<Vec3, 2>, 2> neighbours;
  /// Eq. 2: e_c = (1 - h_0·h̄_0) + (1 - h_1·h̄_1), each term 1 where the input is straight; 0 for
  /// the null hook. In [0, 4]; the costs of the two hooks always sum to 4.
  double metric = 0.0;
};

/// The geometry and cost of `hook` ∈ {-1, 0, 1} at crossing `c`.
HookGeometry hook_geometry(const Network& net, int c, int hook, const ContactOptions& options = {});

/// Just the metric e_c of `hook` at crossing `c` (0 for the null hook).
double hook_metric(const Network& net, int c, int hook, const ContactOptions& options = {});

/// Validates ContactOptions (finite friction >= 0, contact_angle in (0, π], spans >= 0);
/// throws InputError naming the option.
void validate(const ContactOptions& options);

}  // namespace wiresculpt
