#pragma once
// Load capacity, beyond the paper: how many times its own weight the finished sculpture holds
// when it stands on a table, for gravity along each of the six axis directions. Method notes:
// docs/method-forces.md.
//
// For gravity ĝ (unit, ±x, ±y, ±z), every edge e of every wire carries its weight
// w_e = |e| π (d/2)² ρ g at its midpoint. The base is the wire that touches the table: the wire
// with the lowest point along ĝ (largest x·ĝ); every wire whose lowest point is within
// `tie_tolerance` of it touches the table too and is held as well (e.g. two meridians of a
// globe meet at its pole). Held wires take any wrench from the table. One LP per direction:
//
//   maximise    λ
//   subject to  M_i (a0 + δ) + λ W_i = 0               every wire i not held (6 rows)
//               |t_v(a0 + δ) + λ t_v^grav| <= t_max    every vertex of every wire not held (3D,
//                                                       or its n component: torque_bound)
//               a0 + δ >= 0                             every pyramid coefficient
//               λ >= 0
//
// with a0 the pre-stress of optimize_forces (M a0 = 0), W_i the weight wrench of wire i, t_v as
// in forces.hpp (walked from the cut) plus the torque of the weight of the edges after v, bounded
// by the rows of torque_bound.hpp (added to each LP as its solutions violate them; the solution
// is scaled into the polytope when GLPK's tolerance left it outside: the constraints are
// homogeneous in (a0 + δ, λ)). λ is the largest multiple of the sculpture's weight the structure holds
// with every contact force inside its pyramid and every wire below its torque limit (rigid
// wires, Sec. 4.1). λ = 0 means the sculpture cannot stand that way up; an unbounded LP gives
// λ = +inf (nothing but friction cones limit it, which scale with the load).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "wiresculpt/forces.hpp"

namespace wiresculpt {

struct LoadCapacityOptions {
  double wire_diameter = 0.003;  ///< metres (Table 1: 3 mm). Default 0.003.
  double density = 7850.0;       ///< kg/m³ in [1, 1e5] (steel 7850, brass 8500). Default 7850.
  double gravity = 9.81;         ///< m/s². Default 9.81.
  /// Metres: wires whose lowest point is this close to the lowest one are held too. Default 1e-6.
  double tie_tolerance = 1e-6;
  /// Which torque is bounded by t_max: full_3d (default, |t_v|) or in_plane (n·t_v only).
  TorqueBound torque_bound = TorqueBound::full_3d;
  /// As ForceOptions::lp_warm_start: false rebuilds GLPK's problem in every cutting-plane round
  /// (for tests). Default true.
  bool lp_warm_start = true;
  /// true: each cutting-plane round adds a vertex's violated neighbour rows too, as the forces'
  /// loop does (for tests: both reach the same λ). Default false, one row per vertex and round,
  /// which carries a third of the rows (docs/method-forces.md §15).
  bool lp_neighbour_rows = false;
  /// The six directions' LPs are solved on this many threads, 1 or 2 (the calling thread is one
  /// of them and the only one that reports progress; without a second thread to be had, 1). The
  /// answers do not depend on it. Default 2.
  int threads = 2;
};

struct LoadDirection {
  std::string name;           ///< "+x", "-x", "+y", "-y", "+z", "-z"
  Vec3 gravity = Vec3::Zero();///< unit direction of gravity
  double multiple = 0.0;      ///< λ (>= 0; +inf when unbounded)
  std::vector<int> base;      ///< held wires (ids)
  /// "optimal", "unbounded", "infeasible" (the pre-stress itself violates a bound: λ = 0) or
  /// "failed" (GLPK could not solve; λ = 0).
  std::string status;
  int lp_iterations = 0;
  int lp_rounds = 0;  ///< GLPK solves (torque rows are added as solutions violate them)
  /// The contact coefficients a = a0 + δ at the limit load (problem.columns(); empty unless
  /// "optimal"): one optimal point of the LP, which may have several; which one depends on the
  /// path of the cutting-plane loop (lp_neighbour_rows), λ does not.
  Eigen::VectorXd coefficients;
};

struct LoadCapacityResult {
  double length = 0.0;   ///< metres of wire
  double weight = 0.0;   ///< N: length × π(d/2)² × ρ × g
  std::vector<LoadDirection> directions;  ///< in the order +x, -x, +y, -y, +z, -z
  double seconds = 0.0;
};

/// Load capacity of the sculpture `net` (target shapes) with hooks, cuts and the pre-stress
/// coefficients `a0` of `problem` (the ForceProblem optimize_forces solved; a0 has
/// problem.columns() entries). Throws InputError for bad options or sizes. Reports progress as
/// stage "load_capacity" from the calling thread only: before direction 0, before each other
/// direction's LP that the calling thread solves, and at the end (7 times on one thread); honours
/// cancellation (throws Cancelled once the second thread has stopped).
LoadCapacityResult load_capacity(const Network& net, const std::vector<int>& cuts, const ForceProblem& problem,
                                 const Eigen::VectorXd& a0, const LoadCapacityOptions& options = {},
                                 const ProgressFn& progress = {});

}  // namespace wiresculpt
