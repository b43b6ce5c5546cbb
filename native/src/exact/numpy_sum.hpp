#pragma once
// The sum of an array of doubles added in numpy's order, so that a length the native code computes
// is to the bit the one the add-on's Python computes with numpy (README.md).
//
// numpy's add.reduce of a contiguous float64 array (pairwise_sum in its loops, unchanged since
// numpy 1.9): the array in chunks of its 8192-element buffer added to 0.0 one after the other;
// within a chunk, fewer than 8 values one by one, up to 128 in eight running sums (value k into
// sum k mod 8) joined as ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)) and the last n mod 8
// added one by one, longer runs split in two halves (the first a multiple of 8 long) summed alike.
#include <algorithm>
#include <cstddef>

namespace wiresculpt::detail {

inline double numpy_pairwise_sum(const double* a, std::size_t n) {
  if (n < 8) {
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) sum += a[i];
    return sum;
  }
  if (n <= 128) {
    double r[8];
    for (std::size_t k = 0; k < 8; ++k) r[k] = a[k];
    std::size_t i = 8;
    for (; i < n - n % 8; i += 8)
      for (std::size_t k = 0; k < 8; ++k) r[k] += a[i + k];
    double sum = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    for (; i < n; ++i) sum += a[i];
    return sum;
  }
  std::size_t half = n / 2;
  half -= half % 8;
  return numpy_pairwise_sum(a, half) + numpy_pairwise_sum(a + half, n - half);
}

inline double numpy_sum(const double* a, std::size_t n) {
  constexpr std::size_t kBuffer = 8192;  // numpy's default buffer size, in elements
  double sum = 0.0;
  for (std::size_t lo = 0; lo < n; lo += kBuffer) sum += numpy_pairwise_sum(a + lo, std::min(kBuffer, n - lo));
  return sum;
}

}  // namespace wiresculpt::detail
