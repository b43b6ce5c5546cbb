// A figure said against the limit it breaks (figures.hpp, private to the core): the same precision
// for both, and digits enough that the two never read alike. Expected texts written out by hand.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "figures.hpp"  // native/src: private to the core

using wiresculpt::detail::versus;
using Pair = std::pair<std::string, std::string>;

TEST_CASE("figures: a value and its limit with the same decimals, more until they differ", "[figures]") {
  CHECK(versus(61.234, 60.0, 1) == Pair{"61.2", "60.0"});
  CHECK(versus(60.01, 60.0, 1) == Pair{"60.01", "60.00"});  // not "60.0 ... 60.0"
  CHECK(versus(60.01, 60.0, 2) == Pair{"60.01", "60.00"});  // not "60.01 ... 60.0"
  CHECK(versus(60.0000004, 60.0, 2) == Pair{"60.0000004", "60.0000000"});
  CHECK(versus(14.99999, 15.0, 3) == Pair{"14.99999", "15.00000"});  // under a least value
}

TEST_CASE("figures: a signed value is compared by its magnitude", "[figures]") {
  CHECK(versus(-60.23, 60.0, 2) == Pair{"-60.23", "60.00"});
  CHECK(versus(-60.001, 60.0, 2) == Pair{"-60.001", "60.000"});
}

TEST_CASE("figures: significant digits", "[figures]") {
  CHECK(versus(3e9, 1e9, 6, 'g') == Pair{"3e+09", "1e+09"});
  CHECK(versus(100.0000001, 100.0, 6, 'g') == Pair{"100.0000001", "100"});
  CHECK(versus(1.00000001e-5, 1e-5, 4, 'g') == Pair{"1.00000001e-05", "1e-05"});
}

TEST_CASE("figures: equal or endless figures keep their digits", "[figures]") {
  CHECK(versus(60.0, 60.0, 1) == Pair{"60.0", "60.0"});
  CHECK(versus(std::numeric_limits<double>::infinity(), 60.0, 1) == Pair{"inf", "60.0"});
  // the largest double with 17 decimals fits
  CHECK(versus(std::numeric_limits<double>::max(), 1.0, 1).first.size() == 311);
}
