#pragma once
// Shared helpers for GL tests: one headless context per test process, the sample scene's oracle
// computed once, and comparison of a GPU method's captured lists and image with the oracle's.
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

// The largest difference between two packed RGBA8 colours over their four channels.
int channelDiff(std::uint32_t a, std::uint32_t b);

struct ListComparison {
  std::size_t pixels = 0;           // all pixels
  std::size_t compared = 0;         // pixels not flagged by the oracle (edges, depth ties)
  std::size_t countMismatches = 0;  // compared pixels whose count differs from the oracle's
  std::size_t depthMismatches = 0;  // compared pixels whose first min(n, max) depths differ
  std::size_t colorMismatches = 0;  // compared pixels whose colours differ by > 2/255
  std::string firstMismatch;        // description of the first one, for the failure message
};

// Compares captured lists with the oracle's: counts (expected = min(oracle count, kNearest)
// when kNearest > 0, i.e. a method keeping the k nearest), and the k nearest depths (relative
// tolerance) and colours.
ListComparison compareLists(const FragmentLists& oracle, const CapturedLists& gpu, std::uint32_t kNearest = 0);

struct ImageComparison {
  std::size_t compared = 0;
  std::size_t within = 0;  // pixels with every channel within tolerance
  int maxDifference = 0;   // over compared pixels
  [[nodiscard]] double fraction() const { return compared ? static_cast<double>(within) / compared : 0.0; }
};

// Per-channel comparison over pixels the oracle does not flag as ambiguous.
ImageComparison compareImages(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                              int tolerance);

// The built-in sample scene seen from its view `view` at w x h, with the oracle's lists and their
// composited image: computed on first use, then shared by the tests of the process (which run one
// at a time).
struct SampleReference {
  Scene scene;
  Camera camera;
  FragmentLists oracle;
  ImageRGBA8 image;  // compositeOver(oracle, scene.background)
};
const SampleReference& sampleReference(const std::string& view, int w, int h);

// An exact GPU method (req: method, parameters, req.width x req.height) against the oracle on
// `scene` from `camera`: expects every fragment of the pixels the oracle does not flag captured
// (count, depths, colours; at least 70 % of the pixels compared) and the image within 2/255 of
// the oracle's on 99.9 % of them. Returns the comparisons and the render, for further checks.
struct OracleMatch {
  ListComparison lists;
  ImageComparison image;
  RenderOutput out;
};
OracleMatch expectGpuMatchesOracle(const Scene& scene, const Camera& camera, const RenderRequest& req);

}  // namespace mfr::test
