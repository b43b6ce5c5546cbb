// libFuzzer target: arbitrary wires through build_network and layering. Planes and points come
// from small integers so wires touch, coincide, cross at one point and run along each other.
#include <fuzzer/FuzzedDataProvider.h>

#include "wiresculpt/error.hpp"
#include "wiresculpt/layering.hpp"
#include "wiresculpt/network.hpp"

using namespace wiresculpt;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  const int count = in.ConsumeIntegralInRange<int>(1, 5);
  std::vector<WireSpec> wires;
  try {
    for (int w = 0; w < count; ++w) {
      Vec3 origin, normal;
      for (int k = 0; k < 3; ++k) origin[k] = 0.05 * in.ConsumeIntegralInRange<int>(-2, 2);
      for (int k = 0; k < 3; ++k) normal[k] = in.ConsumeIntegralInRange<int>(-2, 2);
      WireSpec spec;
      spec.name = "w" + std::to_string(w);
      spec.plane = Plane::make(origin, normal, spec.name);
      spec.closed = in.ConsumeBool();
      const int n = in.ConsumeIntegralInRange<int>(0, 12);
      for (int i = 0; i < n; ++i) {
        const Vec2 q(0.02 * in.ConsumeIntegralInRange<int>(-10, 10), 0.02 * in.ConsumeIntegralInRange<int>(-10, 10));
        spec.points.push_back(spec.plane.to_3d(q));
      }
      wires.push_back(std::move(spec));
    }
    const Network net = build_network(wires);
    LayeringOptions options;
    options.max_nodes = 300;  // bounded: the fuzzer looks for crashes, not for slow searches
    options.max_step_crossings = 8;
    const LayeringResult r = layering(net, options);
    if (r.hooks.size() != net.crossings.size()) __builtin_trap();
  } catch (const Error&) {
  }
  return 0;
}
