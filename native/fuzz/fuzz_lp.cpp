// libFuzzer target: the force LP / GLPK path. Arbitrary small LPs (raw doubles: NaN, inf, 1e±300,
// denormals and ordinary numbers mixed) through solve_lp and the warm-started EqualityLp, and the
// force LP of a two-wire network whose geometry and material numbers come from the input through
// optimize_forces. GLPK must never abort the process: every input gives a status or an Error.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <limits>

#include "lp.hpp"  // native/src: the core's LP layer
#include "wiresculpt/error.hpp"
#include "wiresculpt/forces.hpp"
#include "wiresculpt/rest_shape.hpp"

using namespace wiresculpt;

namespace {

// A double that is often ordinary and sometimes extreme.
double number(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0: return in.ConsumeIntegralInRange<int>(-3, 3);
    case 1: return std::ldexp(in.ConsumeIntegralInRange<int>(-8, 8), in.ConsumeIntegralInRange<int>(-1100, 1100));
    case 2: {
      static const double special[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                       -std::numeric_limits<double>::infinity(), 1e300, -1e300, 1e-300, 5e-324, 0.0};
      return special[in.ConsumeIntegralInRange<int>(0, 7)];
    }
    default: return in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
  }
}

void fuzz_solve_lp(FuzzedDataProvider& in) {
  detail::LinearProgram lp;
  const int rows = in.ConsumeIntegralInRange<int>(0, 4), cols = in.ConsumeIntegralInRange<int>(0, 4);
  lp.maximise = in.ConsumeBool();
  for (int j = 0; j < cols; ++j) {
    lp.obj.push_back(number(in));
    lp.col_lo.push_back(in.ConsumeBool() ? -std::numeric_limits<double>::infinity() : number(in));
    lp.col_hi.push_back(in.ConsumeBool() ? std::numeric_limits<double>::infinity() : number(in));
  }
  for (int r = 0; r < rows; ++r) {
    lp.row_lo.push_back(in.ConsumeBool() ? -std::numeric_limits<double>::infinity() : number(in));
    lp.row_hi.push_back(in.ConsumeBool() ? std::numeric_limits<double>::infinity() : number(in));
  }
  const int entries = in.ConsumeIntegralInRange<int>(0, 10);
  for (int t = 0; t < entries; ++t) {
    lp.tri_row.push_back(in.ConsumeIntegralInRange<int>(-1, rows));  // out of range included
    lp.tri_col.push_back(in.ConsumeIntegralInRange<int>(-1, cols));
    lp.tri_val.push_back(number(in));
  }
  const detail::LpSolution sol = detail::solve_lp(lp);
  if (sol.status == detail::LpSolution::optimal && sol.x.size() != static_cast<std::size_t>(cols)) __builtin_trap();
  if (sol.status == detail::LpSolution::failed && sol.reason.empty()) __builtin_trap();
}

void fuzz_equality_lp(FuzzedDataProvider& in) {
  const int rows = in.ConsumeIntegralInRange<int>(1, 3), cols = in.ConsumeIntegralInRange<int>(1, 4);
  std::vector<int> tr, tc;
  std::vector<double> tv, cost;
  const int entries = in.ConsumeIntegralInRange<int>(0, 8);
  for (int t = 0; t < entries; ++t) {
    tr.push_back(in.ConsumeIntegralInRange<int>(0, rows - 1));
    tc.push_back(in.ConsumeIntegralInRange<int>(0, cols - 1));
    tv.push_back(number(in));
  }
  for (int j = 0; j < cols; ++j) cost.push_back(std::abs(number(in)));
  detail::EqualityLp lp(rows, cols, tr, tc, tv, cost);
  for (int k = in.ConsumeIntegralInRange<int>(1, 3); k > 0; --k) {
    std::vector<double> b;
    for (int r = 0; r < rows; ++r) b.push_back(number(in));
    lp.solve(b);
  }
}

void fuzz_forces(FuzzedDataProvider& in) {
  // Two wires on perpendicular planes meeting at one crossing, their kinks and the material's
  // numbers from the input (the density 1e-300 kind of number included).
  const double s = std::abs(number(in)) + 1e-3, h = number(in);
  WireSpec a, b;
  a.name = "A";
  a.closed = false;
  a.plane = Plane::make(Vec3::Zero(), Vec3::UnitX());
  a.points = {Vec3(0, -s, h), Vec3(0, 0, 0), Vec3(0, s, h)};
  b.name = "B";
  b.closed = false;
  b.plane = Plane::make(Vec3::Zero(), Vec3::UnitY());
  b.points = {Vec3(-s, 0, -h), Vec3(0, 0, 0), Vec3(s, 0, -h)};
  Network net;
  net.wires = {a, b};
  Crossing x;
  x.wires = {0, 1};
  x.vertices = {1, 1};
  x.point = Vec3::Zero();
  net.crossings = {x};
  ForceOptions o;
  o.friction = number(in);
  o.max_torque = number(in);
  o.torque_fraction = number(in);
  o.assembly_weight = number(in);
  o.algorithm = ForceAlgorithm::lp;
  const int hook = in.ConsumeIntegralInRange<int>(-1, 1);
  const auto cuts = choose_cuts(net);
  optimize_forces(net, {hook}, {{0, 1}}, cuts, o);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  try {
    switch (in.ConsumeIntegralInRange<int>(0, 2)) {
      case 0: fuzz_solve_lp(in); break;
      case 1: fuzz_equality_lp(in); break;
      default: fuzz_forces(in); break;
    }
  } catch (const Error&) {
  }
  return 0;
}
