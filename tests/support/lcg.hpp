#pragma once
// Test support: a deterministic pseudo-random number in [-1, 1) (a 64-bit LCG): noise without
// <random>'s implementation-defined distributions, the same on every platform.
#include <cstdint>

namespace vrelab::test {

struct Lcg {
  std::uint64_t s = 12345;
  double next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(s >> 11) / static_cast<double>(1ull << 52) - 1.0;
  }
};

}  // namespace vrelab::test
