#pragma once
// Shared helpers for GL tests: one headless context per test process, and comparison of a GPU
// method's captured lists and image with the oracle's.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>

#include "mfr/gl/context.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr::test {

// The process-wide headless context (created on first use).
gl::HeadlessContext& context();

struct ListComparison {
  std::size_t pixels = 0;            // all pixels
  std::size_t compared = 0;          // pixels not flagged by the oracle (edges, depth ties)
  std::size_t countMismatches = 0;   // compared pixels whose count differs from the oracle's
  std::size_t depthMismatches = 0;   // compared pixels whose first min(n, max) depths differ
  std::size_t colorMismatches = 0;   // compared pixels whose colours differ by > 2/255
  std::string firstMismatch;         // description of the first one, for the failure message
};

// Compares captured lists with the oracle's: counts (expected = min(oracle count, kNearest)
// when kNearest > 0, i.e. a method keeping the k nearest), and the k nearest depths (relative
// tolerance) and colours.
ListComparison compareLists(const FragmentLists& oracle, const CapturedLists& gpu, std::uint32_t kNearest = 0);

struct ImageComparison {
  std::size_t compared = 0;
  std::size_t within = 0;     // pixels with every channel within tolerance
  int maxDifference = 0;      // over compared pixels
  [[nodiscard]] double fraction() const { return compared ? static_cast<double>(within) / compared : 0.0; }
};

// Per-channel comparison over pixels the oracle does not flag as ambiguous.
ImageComparison compareImages(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                              int tolerance);

}  // namespace mfr::test
