#pragma once
// Triangular solves with a Cholesky factor L (column-major, lower triangular), for the target
// shape's small QPs (n of 4 to 60): the very floating-point operations, in the very order, that
// Eigen 3.4's triangular_solve_vector performs for L.solveInPlace(x) and L.transpose().solveInPlace(x)
// with SSE2's two-double packets (panels of EIGEN_TUNE_TRIANGULAR_PANEL_WIDTH rows, the panels'
// matrix-vector products and the in-panel dot products summed as Eigen sums them), without its
// dispatch, alignment and blocking logic, which at these sizes cost more than the arithmetic
// (docs/method-target-shape.md). So every result is Eigen's to the
// bit. Where Eigen's packets are not SSE2's (a build for AVX or FMA, another processor), or its panel
// width or version differ, these call Eigen itself. native/tests/test_small_triangular.cpp compares the two.

#include <Eigen/Core>

namespace wiresculpt::detail {

/// Whether the written-out solves below reproduce this build's Eigen (else they call it).
inline constexpr bool kTriangularReplica =
#if defined(EIGEN_VECTORIZE_SSE2) && !defined(EIGEN_VECTORIZE_FMA)  // x86's packets; no fused multiply-add
    true &&
#else
    false &&
#endif
    Eigen::internal::packet_traits<double>::size == 2 &&
                                           Eigen::internal::packet_traits<double>::Vectorizable &&
                                           EIGEN_TUNE_TRIANGULAR_PANEL_WIDTH == 8 && EIGEN_WORLD_VERSION == 3 &&
                                           EIGEN_MAJOR_VERSION == 4;

/// x ← L⁻¹ x (L n×n, column-major with leading dimension ld, only its lower triangle read).
inline void lower_solve_in_place(const double* L, Eigen::Index ld, Eigen::Index n, double* x) {
  if constexpr (!kTriangularReplica) {
    Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>> m(L, n, n, Eigen::OuterStride<>(ld));
    Eigen::Map<Eigen::VectorXd> v(x, n);
    m.triangularView<Eigen::Lower>().solveInPlace(v);
    return;
  }
  constexpr Eigen::Index panel = 8;
  for (Eigen::Index pi = 0; pi < n; pi += panel) {
    const Eigen::Index width = n - pi < panel ? n - pi : panel;
    const Eigen::Index end = pi + width;
    for (Eigen::Index k = 0; k < width; ++k) {
      const Eigen::Index i = pi + k;
      if (x[i] != 0.0) {
        x[i] /= L[i * ld + i];
        const double xi = x[i];
        const double* col = L + i * ld;
        for (Eigen::Index j = i + 1; j < end; ++j) x[j] -= xi * col[j];
      }
    }
    // The rows below the panel, less the panel's columns times its solved entries (Eigen's
    // column-major matrix-vector product: each row's products summed from 0 in column order).
    for (Eigen::Index r = end; r < n; ++r) {
      double acc = 0.0;
      for (Eigen::Index j = pi; j < end; ++j) acc += L[j * ld + r] * x[j];
      x[r] += -acc;
    }
  }
}

/// x ← L⁻ᵀ x (the same L).
inline void lower_transpose_solve_in_place(const double* L, Eigen::Index ld, Eigen::Index n, double* x) {
  if constexpr (!kTriangularReplica) {
    Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>> m(L, n, n, Eigen::OuterStride<>(ld));
    Eigen::Map<Eigen::VectorXd> v(x, n);
    // Lᵀ's upper view (what triangularView<Lower>().transpose() is): clang rejects the
    // transpose of a read-only map's triangular view (Eigen 3.4's lvalue check)
    m.transpose().triangularView<Eigen::Upper>().solveInPlace(v);
    return;
  }
  // Row i of Lᵀ is column i of L: u(i, j) = L[i * ld + j].
  constexpr Eigen::Index panel = 8;
  for (Eigen::Index pi = n; pi > 0; pi -= panel) {
    const Eigen::Index width = pi < panel ? pi : panel;
    const Eigen::Index start = pi - width;
    if (pi < n) {
      // The panel's rows less their products with the entries solved after it (Eigen's row-major
      // matrix-vector product: two lanes over pairs of columns, added, then the odd column).
      const Eigen::Index cols = n - pi;
      for (Eigen::Index i = start; i < pi; ++i) {
        const double* u = L + i * ld + pi;
        const double* y = x + pi;
        double c0 = 0.0, c1 = 0.0;
        Eigen::Index j = 0;
        for (; j + 2 <= cols; j += 2) {
          c0 += u[j] * y[j];
          c1 += u[j + 1] * y[j + 1];
        }
        double cc = c0 + c1;
        for (; j < cols; ++j) cc += u[j] * y[j];
        x[i] += -cc;
      }
    }
    for (Eigen::Index k = 0; k < width; ++k) {
      const Eigen::Index i = pi - k - 1, s = i + 1;
      if (k > 0) {
        // Eigen's vectorised sum of the k products u(i, s + j) x[s + j]: two packets of two lanes
        // over groups of four, added, then a last pair, the two lanes, and an odd last product.
        const double* u = L + i * ld + s;
        const double* y = x + s;
        double sum;
        if (k >= 2) {
          double a0 = u[0] * y[0], a1 = u[1] * y[1];
          const Eigen::Index pairs_end = (k / 2) * 2, quads_end = (k / 4) * 4;
          if (k >= 4) {
            double b0 = u[2] * y[2], b1 = u[3] * y[3];
            for (Eigen::Index j = 4; j < quads_end; j += 4) {
              a0 += u[j] * y[j];
              a1 += u[j + 1] * y[j + 1];
              b0 += u[j + 2] * y[j + 2];
              b1 += u[j + 3] * y[j + 3];
            }
            a0 += b0;
            a1 += b1;
            if (pairs_end > quads_end) {
              a0 += u[quads_end] * y[quads_end];
              a1 += u[quads_end + 1] * y[quads_end + 1];
            }
          }
          sum = a0 + a1;
          if (pairs_end < k) sum += u[k - 1] * y[k - 1];
        } else {
          sum = u[0] * y[0];
        }
        x[i] -= sum;
      }
      if (x[i] != 0.0) x[i] /= L[i * ld + i];
    }
  }
}

}  // namespace wiresculpt::detail
