#pragma once
// Forces, cuts, rest shapes and load capacity in one call (Sec. 4.4, Eq. 6-12, and beyond the
// paper): the stages after the target shape, composed here so that callers (the Python binding,
// tests, the bench) only convert. Method notes: docs/method-forces.md.
//
//   cuts   = choose_cuts(net, requested_cuts)                      rest_shape.hpp
//   forces = optimize_forces(net, hooks, steps, cuts, forces)       forces.hpp   (Eq. 6-8)
//   rest_w = rest_shape(wire w, cuts[w], wire_loads(w), rest)       rest_shape.hpp (Eq. 9-12)
//   load   = load_capacity(...)  when options.load_capacity          load_capacity.hpp
//   defl_w = wire_deflection(wire w, cuts[w], wire_loads(w), ...)   deflection.hpp (3D check)
//            when options.deflection
//
// Load factor (options.load_factor > 0, with load_capacity): the torque fraction is chosen, not
// given: the least one whose load capacity holds load_factor × the weight in each of the six
// directions. Exact, not searched: the load capacity LP's variable is a = a0 + δ >= 0 with δ
// free, so its feasible set does not depend on the pre-stress a0, and every constraint is
// homogeneous in (a, λ, t_max): λ_d(f) = f λ_d(1) for every direction d and fraction f. So
//   f* = clamp(load_factor / min_d λ_d(1), min_torque_fraction, 1)
// from one load capacity at fraction 1 (with a0 = 0), then the stages above at f* (whose load
// capacity, solved again, reports the multiples the design holds). Directions that hold any load
// (λ = +inf) do not limit f*; if none limits it, f* = min_torque_fraction. When even f = 1 falls
// short, f* = 1 and the factor reached is below the one asked. docs/method-forces.md §10.
//
// The load capacity holds the same torque bound as the forces (options.forces.torque_bound
// overrides options.load.torque_bound).
#include <optional>
#include <string>
#include <vector>

#include "wiresculpt/deflection.hpp"
#include "wiresculpt/forces.hpp"
#include "wiresculpt/load_capacity.hpp"
#include "wiresculpt/network.hpp"
#include "wiresculpt/progress.hpp"
#include "wiresculpt/rest_shape.hpp"

namespace wiresculpt {

struct ForcesAndRestOptions {
  ForceOptions forces;
  RestShapeOptions rest;
  LoadCapacityOptions load;
  /// Compute the load capacity (it needs the material's density). Default false.
  bool load_capacity = false;
  /// Radians; > 0: the load capacity after the forces (and the load factor's `reached`) is only
  /// computed when every rest angle is within this (|rest angle| <= it); otherwise `load_capacity`
  /// stays empty. The pipeline's coupling rounds (Sec. 4.3) solve again when a rest bend is over
  /// the machine's limit and keep only the last round's result, so they skip these six LPs in the
  /// rounds that are followed by another. 0: always computed. Default 0.
  double load_capacity_within = 0.0;
  /// > 0: choose forces.torque_fraction by the load factor (file comment; needs load_capacity,
  /// else InputError); 0: use forces.torque_fraction as given. Multiples of the weight. Default 0.
  double load_factor = 0.0;
  /// (0, 1]: the least fraction the load factor may choose. Default 0.01.
  double min_torque_fraction = 0.01;
  /// Compute each wire's out-of-plane deflection under its contact forces (it needs the
  /// material's shear modulus, deflection_options.shear_modulus). Default false.
  bool deflection = false;
  DeflectionOptions deflection_options;  ///< bending_stiffness is taken from rest.bending_stiffness
  /// Metres: a wire deflecting more than this out of its plane gets a warning naming it. Default 0.002.
  double deflection_limit = 0.002;
};

/// What the load factor chose (ForcesAndRestOptions::load_factor > 0).
struct LoadFactorResult {
  double asked = 0.0;    ///< load_factor, multiples of the weight
  /// min over the six directions of the load capacity at the fraction used (the second load
  /// capacity, not f* λ(1)); +inf when every direction holds any load.
  double reached = 0.0;
  /// min_d λ_d(1): the multiple at the plastic limit (+inf when unbounded in every direction).
  double at_plastic_limit = 0.0;
  std::string weakest;   ///< the direction of that minimum ("+x" ...; "" when unbounded)
  /// The fraction the load factor asks for exceeds 1: the plastic limit is used.
  bool limited = false;
};

struct ForcesAndRestResult {
  std::vector<int> cuts;                ///< per wire (choose_cuts)
  /// The torque fraction used: options.forces.torque_fraction, or the load factor's choice.
  double torque_fraction = 1.0;
  std::optional<LoadFactorResult> load_factor;     ///< when options.load_factor > 0
  /// Per wire when options.deflection (else empty): the 3D frame under its contact forces.
  std::vector<DeflectionResult> deflections;
  double deflection_seconds = 0.0;
  /// The wires over options.deflection_limit, named, with their deflection in mm.
  std::vector<std::string> warnings;
  ForceResult forces;                   ///< Eq. 6-8; forces.seconds is the forces stage's time
  std::vector<RestShapeResult> rests;   ///< per wire, walked from cuts[w]
  std::optional<LoadCapacityResult> load_capacity;  ///< when options.load_capacity
  /// Per crossing: its hook is not 0 (a loaded crossing).
  int hooked_crossings = 0;
  double rest_seconds = 0.0;            ///< the rest shapes of every wire
  /// The largest closure gap over the closed wires (m; 0 without closed wires) and the number
  /// of rest bends beyond options.rest.max_bend over every wire.
  double max_closure_gap = 0.0;
  int over_bend = 0;
};

/// Forces, rest shapes and (optionally) load capacity of `net` (wires with their TARGET points,
/// crossings indexing them) under `hooks` (one per crossing), the assembly `steps` (for G_asm;
/// may be empty) and `requested_cuts` (per wire, -1 automatic; may be empty). Reports progress
/// as stages "forces", "rest_shape" and "load_capacity"; Cancelled when asked. Throws
/// InputError for bad input (naming the wire or crossing) and SolverError as optimize_forces.
ForcesAndRestResult forces_and_rest(const Network& net, const std::vector<int>& hooks,
                                    const std::vector<std::vector<int>>& steps,
                                    const std::vector<int>& requested_cuts, const ForcesAndRestOptions& options = {},
                                    const ProgressFn& progress = {});

}  // namespace wiresculpt
