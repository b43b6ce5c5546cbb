// exact/numpy_sum.hpp: sums whose rounding shows the order of the additions, worked out by hand for
// numpy's pairwise order, and sums against a long double reference.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "exact/numpy_sum.hpp"

using wiresculpt::detail::numpy_sum;

namespace {
// numpy_sum of 1e16 followed by n - 1 ones, less 1e16 (exact: the two are close).
double after_1e16(std::size_t n) {
  std::vector<double> a(n, 1.0);
  a[0] = 1e16;
  return numpy_sum(a.data(), n) - 1e16;
}
}  // namespace

TEST_CASE("numpy's sum: fewer than eight values one by one, up to 128 in eight running sums", "[target]") {
  // Near 1e16 doubles are 2 apart and a tie rounds to the even one: 1e16 + 1 gives 1e16 (even),
  // 1e16 + 7 gives 1e16 + 8, 1e16 + 15 gives 1e16 + 16. Added one by one, every 1 is lost.
  CHECK(after_1e16(7) == 0.0);
  // Eight: one block, nothing left over: s0..s7 = the values, joined ((s0 + s1) + (s2 + s3)) +
  // ((s4 + s5) + (s6 + s7)) = ((1e16 + 1) + 2) + 4 = 1e16 + 6.
  CHECK(after_1e16(8) == 6.0);
  // Nine: the same join, then the ninth: 1e16 + 7, a tie, 1e16 + 8 (np.sum's too).
  CHECK(after_1e16(9) == 8.0);
  // Seventeen: s0 = 1e16 + 1 = 1e16, s1..s7 = 2; joined 1e16 + 14; the seventeenth after the
  // join: 1e16 + 15, a tie, 1e16 + 16 (np.sum's too).
  CHECK(after_1e16(17) == 16.0);
  // 128, still one run of blocks: s0 = 1e16 (fifteen ties lost), s1..s7 = 16; 1e16 + 112.
  CHECK(after_1e16(128) == 112.0);
  // 129: halves of 64 and 65. The first: s0 = 1e16, s1..s7 = 8, 1e16 + 56; the second: eight sums
  // of 8 and one more, 65; 1e16 + 121 is a tie: 1e16 + 120 (np.sum's too; as one run of blocks
  // it would be 1e16 + 112).
  CHECK(after_1e16(129) == 120.0);
}

TEST_CASE("numpy's sum: longer runs in halves and 8192-value chunks, close to the exact sum", "[target]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t n : {0u, 1u, 8u, 127u, 128u, 129u, 1000u, 8192u, 8193u, 20000u}) {
    std::vector<double> a(n);
    long double exact = 0.0L;
    for (double& x : a) exact += (x = unit(rng));
    INFO("n " << n);
    CHECK(std::abs(numpy_sum(a.data(), n) - static_cast<double>(exact)) <= 1e-12 * (1.0 + static_cast<double>(exact)));
  }
  // 9,000 values of 0.1: a chunk of 8,192 and one of 808. np.sum (numpy 1.24) gives
  // 900.0000000000001; the halves without the chunks would give 899.9999999999998, one by one
  // 900.0000000001361.
  const std::vector<double> tenths(9000, 0.1);
  CHECK(numpy_sum(tenths.data(), tenths.size()) == 900.0000000000001);
  // Two halves at 136 values: the first 64 (a multiple of 8 below 68) and the last 72, each in
  // running sums. 1e16 first, then 135 ones: the first half's s0 = 1e16 (its seven ones each a
  // tie, lost), s1..s7 = 8 each, joined 1e16 + 56; the second half is 72 exactly: 1e16 + 128
  // (np.sum's too; one by one, 1e16).
  CHECK(after_1e16(136) == 128.0);
}
