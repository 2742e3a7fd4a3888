// Dynamic k selection (k+-buffer, Vasilakis et al. TVCG 2015, eqs. 4-7) on hand-made depth
// complexity histograms: robustness decides, the memory budget decides, the budget is never
// exceeded, and the edge cases (empty frame, budget below k = 1, overflow bin, k_max).
#include <gtest/gtest.h>

#include <vector>

#include "mfr/budget/dynamic_k.hpp"

namespace mfr {
namespace {

// 100 pixels: 40 empty, 30 with 1, 20 with 4, 10 with 10 fragments. F = 30 + 80 + 100 = 210.
// C(1) = 60, C(2) = 90, C(3) = 120, C(4) = 150, C(5) = 160, …, C(10) = 210.
const std::vector<std::uint64_t> kHist = {40, 30, 0, 0, 20, 0, 0, 0, 0, 0, 10};
const KBufferMemoryModel kModel{100, 8, 8, 32};  // M(k) = 100·(8k + 8) + 32

TEST(DynamicK, RobustnessDecidesWhenTheBudgetIsLarge) {
  const DynamicKChoice c = selectDynamicK(kHist, 0, 1 << 20, 0.70, kModel);
  // 0.7·210 = 147 → C(3) = 120 < 147 ≤ C(4) = 150.
  EXPECT_EQ(c.kRobust, 4u);
  EXPECT_EQ(c.k, 4u);
  EXPECT_NEAR(c.capturedFraction, 150.0 / 210.0, 1e-12);
  EXPECT_EQ(c.bytes, 100u * (8u * 4u + 8u) + 32u);
  EXPECT_NE(c.reason.find("robustness"), std::string::npos);
}

TEST(DynamicK, FullRobustnessNeedsTheMaximumDepthComplexity) {
  EXPECT_EQ(selectDynamicK(kHist, 0, 1 << 20, 1.0, kModel).k, 10u);
  EXPECT_EQ(selectDynamicK(kHist, 0, 1 << 20, 0.0, kModel).k, 1u);  // at least one
  // Exactly on a boundary: R_h·F = C(k) takes that k.
  EXPECT_EQ(selectDynamicK(kHist, 0, 1 << 20, 150.0 / 210.0, kModel).k, 4u);
}

TEST(DynamicK, MemoryBudgetDecidesAndIsNeverExceeded) {
  // k = 2 needs 100·24 + 32 = 2432 B; k = 3 needs 3232 B.
  for (std::uint64_t budget : {2432u, 2433u, 3231u}) {
    const DynamicKChoice c = selectDynamicK(kHist, 0, budget, 0.99, kModel);
    EXPECT_EQ(c.kMemory, 2u) << budget;
    EXPECT_EQ(c.k, 2u);
    EXPECT_LE(c.bytes, budget);
    EXPECT_NEAR(c.capturedFraction, 90.0 / 210.0, 1e-12);
    EXPECT_NE(c.reason.find("memory budget"), std::string::npos);
  }
  EXPECT_EQ(selectDynamicK(kHist, 0, 3232, 0.99, kModel).k, 3u);
  // Every budget: the choice fits, and one more slot would not (unless robustness stopped it).
  for (std::uint64_t budget = 1632; budget < 12000; budget += 97) {
    const DynamicKChoice c = selectDynamicK(kHist, 0, budget, 0.9, kModel);
    ASSERT_GE(c.k, 1u);
    EXPECT_LE(kModel.bytes(c.k), budget);
    if (c.k < c.kRobust) {
      EXPECT_GT(kModel.bytes(c.k + 1), budget);
    }
  }
}

TEST(DynamicK, BudgetBelowOneSlotGivesZero) {
  const DynamicKChoice c = selectDynamicK(kHist, 0, 1631, 0.5, kModel);  // k = 1 needs 1632 B
  EXPECT_EQ(c.k, 0u);
  EXPECT_EQ(c.kMemory, 0u);
  EXPECT_NE(c.reason.find("k = 1 needs 1632"), std::string::npos);
}

TEST(DynamicK, EmptyFrameTakesOneSlot) {
  const std::vector<std::uint64_t> empty = {100};
  const DynamicKChoice c = selectDynamicK(empty, 0, 1 << 20, 0.9, kModel);
  EXPECT_EQ(c.k, 1u);
  EXPECT_DOUBLE_EQ(c.capturedFraction, 1.0);
}

TEST(DynamicK, OverflowBinUsesTheExactTotal) {
  // Bins 0..3, the last one counting n >= 3: 10 pixels with 2, 10 pixels with (really) 100.
  const std::vector<std::uint64_t> h = {0, 0, 10, 10};
  const std::uint64_t total = 10 * 2 + 10 * 100;  // 1020
  // C(3) = 20 + 30 = 50 < 0.05·1020 = 51 → kMax caps at the histogram's reach.
  const DynamicKChoice c = selectDynamicK(h, total, 1 << 20, 0.05, kModel, 3);
  EXPECT_EQ(c.k, 3u);
  EXPECT_NEAR(c.capturedFraction, 50.0 / 1020.0, 1e-12);
  // Without the exact total the last bin counts as n = 3: F = 50, C(2) = 40 < 0.9·50 = 45 ≤ C(3).
  EXPECT_EQ(selectDynamicK(h, 0, 1 << 20, 0.9, kModel, 3).k, 3u);
  EXPECT_EQ(selectDynamicK(h, 0, 1 << 20, 0.8, kModel, 3).k, 2u);
}

TEST(DynamicK, KMaxCapsBothBounds) {
  const DynamicKChoice c = selectDynamicK(kHist, 0, 1ull << 40, 1.0, kModel, 6);
  EXPECT_EQ(c.k, 6u);
  EXPECT_EQ(c.kMemory, 6u);
  EXPECT_EQ(c.kRobust, 6u);
}

}  // namespace
}  // namespace mfr
