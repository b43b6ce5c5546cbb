#pragma once
// Forces, cuts, rest shapes and load capacity in one call (Sec. 4.4, Eq. 6-12, and beyond the
// paper): the stages after the target shape, composed here so that callers (the Python binding,
// tests, the bench) only convert. Method notes: docs/method-forces.md.
//
//   cuts   = choose_cuts(net, requested_cuts)                      rest_shape.hpp
//   forces = optimize_forces(net, hooks, steps, cuts, forces)       forces.hpp   (Eq. 6-8)
//   rest_w = rest_shape(wire w, cuts[w], wire_loads(w), rest)       rest_shape.hpp (Eq. 9-12)
//   load   = load_capacity(...)  when options.load_capacity          load_capacity.hpp
//
// The load capacity holds the same torque bound as the forces (options.forces.torque_bound
// overrides options.load.torque_bound).
#include <optional>
#include <vector>

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
};

struct ForcesAndRestResult {
  std::vector<int> cuts;                ///< per wire (choose_cuts)
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
