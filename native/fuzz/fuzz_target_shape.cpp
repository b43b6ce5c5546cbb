// libFuzzer target: optimize_target_shape's options and input. Every numeric option takes
// ordinary, extreme (2^31-1, 1e-12, 1e300), NaN and inf values; each input must give a result or
// an InputError/SolverError, never a hang (window 2^31-1 overflowed 4*window), a memory blow-up
// (spacing 1e-12) or a crash. Budgets keep each run short: max_seconds and max_iterations are
// capped here so the fuzzer looks for crashes, not for slow convergence.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "wiresculpt/error.hpp"
#include "wiresculpt/target_shape.hpp"

using namespace wiresculpt;

namespace {

double number(FuzzedDataProvider& in, double typical) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: {
      static const double special[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                       -1.0, 0.0, 1e-12, 1e300, 2147483647.0, 5e-324};
      return special[in.ConsumeIntegralInRange<int>(0, 7)];
    }
    case 1: return typical * std::ldexp(1.0, in.ConsumeIntegralInRange<int>(-6, 6));
    default: return typical;
  }
}

int integer(FuzzedDataProvider& in, int typical) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: {
      static const int special[] = {std::numeric_limits<int>::max(), std::numeric_limits<int>::min(), -1, 0, 1, 3, 4};
      return special[in.ConsumeIntegralInRange<int>(0, 6)];
    }
    case 1: return in.ConsumeIntegralInRange<int>(-10, 40);
    default: return typical;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  TargetShapeOptions o;
  o.min_segment = number(in, 0.015);
  o.max_bend = number(in, 2.0);
  o.spacing = in.ConsumeBool() ? 0.0 : number(in, 0.02);
  o.regularization = number(in, 1e-3);
  o.friction = number(in, 0.32);
  o.ftol_rel = number(in, 1e-12);
  o.xtol_rel = number(in, 1e-10);
  o.constraint_tol = number(in, 1e-10);
  o.max_iterations = std::min(integer(in, 300), 400);
  o.window = integer(in, 8);
  o.sweep_tol = number(in, 1e-7);
  o.max_sweeps = integer(in, 20);
  o.max_seconds = std::min(number(in, 0.5), 0.5);
  o.model_size = number(in, 0.0);
  o.angle_tolerance = number(in, 1e-6);
  o.length_tolerance = number(in, 1e-6);
  static const TargetShapeAlgorithm algorithms[] = {TargetShapeAlgorithm::slsqp, TargetShapeAlgorithm::auglag_lbfgs,
                                                     TargetShapeAlgorithm::ccsaq, TargetShapeAlgorithm::mma,
                                                     TargetShapeAlgorithm::sqp};
  o.algorithm = algorithms[in.ConsumeIntegralInRange<int>(0, 4)];
  // A circle (or an arc) of n points, its radius from the input too (1e9 m included).
  const bool closed = in.ConsumeBool();
  const int n = in.ConsumeIntegralInRange<int>(0, 64);
  const double radius = number(in, 0.1);
  Polyline2 contour;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * 3.141592653589793 * i / std::max(n, 1);
    contour.emplace_back(radius * std::cos(t), radius * std::sin(t));
  }
  std::vector<TargetCrossing> crossings;
  for (int k = in.ConsumeIntegralInRange<int>(0, 3); k > 0; --k) {
    TargetCrossing x;
    x.vertex = in.ConsumeIntegralInRange<int>(-1, n);
    x.bisector = Vec2(number(in, 1.0), number(in, 0.0));
    x.contact_angle = number(in, 2.0);
    x.active = in.ConsumeBool();
    crossings.push_back(x);
  }
  try {
    const TargetShapeResult r = optimize_target_shape(contour, closed, crossings, o);
    if (r.crossings.size() != crossings.size()) __builtin_trap();
  } catch (const Error&) {
  }
  return 0;
}
