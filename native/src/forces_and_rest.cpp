#include "wiresculpt/forces_and_rest.hpp"

#include <algorithm>
#include <chrono>

namespace wiresculpt {

ForcesAndRestResult forces_and_rest(const Network& net, const std::vector<int>& hooks,
                                    const std::vector<std::vector<int>>& steps,
                                    const std::vector<int>& requested_cuts, const ForcesAndRestOptions& options,
                                    const ProgressFn& progress) {
  ForcesAndRestResult out;
  out.cuts = choose_cuts(net, requested_cuts);
  out.forces = optimize_forces(net, hooks, steps, out.cuts, options.forces, progress);

  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t P = net.wires.size();
  for (std::size_t w = 0; w < P; ++w) {
    report_progress(progress, "rest_shape", static_cast<double>(w) / static_cast<double>(P));
    const int wi = static_cast<int>(w);
    out.rests.push_back(rest_shape(net.wires[w], out.cuts[w], wire_loads(net, hooks, out.forces.forces, wi), options.rest));
  }
  out.rest_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  report_progress(progress, "rest_shape", 1.0);

  for (std::size_t w = 0; w < P; ++w) {
    if (net.wires[w].closed) out.max_closure_gap = std::max(out.max_closure_gap, out.rests[w].closure_gap);
    out.over_bend += static_cast<int>(out.rests[w].over_bend.size());
  }
  for (int h : hooks) out.hooked_crossings += h != 0 ? 1 : 0;

  if (options.load_capacity) {
    LoadCapacityOptions load = options.load;
    load.torque_bound = options.forces.torque_bound;  // the same bound as the forces
    const ForceProblem problem(net, hooks, steps, out.cuts, options.forces);
    out.load_capacity = load_capacity(net, out.cuts, problem, out.forces.coefficients, load, progress);
  }
  return out;
}

}  // namespace wiresculpt
