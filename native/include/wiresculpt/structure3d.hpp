#pragma once
// The sculpture as it would stand: a geometrically nonlinear 3D equilibrium of
// the assembled structure, beyond the paper (whose wires bend only in their planes).
//
// Model. Every wire is a discrete elastic rod (Bergou, Wardetzky, Robinson, Audoly, Grinspun 2008,
// "Discrete Elastic Rods"): its nodes x_k (#n) and one material-frame angle θ_e per edge (#n-1)
// measured from a reference frame kept by time-parallel transport (Bergou et al. 2010: after each
// accepted Newton step the reference frames are re-based on the current tangents). Round section,
// so one bending stiffness for both section axes. With l̄_k = |ē_{k-1}| + |ē_k| (rest lengths, the
// Voronoi length of rest_shape.hpp's voronoi_length), at each interior node k
//   κb_k = 2 t_{k-1} × t_k / (1 + t_{k-1}·t_k)                 (|κb| = 2 tan(turn/2))
//   ω_k^j = (κb_k·m2_j, -κb_k·m1_j), j = k-1, k                (material curvatures)
//   E_bend  = (E I / l̄_k) · ½ Σ_j |ω_k^j - ω̄_k^j|²
//   E_twist = (G J / l̄_k) · (θ_k - θ_{k-1} + reference twist_k)²
// and per edge E_stretch = ½ E A (|e|/|ē| - 1)² |ē|. The natural shape is the given rest
// polyline, planar and untwisted: ω̄ from the rest polyline with its material frame m2 = `normal`
// (transported along it), natural twist 0. Materials as deflection.hpp: E·I = bending_stiffness,
// G·J = shear_modulus·π d⁴/32, E·A = (E·I / I)·π d²/4 with I = π d⁴/64.
//
// Loads: the weight (linear_density × g, lumped on the nodes by half their edges' rest lengths)
// and nodal forces. Supports (for tests and fixtures): a clamp holds a node, its neighbour along
// the wire (the next one, the previous for the last node) and the angle of the edge between them,
// i.e. position and material frame; a pin holds a node's position only. Ties join node a of one
// wire and node b of another (or the same) wire as a sticking point contact, x_a - x_b = offset,
// force only. The table: the chosen nodes may rest on the plane z = z0 through a smooth one-sided
// penalty (below); the lowest table node holds horizontally (sticking friction) and the table node
// farthest from it horizontally holds along the one axis that stops a turn about z, so the table
// alone leaves no rigid motion free.
//
// Constraints are linear and are eliminated, not multiplied: held DOFs are dropped and node b of a
// tie shares node a's DOFs (x_b = x_a - offset). The reduced Hessian stays symmetric, so its
// sparse LDLᵀ pivots tell a mechanism; each tie's force is still exact, the force node a needs
// from node b to balance, ∂Π/∂x_a (the KKT multiplier of x_a - x_b = offset, up to sign).
//
// Solve. Newton on the total energy Π (elastic + table - loads·x) from the start shape. Gradient
// and Hessian are exact: each local stencil (a bend-twist node: 3 nodes, 2 angles; a stretch edge:
// 2 nodes) is differentiated by forward second-order automatic differentiation, assembled into an
// Eigen sparse matrix and factorised by SimplicialLDLT; where the Hessian is not positive definite
// a multiple of the identity is added (Levenberg) until it is. Steps are capped to a quarter of the
// structure's size and searched back (Armijo) on Π. Converged when the residual, the largest
// unbalanced force of a free node (moments about an edge divided by its rest length), is at most
// `tolerance` × the load scale (Σ|loads and weights|, or E·I / size² without any: pre-stress
// alone), or at most the stretch forces' rounding 8 ε (E·A / shortest edge) × size where that is
// larger (coordinates carry ε × size; 2e-8 N for 3 mm steel, 1 cm edges, a 0.2 m structure).
//
// Not standing. (1) At the start, the unbalanced forces g drive a motion nothing resists when the
// linear response (H + 1e-14 × its largest diagonal)⁻¹ g, table contacts closed (every table node
// at most `smoothing` above the table given the table's stiffness), moves a node over
// 100 × size (a resisted response is a few sizes at most): mechanism. (2) At convergence the
// unregularised reduced Hessian must be positive definite, every LDLᵀ pivot above 1e-12 of the
// largest: otherwise mechanism. A wire whose spin about itself (all its angles turned alike, no
// node moved) is nearly free (below 1e-9 of the largest diagonal entry: a straight or nearly
// straight wire) has that spin taken out first; it moves nothing. (3) A node moving farther than
// max_motion from the start: moved_away. (4) No descent in the line search: no_equilibrium.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "wiresculpt/geometry.hpp"
#include "wiresculpt/progress.hpp"

namespace wiresculpt {

/// One wire of the structure.
struct Structure3dWire {
  std::string name;  ///< shown in every message about this wire
  Polyline3 rest;    ///< #n >= 2: the natural (fabricated) polyline, planar, untwisted, metres
  Polyline3 start;   ///< #n: where Newton starts (in use: the target shape), metres
  /// The rest shape's plane normal: the material frame's m2 on the first edge of both `rest` and
  /// `start` (made perpendicular to it), transported along them. Must not lie along a first edge.
  Vec3 normal = Vec3::UnitZ();
};

/// A node of the structure: vertex `vertex` of wire `wire` (indices into Structure3dInput::wires
/// and that wire's points).
struct NodeRef {
  int wire = -1;
  int vertex = -1;
};

/// A sticking point contact: x_a - x_b = offset (metres, constant) at equilibrium.
struct Structure3dTie {
  NodeRef a, b;
  Vec3 offset = Vec3::Zero();
};

struct Structure3dLoad {
  NodeRef node;
  Vec3 force = Vec3::Zero();  ///< N
};

struct Structure3dTable {
  bool enabled = false;
  double z0 = 0.0;  ///< metres: the table's plane z = z0
  /// Nodes that may rest on it; empty: every node of every wire.
  std::vector<NodeRef> nodes;
  /// N/m. The push of the table on a node sunk g below z0: stiffness × (g - w/2) for g >= w, and
  /// stiffness × g²/(2w) on 0 < g < w (w = `smoothing`), 0 above: the energy is twice continuously
  /// differentiable, and a 1 N load sinks 1 µm + w/2. Default 1e6.
  double stiffness = 1e6;
  double smoothing = 1e-6;  ///< metres, w above. Default 1e-6.
  /// Hold the lowest table node horizontally and the farthest one along one axis (see above).
  /// Default true.
  bool hold_horizontal = true;
  /// Hold every table node at its height too (a support, not a contact): structure3d_tie_response's
  /// table, whose linear response has no contact stiffness to lean on. Default false.
  bool hold_vertical = false;
};

struct Structure3dInput {
  std::vector<Structure3dWire> wires;
  std::vector<Structure3dTie> ties;
  std::vector<Structure3dLoad> loads;
  std::vector<NodeRef> clamps;
  std::vector<NodeRef> pins;
  Structure3dTable table;
};

struct Structure3dOptions {
  double bending_stiffness = 0.73;  ///< E·I, N·m² (Table 1: steel 0.73, brass 0.42). Default 0.73.
  double wire_diameter = 0.003;     ///< metres. Default 0.003.
  double shear_modulus = 79.3e9;    ///< G, Pa (steel 79.3e9, brass 39e9). Default 79.3e9.
  /// kg/m; 0 for no weight. Default 0.0555 (3 mm steel: 7850 kg/m³ × π (1.5 mm)²).
  double linear_density = 0.0555;
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  ///< m/s². Default (0, 0, -9.81).
  /// Relative residual (see the header comment). Default 1e-8: stretch forces carry a rounding of
  /// about E·A × 1e-16 (1e-10 N for 3 mm steel), far below 1e-8 of a sculpture's weight.
  double tolerance = 1e-8;
  int max_iterations = 200;  ///< Newton iterations. Default 200.
  /// Metres: a node moving farther than this from the start has not stood where it was built
  /// (cause moved_away). 0: the structure's size (the largest side of the start's box). Default 0.
  double max_motion = 0.0;
};

/// Why the 3D check did not find the structure standing.
enum class Structure3dCause {
  none,            ///< converged
  mechanism,       ///< a free motion at the equilibrium found (singular or indefinite stiffness)
  no_equilibrium,  ///< the line search found no descent: no equilibrium reachable from the start
  moved_away,      ///< a node moved farther than max_motion from the start
  iteration_cap,   ///< max_iterations reached
};

/// The sentence a user reads for `cause` with its figure (Structure3dResult::cause_figure).
std::string describe(Structure3dCause cause, double figure);

struct Structure3dWireResult {
  Polyline3 points;            ///< #n deformed nodes, metres
  std::vector<double> angles;  ///< #n-1 material angles θ_e from the transported frame, radians
  double max_distance = 0.0;   ///< the largest |points[k] - start[k]|, metres
  int max_distance_vertex = 0;
};

struct Structure3dReaction {
  NodeRef node;
  Vec3 force = Vec3::Zero();   ///< N, the support's force on the structure
  Vec3 moment = Vec3::Zero();  ///< N·m about the node (clamps only; 0 for pins and holds)
};

struct Structure3dResult {
  bool converged = false;
  Structure3dCause cause = Structure3dCause::iteration_cap;
  /// mechanism: the smallest pivot / the largest; moved_away: the motion (m); else the residual.
  double cause_figure = 0.0;
  double residual = 0.0;    ///< relative, as `tolerance`
  double load_scale = 0.0;  ///< N
  int iterations = 0;
  std::vector<Structure3dWireResult> wires;
  std::vector<Vec3> tie_forces;  ///< per tie, N: the force on node a (node b gets its negative)
  std::vector<Structure3dReaction> clamps, pins;
  std::vector<Structure3dReaction> table;  ///< per table node: the table's push (and holds' friction)
};

/// The equilibrium of `input` (see the header comment). Throws InputError naming the wire, tie,
/// load, support or option for bad input (non-finite or too few points, zero-length edges, a
/// vertex that does not exist, a node in two ties or tied where it is held, a normal along a first
/// edge, non-positive stiffness). Reports progress as stage "structure3d" once per Newton
/// iteration and honours cancellation by throwing Cancelled, like every stage.
Structure3dResult solve_structure3d(const Structure3dInput& input, const Structure3dOptions& options = {},
                                    const ProgressFn& progress = {});

/// The nearest nonnegative combination of `pyramid` (contact.hpp's contact_pyramid) to `force`.
/// The linear response of the assembled structure about its start, stress-free (each wire's rest
/// is its start): per load case (forces on nodes, N), the force each tie carries on its node a
/// (N), in the order of input.ties, from K Δq = P (K the stiffness at the start with the ties
/// made to hold and the clamps held; no weight, no table) and the tie's share of it,
/// H_a Δq - P_a (H_a the elastic stiffness of node a's own rod). Within the linear range this
/// is what solve_structure3d's ties carry under the same loads. For self-balanced loads a clamp
/// (any one node) only removes the rigid motions; a table (Structure3dTable::hold_vertical) holds
/// its nodes at their heights and as hold_horizontal says. One factorisation for every case. Throws
/// InputError as solve_structure3d, and SolverError when the tied structure is a mechanism.
std::vector<std::vector<Vec3>> structure3d_tie_response(const Structure3dInput& input,
                                                        const std::vector<std::vector<Structure3dLoad>>& cases,
                                                        const Structure3dOptions& options = {});

struct PyramidFit {
  std::array<double, 4> coefficients{};  ///< >= 0
  double distance = 0.0;  ///< |Σ c_i p_i - force|, N
  bool inside = false;    ///< distance <= tolerance × max(|force|, 1e-300)
};

/// Whether `force` lies in the cone of the four vectors (exact: every face and edge of the cone
/// is tried). `tolerance` is relative to |force|. Default 1e-9.
PyramidFit pyramid_fit(const Vec3& force, const std::array<Vec3, 4>& pyramid, double tolerance = 1e-9);

}  // namespace wiresculpt
