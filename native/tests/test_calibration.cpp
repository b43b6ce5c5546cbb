// Calibration (Sec. 5.1-5.2, Eq. 13): synthetic captures made with the project's own rod model
// (simulate_cantilever, Eq. 9-10) from a known k_b plus 0.2 mm of noise (fixed seed) must give
// that k_b back within 2 %, the plastic limit at the known onset, spring-back lines their slope
// and offset, and bad captures an error naming the line.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/calibration.hpp"
#include "wiresculpt/rest_shape.hpp"

using namespace wiresculpt;
using namespace wiresculpt::fab;
using Catch::Matchers::Contains;

namespace {

constexpr double g = 9.81;

/// Deflection (m, down) of a simulated rod at arc length s (linear on its equal edges).
double deflection_at(const Polyline2& rod, double length, double s) {
  const int m = static_cast<int>(rod.size()) - 1;
  const double h = length / m;
  const int k = std::min(m - 1, static_cast<int>(std::floor(s / h)));
  const double t = (s - k * h) / h;
  return -((1 - t) * rod[k].y() + t * rod[k + 1].y());
}

struct Synthetic {
  double kb = 0.73;
  double overhang = 0.30;
  double linear_density = 0.0;
  double noise = 0.0002;        // m
  double onset = 0.6;           // kg: the largest load that still returns
  int marks = 10;
  unsigned seed = 2016;
};

/// The Fig. 10 capture: 0..1000 g in 100 g steps, loaded and unloaded each; loads above the
/// onset leave a permanent set (a clamp kink) growing with the load.
std::vector<CantileverRecord> capture(const Synthetic& c) {
  std::mt19937 rng(c.seed);
  std::normal_distribution<double> noise(0.0, c.noise);
  std::vector<CantileverRecord> rows;
  int line = 2;  // after the header
  const Polyline2 rest = simulate_cantilever(c.kb, c.overhang, 0.0, c.linear_density * g, 300);
  for (int step = 0; step <= 10; ++step) {
    const double load = 0.1 * step;
    const double set_angle = load > c.onset + 1e-9 ? 0.01 * (load - c.onset) / 0.1 : 0.0;  // rad at the clamp
    const Polyline2 rod = simulate_cantilever(c.kb, c.overhang, load * g, c.linear_density * g, 300);
    for (bool loaded : {true, false}) {
      if (step == 0 && !loaded) continue;
      for (int i = 1; i <= c.marks; ++i) {
        const double s = c.overhang * i / c.marks;
        const double w = deflection_at(loaded ? rod : rest, c.overhang, s) + set_angle * s;
        rows.push_back({load, loaded, s, w + noise(rng), line++});
      }
    }
  }
  return rows;
}

}  // namespace

TEST_CASE("calibration: the simulated cantilever bends as the textbook beam of stiffness k_b", "[calibration]") {
  // With the Voronoi length l̄ = |e_{v-1}| + |e_v|, Eq. 10 gives t ≈ k_b κ at small turns: a beam
  // of E I = k_b, tip deflection P L³ / (3 E I).
  const double kb = 0.73, L = 0.3, P = 0.05;
  const Polyline2 rod = simulate_cantilever(kb, L, P, 0.0, 200);
  const double expected = P * L * L * L / (3 * kb);  // the textbook cantilever, E·I = k_b
  CHECK(-rod.back().y() == Approx(expected).epsilon(0.005));
  // Every edge keeps its length (inextensible) and the rod is in torque equilibrium (Eq. 10 = 11).
  for (std::size_t k = 0; k + 1 < rod.size(); ++k) CHECK((rod[k + 1] - rod[k]).norm() == Approx(L / 200).epsilon(1e-12));
  const Polyline2 heavy = simulate_cantilever(kb, L, 9.81, 0.5, 100);
  const double h = L / 100;
  double prev_theta = 0.0;
  for (int v = 0; v < 100; ++v) {
    const Vec2 e = heavy[v + 1] - heavy[v];
    const double theta = std::atan2(e.y(), e.x());
    double t_ext = (heavy[v].x() - heavy[100].x()) * -9.81;  // (x_v - x_tip) × (0, -P)
    for (int k = v + 1; k <= 100; ++k) t_ext += (heavy[v].x() - heavy[k].x()) * -(0.5 * h * (k == 100 ? 0.5 : 1.0));
    CHECK(elastic_torque(theta - prev_theta, 0.0, v == 0 ? voronoi_length(0.0, h) : voronoi_length(h, h), kb) ==
          Approx(t_ext).margin(1e-9));
    prev_theta = theta;
  }
}

TEST_CASE("calibration: k_b from a noisy synthetic steel capture within 2 %", "[calibration]") {
  Synthetic c;
  const CantileverFit fit = fit_cantilever(capture(c));
  CHECK(fit.bending_stiffness == Approx(c.kb).epsilon(0.02));
  CHECK(fit.frames_used == 6);  // 100 .. 600 g
  // The model reproduces the capture to the noise level.
  CHECK(fit.position_rms < 2.5 * c.noise);
  CHECK(fit.position_rms > 0.3 * c.noise);
  // Plastic limit: 600 g, torque m g × the loaded shape's lever arm.
  CHECK(fit.plastic_found);
  CHECK(fit.plastic_reached);
  CHECK(fit.plastic_load == Approx(0.6));
  CHECK(fit.lever_arm < c.overhang);
  CHECK(fit.lever_arm > 0.95 * c.overhang);
  CHECK(fit.max_torque == Approx(0.6 * g * fit.lever_arm).epsilon(1e-6));
  // The smoothing's residual is the marks' noise; the noise hardly inflates Σ g².
  CHECK(fit.mark_noise == Approx(c.noise).epsilon(0.3));
  CHECK(fit.noise_share < 0.02);
  CantileverOptions corrected;
  corrected.noise_correction = true;
  CHECK(fit_cantilever(capture(c), corrected).bending_stiffness == Approx(c.kb).epsilon(0.02));
  // Without noise the fit is the model's own k_b (the smoothing's bias is far below 2 %).
  c.noise = 0.0;
  CHECK(fit_cantilever(capture(c)).bending_stiffness == Approx(c.kb).epsilon(0.003));
}

TEST_CASE("calibration: large deflections (50 cm of steel, every load elastic)", "[calibration]") {
  // (50 cm of brass under 1 kg hangs so far that the fit's smoothing no longer follows the shape
  // to the noise level, though k_b stays within 1 %: docs/calibration.md keeps captures at 30 cm.)
  Synthetic c;
  c.kb = 0.73;
  c.overhang = 0.5;
  c.onset = 2.0;
  c.marks = 12;
  CantileverOptions o;
  o.overhang = 0.5;
  const CantileverFit fit = fit_cantilever(capture(c), o);
  CHECK(fit.bending_stiffness == Approx(c.kb).epsilon(0.01));
  CHECK(fit.position_rms < 2 * c.noise);
  // The 1000 g frame hangs far below the beam's small-deflection range.
  const CantileverFrame& heaviest = fit.frames[fit.frames.size() - 2];  // 1000 g loaded, then unloaded
  CHECK(heaviest.load == Approx(1.0));
  CHECK(heaviest.deflection.back() > 0.1);
}

TEST_CASE("calibration: brass, other seeds, the wire's own weight", "[calibration]") {
  for (unsigned seed : {1u, 7u, 42u}) {
    Synthetic c;
    c.kb = 0.42;
    c.onset = 0.4;
    c.seed = seed;
    c.linear_density = 8500 * std::numbers::pi * 0.0015 * 0.0015;
    CantileverOptions o;
    o.linear_density = c.linear_density;
    const CantileverFit fit = fit_cantilever(capture(c), o);
    CHECK(fit.bending_stiffness == Approx(c.kb).epsilon(0.02));
    CHECK(fit.plastic_load == Approx(0.4));
    CHECK(fit.position_rms < 2.5 * c.noise);
    // The clamp torque includes the wire's weight: m g x_tip + ~ρ g L²/2.
    CHECK(fit.max_torque > 0.4 * g * fit.lever_arm);
  }
}

TEST_CASE("calibration: every load returns: the plastic limit is a lower bound", "[calibration]") {
  Synthetic c;
  c.onset = 2.0;
  const CantileverFit fit = fit_cantilever(capture(c));
  CHECK(fit.plastic_found);
  CHECK_FALSE(fit.plastic_reached);
  CHECK(fit.plastic_load == Approx(1.0));
  CHECK(fit.frames_used == 10);
  CHECK(fit.bending_stiffness == Approx(c.kb).epsilon(0.02));
  // No unloaded rows: no plastic limit, every loaded frame is used.
  std::vector<CantileverRecord> loaded;
  for (const CantileverRecord& r : capture(c))
    if (r.loaded) loaded.push_back(r);
  const CantileverFit only = fit_cantilever(loaded);
  CHECK_FALSE(only.plastic_found);
  CHECK(only.max_torque == 0.0);
  CHECK(only.bending_stiffness == Approx(c.kb).epsilon(0.02));
}

TEST_CASE("calibration: bad cantilever captures name the line", "[calibration]") {
  Synthetic c;
  std::vector<CantileverRecord> rows = capture(c);
  SECTION("a frame with a single mark") {
    std::vector<CantileverRecord> few{{0.0, true, 0.1, 0.0, 2}, {0.0, true, 0.2, 0.0, 3}, {0.0, true, 0.3, 0.0, 4},
                                      {0.1, true, 0.3, 0.004, 5}};
    CHECK_THROWS_WITH(fit_cantilever(few), Contains("line 5") && Contains("1 mark"));
  }
  SECTION("a mark beyond the overhang") {
    rows[12].s = 0.45;
    CHECK_THROWS_WITH(fit_cantilever(rows), Contains("line 14") && Contains("s_m"));
  }
  SECTION("a negative load") {
    rows[3].load = -0.1;
    CHECK_THROWS_WITH(fit_cantilever(rows), Contains("line 5") && Contains("load_g"));
  }
  SECTION("the first load already deforms the wire") {
    c.onset = 0.05;
    CHECK_THROWS_WITH(fit_cantilever(capture(c)), Contains("did not return") && Contains("100 g"));
  }
  SECTION("no rows") { CHECK_THROWS_AS(fit_cantilever({}), InputError); }
}

TEST_CASE("calibration: friction is the mean tan of the tilt angles", "[calibration]") {
  const double deg = std::numbers::pi / 180;
  const FrictionFit f = fit_friction({17.0 * deg, 18.0 * deg, 19.0 * deg});
  CHECK(f.friction == Approx((std::tan(17 * deg) + std::tan(18 * deg) + std::tan(19 * deg)) / 3));
  CHECK(f.repeats == 3);
  CHECK(f.spread == Approx(0.0193).margin(0.0002));
  CHECK(f.min == Approx(std::tan(17 * deg)));
  CHECK(fit_friction({std::atan(0.32)}).friction == Approx(0.32));
  CHECK_THROWS_WITH(fit_friction({10 * deg, 95 * deg}, {2, 3}), Contains("line 3") && Contains("angle_deg"));
  CHECK_THROWS_AS(fit_friction({}), InputError);
}

TEST_CASE("calibration: spring-back line from a synthetic table", "[calibration]") {
  const double deg = std::numbers::pi / 180, a = 0.92, b = -1.5 * deg;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.1 * deg);
  std::vector<double> commanded, measured, exact;
  for (int k = 1; k <= 30; ++k) {
    const double c = (k % 2 ? 1 : -1) * 5.0 * k * deg;  // both bend directions
    commanded.push_back(c);
    exact.push_back(std::copysign(a * std::abs(c) + b, c));
    measured.push_back(exact.back() + std::copysign(noise(rng), c));
  }
  const SpringbackFit clean = fit_springback(commanded, exact);
  CHECK(clean.a == Approx(a).epsilon(1e-12));
  CHECK(clean.b == Approx(b).epsilon(1e-10));
  CHECK(clean.rms < 1e-12);
  const SpringbackFit fit = fit_springback(commanded, measured);
  CHECK(fit.a == Approx(a).margin(0.003));
  CHECK(fit.b == Approx(b).margin(0.15 * deg));
  CHECK(fit.rms == Approx(0.1 * deg).epsilon(0.4));
  CHECK(fit.max_residual < 0.4 * deg);
  CHECK(fit.samples == 30);
  const MachineProfile p = with_springback(MachineProfile{}, fit);
  CHECK(p.springback_a == fit.a);
  CHECK(p.springback_b == fit.b);
  CHECK_THROWS_WITH(fit_springback({10 * deg}, {9 * deg}, {2}), Contains("two"));
  CHECK_THROWS_WITH(fit_springback({10 * deg, 20 * deg}, {9 * deg, -18 * deg}, {2, 3}), Contains("line 3"));
  CHECK_THROWS_WITH(fit_springback({10 * deg, 10 * deg}, {9 * deg, 9 * deg}), Contains("same commanded"));
  CHECK_THROWS_WITH(fit_springback({10 * deg, 20 * deg}, {20 * deg, 10 * deg}), Contains("do not grow"));
  // 1e300 deg overflowed the fit's sums into "every row has the same commanded angle".
  CHECK_THROWS_WITH(fit_springback({1e300 * deg, 2e300 * deg}, {1e300 * deg, 2e300 * deg}, {2, 3}),
                    Contains("line 2: the commanded angle (1e+300 deg) is beyond a full turn (360 deg)"));
  CHECK_THROWS_WITH(fit_springback({10 * deg, 20 * deg}, {9 * deg, 400 * deg}, {2, 3}),
                    Contains("line 3: the measured angle (400 deg) is beyond a full turn"));
}
