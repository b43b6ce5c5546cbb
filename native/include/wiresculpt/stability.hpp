#pragma once
// Stability of rigid wires held by contact pyramids under external loads: Eq. 1 of Sec. 4.1 and
// the load basis of Sec. 4.2 (Miguel, Lepoutre, Bickel 2016), solved with GLPK.
//
//   minimise Σ a   subject to   M a = -l,   a >= 0                                (Eq. 1)
//
// M has one column per pyramid vector of every hooked crossing among the chosen wires: the unit
// force b on wires[0] of the crossing and its torque (x_c - x_ref) × b, and the negatives in the
// rows of wires[1]. A set of wires is stable when Eq. 1 is feasible for every column of the load
// basis L (6P × 6(P-1), Sec. 4.2) and for the negative of their sum; together these positively
// span every self-equilibrated load (Σ f = 0, Σ t = 0), so stability means that every such load
// can be balanced by contact forces inside the pyramids.
//
// Implementation notes (none change the verdict):
// - Torques are taken about the centroid of all crossings of the network and divided by the RMS
//   distance of the crossings from it, so force and torque rows have comparable size. Feasibility
//   of Eq. 1 is invariant under row scaling and under moving the common reference point.
// - Because every column and every load is self-equilibrated, the rows of one wire are implied
//   by the others and are left out. The paper's L uses its last polyline in that role; here the
//   first wire of the list plays it (any wire gives the same verdict). Loads are tried from the
//   last-listed wire backwards (in an assembly, the wire just added), then the negative sum.
// - Only the verdict is returned, so by default Eq. 1 is solved without its objective (pure
//   feasibility); StabilityOptions::minimise_sum restores it (same verdict, slower).
// - One LP is built per wire set and only its right-hand side changes between loads; each solve
//   warm-starts the dual simplex from the previous basis; the first infeasible load stops.
// - GLPK never prints (terminal output off) and never aborts the process: its error hook
//   unwinds to the caller, which throws SolverError.
#include <Eigen/Core>
#include <vector>

#include "wiresculpt/contact.hpp"
#include "wiresculpt/network.hpp"

namespace wiresculpt {

struct StabilityOptions {
  /// Forces only: 3 rows per wire, torques ignored. Sec. 4.2 uses it for the first pair of an
  /// assembly, which can always turn about the planes' common line. Default false.
  bool forces_only = false;
  /// Solve Eq. 1 with its objective Σ a. The objective only chooses among feasible combinations
  /// and never changes the verdict, which is all this module returns, so by default the LP is
  /// solved as a pure feasibility problem (zero objective), about 4 times faster. Default false.
  bool minimise_sum = false;
};

/// The verdict of Eq. 1 for one wire set.
struct StabilityResult {
  bool stable = false;
  /// When unstable: the wire whose unit load could not be balanced and the load component
  /// (0-2 force x, y, z; 3-5 torque x, y, z), or -1 / -1 when the failing load was the negative
  /// sum of the basis loads.
  int failed_wire = -1;
  int failed_component = -1;
  int lp_solves = 0;  ///< GLPK simplex calls made for this verdict
};

/// M of Eq. 1 for `wires` (ids, each once) under `hooks` (one of -1, 0, 1 per network
/// crossing; crossings with a wire outside `wires` are ignored), all rows kept.
struct WrenchMatrix {
  /// (6 or 3)·#wires rows (block k: force then, unless forces_only, torque of wires[k], torques
  /// in N·m about `reference`, unscaled) by 4·#hooked-crossings columns.
  Eigen::MatrixXd M;
  std::vector<int> column_crossing;  ///< crossing id of each column (4 consecutive per crossing)
  Vec3 reference = Vec3::Zero();     ///< the torque reference point (centroid of all crossings)
};
WrenchMatrix wrench_matrix(const Network& net, const std::vector<int>& wires, const std::vector<int>& hooks,
                           const ContactOptions& contact = {}, bool forces_only = false);

/// The load basis L of Sec. 4.2 exactly as printed: 6P × 6(P-1), L(i, j) = 1 if i = j, -1 if
/// i mod 6 = j mod 6 and i >= 6(P-1) (0-based), else 0. (The -1 rows are the last polyline's.)
Eigen::MatrixXd load_basis(int P);

/// Eq. 1 for every basis load and the negative sum; see the file comment.
/// Throws InputError for unknown wire ids, repeated wires or a wrong-sized `hooks`.
StabilityResult check_stability(const Network& net, const std::vector<int>& wires, const std::vector<int>& hooks,
                                const ContactOptions& contact = {}, const StabilityOptions& options = {});

/// The same check with the pyramids of every crossing computed once, for searches that test
/// many wire sets and hook choices of one network (layering). Not thread-safe; one per thread.
class StabilityChecker {
 public:
  explicit StabilityChecker(const Network& net, const ContactOptions& contact = {}, bool minimise_sum = false);
  /// As check_stability; `hooks` may also hold 2 at a crossing: both hooks' pyramids at once
  /// (8 columns), the relaxation the layering search uses to rule out every hook choice of a
  /// step with a single check (if the union is unstable, each choice is).
  StabilityResult check(const std::vector<int>& wires, const std::vector<int>& hooks, bool forces_only);
  long lp_solves() const { return lp_solves_; }

 private:
  const Network* net_;
  Vec3 reference_ = Vec3::Zero();
  double length_scale_ = 1.0;
  // Per crossing, per hook (0: hook -1, 1: hook +1): 4 columns of (force; scaled torque) on
  // wires[0] of the crossing.
  std::vector<std::array<std::array<Eigen::Matrix<double, 6, 1>, 4>, 2>> columns_;
  bool minimise_sum_ = false;
  long lp_solves_ = 0;
};

}  // namespace wiresculpt
