// Hybrid transparency on exact lists (Tsopouridis, Fudos, Vasilakis, The Visual Computer 2022,
// §3.3; Maule et al., I3D 2013) against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "fragments.hpp"
#include "mfr/error.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/hybrid.hpp"

namespace {

using mfr::test::frag;

// Red α=0.4, green α=0.2, blue α=0.6 (α of 102, 51, 153 out of 255), white background.
std::vector<mfr::Fragment> threeFragments() {
  return {frag(0.1f, 255, 0, 0, 102), frag(0.2f, 0, 255, 0, 51), frag(0.3f, 0, 0, 255, 153)};
}

void expectNear(glm::vec3 got, glm::vec3 want) {
  EXPECT_NEAR(got.r, want.r, 1e-5f);
  EXPECT_NEAR(got.g, want.g, 1e-5f);
  EXPECT_NEAR(got.b, want.b, 1e-5f);
}

std::vector<mfr::Fragment> randomList(std::mt19937& rng, int n) {
  std::uniform_int_distribution<std::uint32_t> byte(0, 255);
  std::vector<mfr::Fragment> list;
  for (int i = 0; i < n; ++i)
    list.push_back(frag(0.01f * static_cast<float>(i + 1), byte(rng), byte(rng), byte(rng), byte(rng)));
  return list;
}

TEST(Hybrid, ThreeFragmentsByHand) {
  const auto list = threeFragments();
  const glm::vec3 white(1.0f);
  // k = 1: core red: C=(0.4,0,0), τ_core=0.6. Tail {green .2, blue .6}: α_avg=.4, τ_tail=.6²=.36,
  // C_tail = (0·.2+…)/.8 → (0,.25,.75)·.64 = (0,.16,.48). C = core + .6·(C_tail + .36).
  expectNear(mfr::compositeHybrid(list, 1, white), {0.616f, 0.312f, 0.504f});
  // k = 0: tail of all three: α_avg=.4, τ=.6³=.216; average (.4,.2,.6)/1.2 · .784.
  expectNear(mfr::compositeHybrid(list, 0, white),
             {0.784f / 3.0f + 0.216f, 0.784f / 6.0f + 0.216f, 0.784f / 2.0f + 0.216f});
  // k = 2: a tail of one fragment is exact: equals "over".
  expectNear(mfr::compositeHybrid(list, 2, white), {0.592f, 0.312f, 0.48f});
  expectNear(mfr::compositeHybrid(list, 2, white), mfr::compositeOver(list, white));
}

TEST(Hybrid, CoreAtLeastListIsOver) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const auto list = randomList(rng, 1 + trial % 9);
    const glm::vec3 bg(0.2f, 0.5f, 0.9f);
    const glm::vec3 over = mfr::compositeOver(list, bg);
    for (std::uint32_t k = static_cast<std::uint32_t>(list.size()); k < list.size() + 3; ++k) {
      EXPECT_EQ(mfr::compositeHybrid(list, k, bg), over);  // bit-identical: same arithmetic
      EXPECT_EQ(mfr::hybridError(list, k, bg), 0.0);
    }
  }
}

// k = n − 1 is exact too: a one-fragment tail is composited like "over" (why budgets above
// Σ(n − 1) cost optimal-k nothing; docs/results.md).
TEST(Hybrid, OneFragmentTailIsExact) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const auto list = randomList(rng, 2 + trial % 9);
    const glm::vec3 bg(0.2f, 0.5f, 0.9f);
    const auto k = static_cast<std::uint32_t>(list.size() - 1);
    expectNear(mfr::compositeHybrid(list, k, bg), mfr::compositeOver(list, bg));
    EXPECT_LT(mfr::hybridError(list, k, bg), 1e-10);
    if (list.size() >= 3) {
      EXPECT_GT(mfr::hybridError(list, k - 1, bg) + mfr::hybridError(list, 0, bg), 0.0);
    }
  }
}

// exactHybridSlots counts max(1, n − 1) per non-empty pixel, and that k map gives the exact image.
TEST(Hybrid, ExactHybridSlots) {
  std::mt19937 rng(9);
  mfr::FragmentLists lists;
  lists.width = 4;
  lists.height = 1;
  lists.offsets = {0};
  for (int n : {0, 1, 2, 5}) {
    const auto list = randomList(rng, n);
    lists.fragments.insert(lists.fragments.end(), list.begin(), list.end());
    lists.offsets.push_back(static_cast<std::uint32_t>(lists.fragments.size()));
  }
  lists.flags.assign(4, 0);
  EXPECT_EQ(mfr::exactHybridSlots(lists), 0u + 1u + 1u + 4u);
  const std::vector<std::uint32_t> k{0, 1, 1, 4};
  const glm::vec3 bg(0.1f, 0.4f, 0.7f);
  const mfr::ImageRGBA8 hybrid = mfr::compositeHybrid(lists, k, bg), exact = mfr::compositeOver(lists, bg);
  for (std::size_t i = 0; i < exact.pixels.size(); ++i)
    EXPECT_LE(std::abs(static_cast<int>(hybrid.pixels[i]) - static_cast<int>(exact.pixels[i])), 1) << "byte " << i;
}

// tailRunLengths: the farthest fragments of one RGBA strictly behind every other colour; a core of
// max(1, n − m) slots then composites exactly, one slot fewer does not.
TEST(Hybrid, TailRunLengthsAndTheirExactness) {
  const mfr::Fragment a = frag(0, 200, 40, 40, 90), b = frag(0, 40, 200, 40, 120), c = frag(0, 40, 40, 200, 80);
  auto at = [](mfr::Fragment f, float depth) {
    f.depth = depth;
    return f;
  };
  const std::vector<std::vector<mfr::Fragment>> pixels = {
      {},                                                                 // m = 0
      {at(a, 0.5f)},                                                      // 1
      {at(a, 0.1f), at(b, 0.2f), at(c, 0.3f), at(c, 0.4f), at(c, 0.5f)},  // 3
      {at(c, 0.1f), at(c, 0.2f), at(c, 0.3f)},                            // all one colour: 3
      {at(a, 0.1f), at(c, 0.2f), at(b, 0.3f)},                            // 1
      {at(a, 0.1f), at(c, 0.8f), at(b, 0.8f)},                            // a tie of two colours at the back: 0
      {at(c, 0.1f), at(a, 0.2f), at(c, 0.3f), at(c, 0.4f)},               // 2
  };
  mfr::FragmentLists lists;
  lists.width = static_cast<int>(pixels.size());
  lists.height = 1;
  lists.offsets = {0};
  for (const auto& list : pixels) {
    lists.fragments.insert(lists.fragments.end(), list.begin(), list.end());
    lists.offsets.push_back(static_cast<std::uint32_t>(lists.fragments.size()));
  }
  lists.flags.assign(pixels.size(), 0);
  const std::vector<std::uint32_t> m = mfr::tailRunLengths(lists);
  EXPECT_EQ(m, (std::vector<std::uint32_t>{0, 1, 3, 3, 1, 0, 2}));
  // max(1, n − max(m, 1)): 0, 1, 2, 1, 2, 2, 2.
  EXPECT_EQ(mfr::exactHybridSlots(lists, m), 10u);
  EXPECT_EQ(mfr::exactHybridSlots(lists), 0u + 1u + 4u + 2u + 2u + 2u + 3u);
  const glm::vec3 bg(0.9f, 0.8f, 0.3f);
  const std::vector<std::uint32_t> k{0, 1, 2, 1, 2, 2, 2};
  for (std::size_t p = 0; p < pixels.size(); ++p) {
    SCOPED_TRACE("pixel " + std::to_string(p));
    EXPECT_LT(mfr::hybridError(pixels[p], k[p], bg), 1e-10);
  }
  // One slot fewer is not exact where a run of another colour is cut into the tail.
  EXPECT_GT(mfr::hybridError(pixels[2], 1, bg), 1e-4);
  EXPECT_GT(mfr::hybridError(pixels[6], 1, bg), 1e-4);
}

TEST(Hybrid, ZeroCoreIsWeightedAverage) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    const auto list = randomList(rng, 1 + trial % 7);
    const glm::vec3 bg(0.3f, 0.6f, 0.1f);
    glm::dvec3 sumCA(0.0);
    double sumA = 0.0;
    for (const auto& f : list) {
      const double a = static_cast<double>(f.color >> 24) / 255.0;
      for (int c = 0; c < 3; ++c) sumCA[c] += static_cast<double>((f.color >> (8 * c)) & 0xFFu) / 255.0 * a;
      sumA += a;
    }
    const double n = static_cast<double>(list.size());
    glm::dvec3 want = glm::dvec3(bg);
    if (sumA > 0) {
      const double tau = std::pow(1.0 - sumA / n, n);
      want = sumCA / sumA * (1.0 - tau) + tau * glm::dvec3(bg);
    }
    const glm::vec3 got = mfr::compositeHybrid(list, 0, bg);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-5);
  }
}

TEST(Hybrid, EmptyAndTransparentTails) {
  const glm::vec3 bg(0.25f, 0.5f, 0.75f);
  expectNear(mfr::compositeHybrid(std::span<const mfr::Fragment>{}, 0, bg), bg);
  // A fully transparent tail (Σα = 0) shows the background through the core.
  const std::vector<mfr::Fragment> list{frag(0.1f, 255, 255, 255, 51), frag(0.2f, 255, 0, 0, 0),
                                        frag(0.3f, 0, 255, 0, 0)};
  expectNear(mfr::compositeHybrid(list, 1, bg), glm::vec3(0.2f) + 0.8f * bg);
  const mfr::HybridTailSums s = mfr::hybridTailSums(threeFragments(), 1);
  EXPECT_EQ(s.count, 2u);
  EXPECT_EQ(s.alpha, 51u + 153u);
  EXPECT_EQ(s.colorAlpha[0], 0u);
  EXPECT_EQ(s.colorAlpha[1], 255u * 51u);
  EXPECT_EQ(s.colorAlpha[2], 255u * 153u);
}

TEST(Hybrid, ImageWithPerPixelK) {
  // 2x1 image: pixel 0 holds the three fragments, pixel 1 none.
  mfr::FragmentLists lists;
  lists.width = 2;
  lists.height = 1;
  lists.fragments = threeFragments();
  lists.offsets = {0, 3, 3};
  lists.flags = {0, 0};
  const glm::vec3 white(1.0f);
  const std::vector<std::uint32_t> kMap{1, 4};
  const mfr::ImageRGBA8 image = mfr::compositeHybrid(lists, kMap, white);
  EXPECT_EQ(image.at(0, 0)[0], 157);  // round(.616·255) = round(157.08)
  EXPECT_EQ(image.at(0, 0)[1], 80);   // .312·255 = 79.56
  EXPECT_EQ(image.at(0, 0)[2], 129);  // .504·255 = 128.52
  EXPECT_EQ(image.at(1, 0)[0], 255);
  const mfr::ImageRGBA8 uniform = mfr::compositeHybrid(lists, 8u, white);
  EXPECT_EQ(uniform.pixels, mfr::compositeOver(lists, white).pixels);
  EXPECT_THROW(mfr::compositeHybrid(lists, std::vector<std::uint32_t>{1}, white), mfr::Error);
}

}  // namespace
