#pragma once
// Internal contact forces of the assembled, unloaded sculpture (Sec. 4.4, Eq. 6-8 of Miguel,
// Lepoutre, Bickel 2016). Method notes, every choice and the measurements behind them:
// docs/method-forces.md.
//
//   maximise    G(a) = G_stb(a) + G_asm(a)
//   subject to  M a = 0                   6 rows per wire (force, torque), the final structure
//               |t_v(a)| <= t_max         every vertex of every wire, walked from its cut
//               N_k(a) >= 0               every hooked crossing (implied in practice, see below)
//               a >= 0
//
// Pyramids from the TARGET geometry (target_pyramid): the paper's pyramid vectors are built from
// the actual incident edges of both wires at each hooked crossing, so the forces are consistent
// with the shape that is fabricated and assembled (the layering judged the idealised kink of
// contact.hpp; the target-shape stage realises kinks at least that sharp, not exactly it). For
// an exactly symmetric kink of opening contact_angle about ±d the vectors equal contact_pyramid.
// Null crossings (hook 0) carry no force and have no columns.
//
// Normal force: at crossing k with d_k = normalize(n0 × n1) and hook s_k, the normal force is
// N_k = -s_k (f_k · d_k), f_k the force on wires[0]: the component along the planes' common line
// (the contact normal of two crossing wires, perpendicular to both wires' tangents where they are
// straight), signed so that the hooked push is positive. Every pyramid vector has a negative
// -s_k d_k component whenever each incident edge is more than atan μ away from the kink's
// bisector (the usual case), so N_k = |f_k · d_k|; the constraint N_k >= 0 keeps this identity
// exact otherwise. G_stb (Eq. 7) counts every crossing once per wire: G_stb = 2 Σ_k N_k.
//
// Torque (Sec. 4.4): t_v = Σ_{k after v} (x_v - x_k) × f_k^(i), a 3D vector, bounded by the
// rows of torque_bound.hpp in the wire's frame (n, u, v): by default the paper's |t_v| <= t_max
// (a polytope inscribed in the ball, exact for pure in-plane bending ±n t_max, at most 2.84%
// inside it elsewhere); ForceOptions::torque_bound = in_plane bounds only n·t_v, the component
// that bends the wire in its plane (the only bending the planar rest shape stores, Eq. 11).
// The LP takes the polytope's rows lazily (those a solution violates, until none is); SLSQP
// keeps them in its working set; the result is scaled into the polytope when a solver's
// tolerance left it outside (every constraint but the torque rows is homogeneous in a).
//
// G_asm (Eq. 8): -w Σ_s ||M_s a_s||² over the assembly prefixes s (each step of the assembly,
// the last one included although M a = 0 makes it vanish), with torque rows about the crossings'
// centroid divided by their RMS distance L from it (so every row is in newtons) and
// w = assembly_weight / F_ref, F_ref = t_max / L (the force the torque limit allows at the
// model's scale). G_stb is linear, G_asm concave quadratic: the problem is a convex QP.
// Solved by a GLPK LP for G_stb alone (exact, a vertex of the feasible set) and then, when
// w > 0, NLopt SLSQP on the whole G from the LP optimum, in the null space of M (a = N z, so
// M a = 0 holds to rounding); ForceAlgorithm chooses.
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "wiresculpt/carried_forces.hpp"
#include "wiresculpt/network.hpp"
#include "wiresculpt/progress.hpp"
#include "wiresculpt/rest_shape.hpp"
#include "wiresculpt/torque_bound.hpp"

namespace wiresculpt {

enum class ForceAlgorithm {
  lp_then_slsqp,  ///< default: GLPK for G_stb, then NLopt LD_SLSQP for G_stb + G_asm from there
  lp,             ///< GLPK only: maximises G_stb (G_asm reported, not optimised)
  slsqp,          ///< NLopt LD_SLSQP only, from a = 0 (for comparison)
};

struct ForceOptions {
  /// Coulomb friction μ (Table 1: steel 0.32, brass 0.23); pyramid vectors are widened by
  /// atan μ (contact.hpp). Default 0.32.
  double friction = 0.32;
  /// N·m: the material's plastic-limit bending torque (Table 1: steel 1.77, brass 1.30). Default 1.77.
  double max_torque = 1.77;
  /// (0, 1]: t_max = max_torque × torque_fraction (the paper's drop tests: 0.3, 0.6, 1). Default 1.
  double torque_fraction = 1.0;
  /// w̄ >= 0, dimensionless weight of G_asm (see file comment: w = w̄ / F_ref). 0 drops G_asm and
  /// makes the problem an LP. Default 0.05 (docs/method-forces.md: a tie-breaker that lowers the
  /// assembly residuals without giving up more than a few per cent of G_stb).
  double assembly_weight = 0.05;
  ForceAlgorithm algorithm = ForceAlgorithm::lp_then_slsqp;
  int max_iterations = 3000;   ///< NLopt evaluations. Default 3000.
  double ftol_rel = 1e-12;     ///< NLopt relative tolerance on G. Default 1e-12.
  double xtol_rel = 1e-10;     ///< NLopt relative tolerance on z. Default 1e-10.
  /// Relative to t_max: NLopt's tolerance on the torque and sign constraints. Default 1e-10.
  double constraint_tol = 1e-10;
  /// SLSQP sees only a working set of the torque rows (those near their bound at the start, then
  /// any the solution violates, until it violates none), not all 2 per vertex: the same optimum,
  /// since the relaxed problem's optimum that satisfies every row is the full problem's, at a
  /// fraction of the cost. false: every row from the start (for tests). Default true.
  bool working_set = true;
  /// Relative to t_max: the torque rows within this of their bound at the start (the LP's
  /// optimum) form the first working set (TorqueBound::in_plane). Default 0.5.
  double working_set_margin = 0.5;
  /// The same for TorqueBound::full_3d, where each vertex near its bound brings up to 6 facet
  /// rows, so a narrower margin keeps SLSQP's set small (docs/method-forces.md §3). Default 0.05.
  double working_set_margin_3d = 0.05;
  /// Which torque |t_v| <= t_max bounds (torque_bound.hpp): full_3d (default, the paper's 3D
  /// norm) or in_plane (n·t_v only, the behaviour before).
  TorqueBound torque_bound = TorqueBound::full_3d;
  /// After the LP, a second LP: among the solutions within tie_tolerance of the optimal G_stb,
  /// one with the least Σ_k Σ_w |f_k · n_w| (the forces' out-of-plane parts, w the crossing's two
  /// wires). The first LP returns a vertex of its feasible set, which may carry out-of-plane
  /// components that a near-optimal solution does not (docs/method-forces.md §12). Its result is
  /// final: SLSQP's G_asm (which would move back to the G_stb optimum) does not run. The
  /// pipeline's forces stage turns it on. Default false.
  bool least_out_of_plane = false;
  /// Relative: the second LP keeps G_stb >= (1 - tie_tolerance) × the first LP's optimum.
  /// Default 0.03 (the bundled globe's ellipse hooks reach 0% out of plane at 3%, §12).
  double tie_tolerance = 0.03;
  /// The LPs' cutting-plane rounds (torque rows added as solutions violate them) re-solve the
  /// problem GLPK holds from the last basis (lp.hpp, solve_lp_with_torque_rows). false: every
  /// round rebuilds it from scratch, as before (for tests, which compare the two). Default true.
  bool lp_warm_start = true;
  /// Beyond the paper (carried_forces.hpp, docs/method-forces.md §17): keep the force each hooked
  /// crossing carries once the structure is assembled in 3D (F3 = R f, linear) inside its
  /// pyramid shrunk by carried_margin, as rows of the force LPs; SLSQP does not run (it does not
  /// hold them). When only zero forces keep them, the LP is solved again without them
  /// (ForceResult::carried_3d false). Default false; the pipeline's forces stage turns it on.
  bool carried_3d = false;
  /// [0, 1): each pyramid vector is moved this far towards the pyramid's mean vector before the
  /// carried forces are held in the cone they span (0: the pyramid itself), so that what the
  /// linear map leaves out (the weight, the pre-stress's own stiffening) does not push a force
  /// out at once. Default 0.2.
  double carried_margin = 0.2;
  /// [0, 1]: every hooked crossing's carried normal force at least this share of their mean, so
  /// that the pre-stress, not the weight, loads each crossing. Default 0.25.
  double carried_share = 0.25;
  CarriedForceOptions carried;  ///< the material of the 3D structure
};

/// The four unit pyramid vectors of hooked crossing `c` (hook ±1) from the actual incident
/// edges of both wires in `net` (the target shapes): forces on wires[0] exerted by wires[1].
/// For wire w of the crossing, with arms a, b (unit vectors from the crossing vertex to its
/// neighbours, in plane w) and desired bisector h_w = (+s d for wires[0], -s d for wires[1]):
///   m_a = the unit in-plane normal of arm a pointing away from the kink's opening (m_a·h_w < 0;
///         for an arm along ±h_w, away from the other arm), widened by friction:
///   q_a = (m_a + μ a) / |m_a + μ a|   (the normal rotated by atan μ towards the arm)
/// Pyramid on wires[0]: { q_a(0), q_b(0), -q_a(1), -q_b(1) } (Newton's third law for wires[1]'s
/// own edges). An open end has no arm: InputError naming the crossing.
std::array<Vec3, 4> target_pyramid(const Network& net, int c, int hook, double friction);

/// Per wire: torque statistics at the optimum (walked from its cut).
struct WireTorque {
  double max_torque = 0.0;       ///< max_v |t_v| (plane-normal component), N·m
  int max_torque_vertex = -1;    ///< target index of that vertex (-1 when all are 0)
  double max_out_of_plane = 0.0; ///< max_v of the in-plane part of the 3D torque sum, N·m
  /// max_v of the whole 3D torque |Σ (x_v - x_k) × f_k| (in-plane bending, out-of-plane bending
  /// and twist together; the paper's |t_v| of Eq. 6), N·m. At most t_max with the default
  /// TorqueBound::full_3d; with in_plane only the plane-normal part is bounded.
  double max_torque_3d = 0.0;
};

/// Out-of-plane shares of the contact forces, per wire and in its own plane's terms.
struct OutOfPlaneShares {
  /// Per crossing: |f·n_w| / |f| for w = wires[0] and wires[1] (n_w the unit normal of that
  /// wire's own plane; the same |f| for both since wires[1] receives -f); {0, 0} when f = 0 or
  /// the crossing is null. A force along the planes' common line d = n0 × n1 lies in both planes:
  /// {0, 0}. A force along n0 gives {1, |n0·n1|}: the part of it in plane 1 bends wire 1 in its
  /// plane.
  std::vector<std::array<double, 2>> share;
  double mean = 0.0;  ///< mean of `share` over the crossings with a force and both their wires
  double max = 0.0;   ///< max of `share`
  /// The paper's normalisation (Sec. 7: "per-assembly out-of-plane component to maximum contact
  /// force ratio"): |f·n_w| divided by the largest |f| of the whole structure, mean and max over
  /// the same (crossing, wire) pairs.
  double mean_to_max_force = 0.0;
  double max_to_max_force = 0.0;
};

/// The out-of-plane shares of `forces` (per crossing, on wires[0]; ForceResult::forces) on `net`.
/// Null crossings (hooks[c] == 0) and zero forces are left out of the statistics.
OutOfPlaneShares out_of_plane_shares(const Network& net, const std::vector<int>& hooks,
                                     const std::vector<Vec3>& forces);

struct ForceResult {
  std::vector<Vec3> forces;    ///< per crossing: force on wires[0] by wires[1], N (0 when null)
  std::vector<double> normal;  ///< per crossing: N_k = -hook (f·d) >= 0, N (0 when null)
  /// Per crossing: |f·n_w|/|f| for its wires[0] and wires[1] (n_w their plane normals); 0 when f = 0.
  std::vector<std::array<double, 2>> out_of_plane;
  double mean_out_of_plane = 0.0;  ///< mean over hooked crossings and both wires
  double max_out_of_plane = 0.0;
  /// The same |f·n_w| over the structure's largest |f| (the paper's normalisation), mean and max.
  double mean_out_of_plane_to_max_force = 0.0;
  double max_out_of_plane_to_max_force = 0.0;
  Eigen::VectorXd coefficients;      ///< a, 4 per hooked crossing
  std::vector<int> column_crossing;  ///< crossing id of each coefficient
  std::vector<int> cuts;             ///< per wire (choose_cuts)
  std::vector<WireTorque> wires;
  double t_max = 0.0;          ///< N·m
  double g_stb = 0.0;          ///< N, Eq. 7
  double g_asm = 0.0;          ///< N, Eq. 8 times w (so G = g_stb + g_asm)
  /// Σ_s ||M_s a_s||² (N², torque rows scaled by 1/L) and ||M a|| / (Σ_j |a_j| ||m_j||), the
  /// relative equilibrium residual of the final structure.
  double assembly_residual = 0.0;
  double equilibrium_residual = 0.0;
  /// Some t_v is within 1e-6 relative of the torque bound (its gauge, torque_bound.hpp, >= 1 - 1e-6).
  bool torque_active = false;
  TorqueBound torque_bound = TorqueBound::full_3d;  ///< the bound that was imposed
  int lp_rounds = 0;           ///< GLPK solves (the torque rows are added as solutions violate them)
  std::string method;          ///< "lp", "lp+least_out_of_plane", "lp+slsqp" or "slsqp" (what produced the result)
  std::string nlopt_result;    ///< NLopt's code as text, "" when NLopt did not run
  int lp_iterations = 0;       ///< GLPK simplex iterations
  int iterations = 0;          ///< NLopt objective evaluations
  int working_set_rounds = 0;  ///< SLSQP solves over a growing working set (ForceOptions::working_set)
  int working_set_rows = 0;    ///< constraint rows in the last of them
  double lp_seconds = 0.0, nlp_seconds = 0.0, seconds = 0.0;
  std::vector<std::string> warnings;
  /// ForceOptions::carried_3d held: every hooked crossing's carried force lies in its shrunk pyramid.
  bool carried_3d = false;
  /// Per crossing: the force it carries in the assembled 3D structure (on wires[0], N; linear,
  /// carried_forces.hpp); zero for a null crossing. Empty unless ForceOptions::carried_3d.
  std::vector<Vec3> carried_forces;
  /// Per crossing: the weight's share in carried_forces (N; zero without a density).
  std::vector<Vec3> carried_weights;
};

/// The force problem of a network, exposed for tests: columns, M, torque rows, objective.
class ForceProblem {
 public:
  /// `net`: wires with their TARGET points and crossings indexing them; `hooks` one per crossing;
  /// `steps` the assembly (lists of wire ids, each wire once over all steps, or empty: no G_asm);
  /// `cuts` per wire (choose_cuts). Throws InputError naming the wire or crossing at fault.
  ForceProblem(const Network& net, const std::vector<int>& hooks, const std::vector<std::vector<int>>& steps,
               const std::vector<int>& cuts, const ForceOptions& options = {});

  int columns() const { return static_cast<int>(column_crossing_.size()); }
  const std::vector<int>& column_crossing() const { return column_crossing_; }
  const Eigen::MatrixXd& equilibrium() const { return M_; }   ///< 6P × K, torques in N·m about reference()
  const Eigen::MatrixXd& torque_rows() const { return T_; }   ///< #vertices × K: n·t_v per unit a_j, N·m
  /// 3 × #vertices rows × K: the components of t_v along its wire's n, u, v per unit a_j, N·m
  /// (row 3r is torque_rows() row r).
  const Eigen::MatrixXd& torque_frame_rows() const { return T3_; }
  TorqueBound torque_bound() const { return bound_; }
  const TorquePolytope& polytope() const { return torque_polytope(bound_); }
  /// Per torque row: the gauge of t_v(a) in polytope() (<= 1: within the bound).
  Eigen::VectorXd torque_gauges(const Eigen::VectorXd& a) const;
  const Eigen::VectorXd& normal_weights() const { return c_; } ///< c with G_stb = c·a
  const Eigen::MatrixXd& assembly_matrix() const { return Q_; } ///< Q with Σ_s ||M_s a_s||² = aᵀQa
  const Eigen::MatrixXd& normal_rows() const { return Nk_; }   ///< #hooked × K: N_k per unit a_j
  /// Per torque row: (wire, target vertex).
  const std::vector<std::array<int, 2>>& torque_vertex() const { return torque_vertex_; }
  Vec3 reference() const { return reference_; }
  double length_scale() const { return L_; }
  double t_max() const { return t_max_; }
  double weight() const { return w_; }  ///< w of G_asm, 1/N
  /// G(a) = c·a - w aᵀQa (N); adds dG/da to `grad` when non-null (resized to K).
  double objective(const Eigen::VectorXd& a, Eigen::VectorXd* grad = nullptr) const;
  /// Per crossing: its force on wires[0] for coefficients a.
  std::vector<Vec3> forces(const Eigen::VectorXd& a) const;
  const std::array<Vec3, 4>& pyramid(int crossing) const { return pyramid_[crossing]; }
  /// 3H × K: each hooked crossing's carried 3D force per unit a_j (empty unless carried_3d).
  const Eigen::MatrixXd& carried_map() const { return F3_; }
  /// 3H, N: each hooked crossing's carried share of the weight (F3 = carried_map() a + this).
  const Eigen::VectorXd& carried_weight() const { return W_; }
  /// #rows × K: rows >= carried_lower() keep every carried force in its shrunk pyramid and its
  /// normal force at least carried_share of their mean (empty unless carried_3d).
  const Eigen::MatrixXd& carried_rows() const { return C_; }
  const Eigen::VectorXd& carried_lower() const { return C_lo_; }

 private:
  void carried_rows(const Network& net, const std::vector<int>& hooks, const std::vector<int>& cuts,
                    const ForceOptions& options);

  const Network* net_;
  std::vector<int> hooks_;
  std::vector<int> column_crossing_;
  std::vector<std::array<Vec3, 4>> pyramid_;
  Eigen::MatrixXd M_, T_, T3_, Q_, Nk_, F3_, C_;
  TorqueBound bound_ = TorqueBound::full_3d;
  Eigen::VectorXd c_, W_, C_lo_;
  std::vector<std::array<int, 2>> torque_vertex_;
  Vec3 reference_ = Vec3::Zero();
  double L_ = 1.0, t_max_ = 0.0, w_ = 0.0;
};

/// Eq. 6-8 on `net` (target shapes). `cuts` per wire, already validated (choose_cuts).
/// Reports progress as stage "forces"; Cancelled when asked. Throws InputError for bad input and
/// SolverError when no optimum is found (GLPK failure; an unbounded problem names the crossing
/// whose force no torque limits).
ForceResult optimize_forces(const Network& net, const std::vector<int>& hooks,
                            const std::vector<std::vector<int>>& steps, const std::vector<int>& cuts,
                            const ForceOptions& options = {}, const ProgressFn& progress = {});

/// The contact loads of `forces` (per crossing, on wires[0]) on wire `wire`: +f at its vertex on
/// wires[0], -f on wires[1]; null crossings skipped.
std::vector<WireLoad> wire_loads(const Network& net, const std::vector<int>& hooks,
                                 const std::vector<Vec3>& forces, int wire);

}  // namespace wiresculpt
