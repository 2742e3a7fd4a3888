#pragma once
// Hand-made fragments for tests of the CPU references (hybrid composite, optimal k, k allocation).
#include <cstdint>

#include "mfr/reference/oracle.hpp"

namespace mfr::test {

// A fragment at `depth` with colour (r, g, b, a), each 0..255, packed with R in the low byte.
inline Fragment frag(float depth, std::uint32_t r, std::uint32_t g, std::uint32_t b, std::uint32_t a) {
  Fragment f;
  f.depth = depth;
  f.color = r | (g << 8) | (b << 16) | (a << 24);
  return f;
}

}  // namespace mfr::test
