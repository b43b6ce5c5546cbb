// wiresculpt_bench: measures the native stages on generated inputs and prints one JSON document.
// Times are medians of repeated runs (steady_clock, single thread). Run through scripts/bench,
// which writes docs/performance.md; no test asserts a time.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "wiresculpt/shapes.hpp"
#include "wiresculpt/slicing.hpp"

using namespace wiresculpt;

namespace {

double median_seconds(int repeats, const std::function<void()>& work) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    work();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Ten planes through a sphere of radius 1: five horizontal, five through the axis.
std::vector<Plane> ten_planes() {
  std::vector<Plane> planes;
  for (int k = 0; k < 5; ++k) planes.push_back(Plane::make({0, 0, -0.8 + 0.4 * k}, {0, 0, 1}));
  for (int k = 0; k < 5; ++k) {
    const double a = std::numbers::pi * k / 5;
    planes.push_back(Plane::make({0, 0, 0}, {std::cos(a), std::sin(a), 0.1}));
  }
  return planes;
}

std::string slicing_case(int segments) {
  const RawMesh raw = uv_sphere(1.0, segments, segments / 2);
  const auto planes = ten_planes();
  const int repeats = raw.F.rows() > 500000 ? 5 : 9;
  TriMesh mesh;
  const double prepare = median_seconds(repeats, [&] { mesh = prepare_mesh(raw.V, raw.F); });
  std::size_t contours = 0;
  const double cut = median_seconds(repeats, [&] {
    contours = 0;
    for (const Plane& p : planes) contours += slice(mesh, p).size();
  });
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "{\"triangles\": %lld, \"vertices\": %lld, \"planes\": %zu, \"contours\": %zu, "
                "\"prepare_seconds\": %.6f, \"slice_seconds\": %.6f, \"repeats\": %d}",
                static_cast<long long>(raw.F.rows()), static_cast<long long>(raw.V.rows()), planes.size(),
                contours, prepare, cut, repeats);
  return buf;
}

}  // namespace

int main() {
  std::printf("{\n \"version\": \"%s\",\n \"slicing\": [", WIRESCULPT_VERSION);
  const int sizes[] = {100, 316, 1000};  // about 10k, 100k and 1M triangles
  for (std::size_t i = 0; i < std::size(sizes); ++i) {
    std::printf("%s\n  %s", i ? "," : "", slicing_case(sizes[i]).c_str());
    std::fflush(stdout);
  }
  std::printf("\n ]\n}\n");
  return 0;
}
