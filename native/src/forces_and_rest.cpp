#include "wiresculpt/forces_and_rest.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "figures.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {

ForcesAndRestResult forces_and_rest(const Network& net, const std::vector<int>& hooks,
                                    const std::vector<std::vector<int>>& steps,
                                    const std::vector<int>& requested_cuts, const ForcesAndRestOptions& options,
                                    const ProgressFn& progress) {
  ForcesAndRestResult out;
  if (!(std::isfinite(options.load_capacity_within) && options.load_capacity_within >= 0))
    throw InputError("load_capacity_within must be a finite number of radians >= 0 (0: always compute the load capacity)");
  out.cuts = choose_cuts(net, requested_cuts);
  ForceOptions force_options = options.forces;
  force_options.carried.bending_stiffness = options.rest.bending_stiffness;
  force_options.carried.wire_diameter = options.load.wire_diameter;
  force_options.carried.shear_modulus = options.deflection_options.shear_modulus;
  force_options.carried.linear_density = !options.load_capacity ? 0.0 : options.load.density * 0.25 * 3.141592653589793 * options.load.wire_diameter *
                                         options.load.wire_diameter;
  LoadCapacityOptions load = options.load;
  std::optional<LoadCapacityResult> at_plastic_limit;  // with a load factor
  load.torque_bound = options.forces.torque_bound;  // the same bound as the forces
  if (options.load_factor != 0.0) {
    if (!std::isfinite(options.load_factor) || options.load_factor < 0)
      throw InputError("load_factor must be a finite multiple of the weight >= 0");
    if (!(options.min_torque_fraction > 0 && options.min_torque_fraction <= 1))
      throw InputError("min_torque_fraction must be in (0, 1]");
    if (!options.load_capacity)
      throw InputError("the load factor needs the load capacity (a material with a density)");
    // λ_d(1): the load capacity at the plastic limit; the pre-stress does not enter it (a0 = 0).
    ForceOptions full = options.forces;
    full.torque_fraction = 1.0;
    full.carried_3d = false;  // the load capacity does not use the carried forces
    const ForceProblem problem(net, hooks, steps, out.cuts, full);
    const LoadCapacityResult at_one =
        load_capacity(net, out.cuts, problem, Eigen::VectorXd::Zero(problem.columns()), load, progress);
    LoadFactorResult lf;
    lf.asked = options.load_factor;
    lf.at_plastic_limit = std::numeric_limits<double>::infinity();
    for (const LoadDirection& d : at_one.directions)
      if (d.multiple < lf.at_plastic_limit) {
        lf.at_plastic_limit = d.multiple;
        lf.weakest = d.name;
      }
    double f = options.min_torque_fraction;
    if (std::isfinite(lf.at_plastic_limit)) {
      const double wanted = lf.at_plastic_limit > 0 ? lf.asked / lf.at_plastic_limit : std::numeric_limits<double>::infinity();
      lf.limited = wanted > 1.0;
      f = std::clamp(wanted, options.min_torque_fraction, 1.0);
    }
    force_options.torque_fraction = f;
    out.load_factor = lf;
    at_plastic_limit = at_one;
  }
  out.torque_fraction = force_options.torque_fraction;
  out.forces = optimize_forces(net, hooks, steps, out.cuts, force_options, progress);

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

  if (options.deflection) {
    if (!(std::isfinite(options.deflection_limit) && options.deflection_limit > 0))
      throw InputError("deflection_limit must be a finite number of metres > 0");
    const auto d0 = std::chrono::steady_clock::now();
    DeflectionOptions d = options.deflection_options;
    d.bending_stiffness = options.rest.bending_stiffness;
    for (std::size_t w = 0; w < P; ++w) {
      const int wi = static_cast<int>(w);
      out.deflections.push_back(wire_deflection(net.wires[w], out.cuts[w], wire_loads(net, hooks, out.forces.forces, wi), d));
      const double m = out.deflections.back().max_out_of_plane;
      if (m > options.deflection_limit) {
        const auto [text, limit] = detail::versus(1000.0 * m, 1000.0 * options.deflection_limit, 2);
        out.warnings.push_back("wire '" + net.wires[w].name + "' deflects " + text + " mm out of its plane under its contact forces (at target vertex " +
                               std::to_string(out.deflections.back().max_out_of_plane_vertex) + "), more than " + limit +
                               " mm: lower the torque fraction or the load factor");
      }
    }
    out.deflection_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - d0).count();
  }

  bool rests_within = true;
  if (options.load_capacity_within > 0.0)
    for (const RestShapeResult& rest : out.rests)
      for (double a : rest.rest_angles) rests_within = rests_within && std::abs(a) <= options.load_capacity_within;
  if (options.load_capacity && rests_within && at_plastic_limit) {
    // The load capacity's LP does not depend on the pre-stress (a0 + δ >= 0 with δ free: only
    // x = a0 + δ enters, and a0 shifts the row bounds with it) and is homogeneous in (x, λ, t_max),
    // so at torque fraction f it is f times the one at the plastic limit, direction by direction
    // (load_capacity.hpp; test "the load capacity after the forces is f times the one at the
    // plastic limit" against the LPs solved at f with the forces' pre-stress).
    const auto t1 = std::chrono::steady_clock::now();
    const double f = force_options.torque_fraction;
    out.load_capacity = *at_plastic_limit;
    for (LoadDirection& d : out.load_capacity->directions) {
      d.multiple *= f;  // +inf stays +inf (f > 0)
      d.coefficients *= f;
      d.lp_iterations = 0;
      d.lp_rounds = 0;
    }
    out.load_capacity->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  } else if (options.load_capacity && rests_within) {
    ForceOptions plain = force_options;
    plain.carried_3d = false;  // the load capacity does not use the carried forces
    const ForceProblem problem(net, hooks, steps, out.cuts, plain);
    out.load_capacity = load_capacity(net, out.cuts, problem, out.forces.coefficients, load, progress);
  }
  if (out.load_capacity) {
    if (out.load_factor) {
      out.load_factor->reached = std::numeric_limits<double>::infinity();
      for (const LoadDirection& d : out.load_capacity->directions)
        out.load_factor->reached = std::min(out.load_factor->reached, d.multiple);
    }
  }
  return out;
}

}  // namespace wiresculpt
