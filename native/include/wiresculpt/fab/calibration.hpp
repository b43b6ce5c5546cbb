#pragma once
// Material and machine calibration (Sec. 5.1-5.2 of Miguel, Lepoutre, Bickel 2016): the bending
// stiffness k_b and the plastic-limit torque from the cantilever capture (Eq. 13, Fig. 10 left),
// the friction coefficient from the tilt capture (mu = tan alpha, Fig. 10 right), and the
// spring-back line of the bending machine (Sec. 5.1: measured = a * commanded + b). How to build
// the rigs and write the captures: docs/calibration.md.
//
// The rod model is the project's own (rest_shape.hpp, Eq. 9-10): the fitted k_b is the k_b that
// makes elastic_torque reproduce the measured torques, so rest shapes computed with it match the
// wire. Note that Eq. 10 as written (l̄ the half sum of the edges) gives t ≈ 2 k_b κ for small
// turns, i.e. a fitted k_b is about half the wire's E·I (docs/calibration.md).
//
// Units: SI inside (kg, m, rad, N·m). Grams and degrees are converted at the binding.
#include <vector>

#include "wiresculpt/fab/machine.hpp"
#include "wiresculpt/geometry.hpp"

namespace wiresculpt::fab {

// ---- cantilever: bending stiffness and plastic limit (Eq. 13) ----------------------------

/// One measured point of the cantilever capture (one CSV row).
struct CantileverRecord {
  double load = 0.0;        ///< kg hung at the tip (s = overhang); 0 = the initial shape
  bool loaded = true;       ///< true: measured under the load; false: after taking it off again
  double s = 0.0;           ///< m, arc length of the mark from the clamp's edge, in (0, overhang]
  double deflection = 0.0;  ///< m, downward distance of the mark from the clamp's horizontal line
  int line = 0;             ///< source line, used in messages (0: unknown)
};

struct CantileverOptions {
  double overhang = 0.30;        ///< m, free length from the clamp to the load; default 0.30 (paper)
  /// kg/m, the wire's mass per length, so its own weight adds to the external torque
  /// (ρ π d² / 4: 3 mm steel 0.0555). 0 ignores it (the paper's model). Default 0.
  double linear_density = 0.0;
  double gravity = 9.81;           ///< m/s²; default 9.81
  /// m: an unloaded shape "returns" unless its smoothed shape is farther than this from the
  /// smoothed initial shape (the 0 g frame) at some mark by more than 2 standard deviations of
  /// that difference under the marks' noise (the frames' pooled scatter about their polynomials):
  /// noise alone does not refuse a wire that came back. Default 0.001 (1 mm).
  double plastic_tolerance = 0.001;
  /// Highest power of s of the clamped polynomial w(s) = Σ_{k=2..d} c_k s^k each frame is
  /// smoothed with before its curvature is taken. Each frame starts from the cubic (the tip-loaded
  /// beam's exact small-deflection shape) and takes the next power only while it lowers the
  /// residual significantly (F > 10), up to this degree and to marks - 1 terms. Default 6.
  int smoothing_degree = 6;
  /// Remove the marks' noise from Σ g² (see CantileverFit::noise_share). Default false: with
  /// the adaptive smoothing the share is well below 1 % and the plain Eq. 13 is unbiased to
  /// ~0.1 % on synthetic captures (docs/calibration.md); use it for noisy photos of small loads.
  bool noise_correction = false;
  int nodes = 31;                 ///< evaluation nodes (uniform in s, clamp and tip included); default 31
  int simulation_segments = 150;  ///< edges of the simulated rod (fit check); default 150
};

/// One (load, state) frame of the capture, as fitted.
struct CantileverFrame {
  double load = 0.0;           ///< kg
  bool loaded = true;
  int line = 0;                ///< first source line of the frame
  bool used = false;           ///< in the k_b fit (loaded, 0 < load <= plastic load)
  std::vector<double> s;       ///< m, measured marks (sorted by s)
  std::vector<double> deflection;  ///< m, measured
  std::vector<double> x;       ///< m, horizontal position of each mark (from the smoothed shape)
  /// m: deflection of the rod model with the fitted k_b at each mark (used frames; else empty).
  std::vector<double> simulated;
  double position_rms = 0.0;   ///< m, RMS distance model-measured (used frames)
  /// m, unloaded frames: max over the marks of |w(s) - w_0(s)|, w and w_0 the smoothing polynomials
  /// (smoothing_degree) of this frame and of the 0 g frame: reading noise mostly averages out.
  double return_error = 0.0;
  double clamp_torque = 0.0;   ///< N·m, external torque at the clamp (Eq. 11) in this shape
};

struct CantileverFit {
  double bending_stiffness = 0.0;  ///< k_b, N·m² (Eq. 13, closed form)
  /// N·m: the clamp torque of the largest load whose unloaded shape returned (its loaded frame's
  /// lever arm; m g × overhang when that frame is missing). 0 when no unloaded frame was given.
  double max_torque = 0.0;
  double plastic_load = 0.0;       ///< kg, that load
  bool plastic_found = false;      ///< unloaded frames were given
  bool plastic_reached = false;    ///< some unloaded shape did not return (else max_torque is a lower bound)
  double lever_arm = 0.0;          ///< m, horizontal clamp-to-load distance used for max_torque
  double torque_rms = 0.0;         ///< N·m, sqrt(mean (t_int - t_ext)²) at the fitted k_b
  /// m: the marks' noise, the pooled RMS residual of the frames' smoothing polynomials.
  double mark_noise = 0.0;
  /// Σ_v Var(g_v) / Σ_v g_v²: the share of Σ g² (Eq. 13's normal equation) the marks' noise
  /// accounts for (a quality figure: above ~5 % the loads are too small for the photo's
  /// precision). With CantileverOptions::noise_correction, k_b = Σ g t / (Σ g² (1 - share))
  /// (share capped at 0.5), the estimate without the attenuation noisy curvatures cause.
  double noise_share = 0.0;
  double position_rms = 0.0;       ///< m, over every mark of every used frame (paper: 5.2 mm brass, 1.9 mm steel)
  double position_max = 0.0;       ///< m
  int frames_used = 0;
  std::vector<CantileverFrame> frames;  ///< by load, loaded before unloaded
};

/// Fits k_b (Eq. 13) and the plastic limit from a cantilever capture.
/// Frames are the rows grouped by (load, loaded). The initial shape is the 0 g frame. Each used
/// frame's marks are smoothed by a clamped polynomial (see options), resampled at `nodes`
/// uniform nodes, and at every node but the tip the internal torque of Eq. 10 with a straight
/// rest shape, elastic_torque(α_v, 0, l̄_v, k_b) = k_b g_v, is matched to the external torque
/// t_v = Σ_{k beyond v} (x_v - x_k) × f_k of the tip load (and the wire's weight): k_b = Σ g t / Σ g²
/// (with the marks' noise taken out of Σ g², see CantileverFit::noise_share).
/// The clamp node has the half edge as l̄ (the wire inside the clamp is straight). The fit is
/// then checked by simulate_cantilever at every used frame (position RMS).
/// Throws InputError naming the line for bad records (s outside (0, overhang], a frame with fewer
/// than 3 marks, repeated marks, a negative load, no loaded frame with a load, a first load that
/// already deforms the wire).
CantileverFit fit_cantilever(const std::vector<CantileverRecord>& records, const CantileverOptions& options = {});

/// The rod model's cantilever: an inextensible discrete elastic rod (Eq. 9 energy, straight
/// rest shape) of `segments` equal edges, clamped horizontally at the origin along +x, under a
/// downward tip force `tip_force` (N) and its own weight `weight_per_length` (N/m, lumped at the
/// vertices). Solved by Newton on the total potential energy with load continuation.
/// Returns #segments+1 points (m, y up). Throws SolverError when Newton does not converge.
Polyline2 simulate_cantilever(double bending_stiffness, double length, double tip_force,
                              double weight_per_length = 0.0, int segments = 150);

// ---- tilt: friction ------------------------------------------------------------------------

struct FrictionFit {
  double friction = 0.0;  ///< μ = mean over repeats of tan α
  double spread = 0.0;    ///< sample standard deviation of tan α (0 for one repeat)
  double min = 0.0, max = 0.0;  ///< smallest and largest tan α
  double mean_angle = 0.0;      ///< rad
  int repeats = 0;
};

/// μ = tan α averaged over the repeats (Sec. 5.2). `angles` in radians, each in (0, π/2);
/// `lines` (optional, same size) name the rows in messages. Throws InputError.
FrictionFit fit_friction(const std::vector<double>& angles, const std::vector<int>& lines = {});

// ---- spring-back (Sec. 5.1) ----------------------------------------------------------------

struct SpringbackFit {
  double a = 1.0;             ///< slope (measured per commanded)
  double b = 0.0;             ///< offset, rad
  double rms = 0.0;           ///< rad, RMS of measured - (a commanded + b)
  double max_residual = 0.0;  ///< rad, largest |residual|
  int samples = 0;
};

/// Least-squares line measured = a · commanded + b through |angles| (rad). Both angles of a row
/// must have the same sign (a bend to the other side is fitted by its magnitude). Needs two
/// different commanded angles and a > 0. Throws InputError naming the line.
SpringbackFit fit_springback(const std::vector<double>& commanded, const std::vector<double>& measured,
                             const std::vector<int>& lines = {});

/// `profile` with the fit's a and b (validated).
MachineProfile with_springback(MachineProfile profile, const SpringbackFit& fit);

}  // namespace wiresculpt::fab
