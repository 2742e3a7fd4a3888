// Image metrics: FLIP against the reference implementation's output on a real image pair
// (tests/data/flip/README.md), RMSE and percentiles against hand-computed values.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/image.hpp"
#include "mfr/reference/metrics.hpp"

namespace {

const std::filesystem::path kFlipData = std::filesystem::path(MFR_TEST_DATA_DIR) / "flip";

mfr::ImageRGBA8 noiseImage(int w, int h, unsigned seed) {
  mfr::ImageRGBA8 image(w, h);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  for (auto& v : image.pixels) v = static_cast<std::uint8_t>(byte(rng));
  return image;
}

mfr::ImageRGBA8 flatImage(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  mfr::ImageRGBA8 image(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = image.at(x, y);
      p[0] = r;
      p[1] = g;
      p[2] = b;
      p[3] = 255;
    }
  }
  return image;
}

// The conformance pair is evaluated once for all tests that look at it.
class FlipConformance : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const mfr::ImageRGBA8 reference = mfr::readPng(kFlipData / "tree-ref.png");
    const mfr::ImageRGBA8 test = mfr::readPng(kFlipData / "tree-test.png");
    const auto start = std::chrono::steady_clock::now();
    result_ = std::make_unique<mfr::FlipResult>(mfr::flip(reference, test, 67.0));
    seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  static void TearDownTestSuite() { result_.reset(); }

  static std::unique_ptr<mfr::FlipResult> result_;
  static double seconds_;
};
std::unique_ptr<mfr::FlipResult> FlipConformance::result_;
double FlipConformance::seconds_ = 0;

TEST_F(FlipConformance, StatisticsMatchReferenceImplementation) {
  ASSERT_TRUE(result_);
  const mfr::FlipStats& s = result_->stats;
  std::printf("FLIP tree pair (640x960, 67 ppd) in %.3f s: mean %.6f p25 %.6f p50 %.6f p75 %.6f min %.6f max %.6f\n",
              seconds_, s.mean, s.p25, s.p50, s.p75, s.min, s.max);
  EXPECT_EQ(result_->errorMap.width, 640);
  EXPECT_EQ(result_->errorMap.height, 960);
  EXPECT_EQ(result_->errorMap.channels, 1);
  EXPECT_NEAR(s.mean, 0.133285, 1e-4);
  EXPECT_NEAR(s.p25, 0.184924, 1e-4);
  EXPECT_NEAR(s.p50, 0.333241, 1e-4);
  EXPECT_NEAR(s.p75, 0.503441, 1e-4);
  EXPECT_NEAR(s.min, 0.0, 1e-4);
  EXPECT_NEAR(s.max, 0.983044, 1e-4);
}

TEST_F(FlipConformance, MagmaMapMatchesReferenceToolOutput) {
  ASSERT_TRUE(result_);
  const mfr::ImageRGBA8 expected = mfr::readPng(kFlipData / "tree-comparison-cli.png");
  const mfr::ImageRGBA8 actual = mfr::magma(result_->errorMap);
  ASSERT_EQ(actual.width, expected.width);
  ASSERT_EQ(actual.height, expected.height);
  int maxDiff = 0;
  long differing = 0;    // any channel differs at all
  long outOfBounds = 0;  // some channel differs by more than 3
  for (int y = 0; y < expected.height; ++y) {
    for (int x = 0; x < expected.width; ++x) {
      int pixelMax = 0;
      for (int c = 0; c < 3; ++c) {
        pixelMax = std::max(pixelMax, std::abs(int{actual.at(x, y)[c]} - int{expected.at(x, y)[c]}));
      }
      maxDiff = std::max(maxDiff, pixelMax);
      differing += pixelMax > 0 ? 1 : 0;
      outOfBounds += pixelMax > 3 ? 1 : 0;
    }
  }
  std::printf("magma map vs tree-comparison-cli.png: %ld pixels differ, %ld by more than 3, max difference %d\n",
              differing, outOfBounds, maxDiff);
  EXPECT_EQ(outOfBounds, 0) << "max per-channel difference " << maxDiff;
  EXPECT_LE(maxDiff, 3);
}

TEST(Flip, IdenticalImagesGiveZeroError) {
  const mfr::ImageRGBA8 image = noiseImage(37, 23, 1);
  const mfr::FlipResult r = mfr::flip(image, image);
  EXPECT_EQ(r.stats.mean, 0.0);
  EXPECT_EQ(r.stats.max, 0.0);
  EXPECT_EQ(r.stats.p50, 0.0);
  EXPECT_TRUE(std::all_of(r.errorMap.data.begin(), r.errorMap.data.end(), [](float v) { return v == 0.0f; }));
}

TEST(Flip, ErrorIsLocalAndBounded) {
  // One changed pixel in a flat 64x64 image: error near it, none beyond the filters' reach.
  const mfr::ImageRGBA8 reference = flatImage(64, 64, 128, 128, 128);
  mfr::ImageRGBA8 test = reference;
  test.at(32, 32)[0] = 255;
  const mfr::FlipResult r = mfr::flip(reference, test);
  EXPECT_GT(r.errorMap.at(32, 32), 0.1f);
  EXPECT_EQ(r.errorMap.at(0, 0), 0.0f);
  EXPECT_EQ(r.errorMap.at(63, 10), 0.0f);
  EXPECT_GT(r.stats.max, 0.1);
  EXPECT_LE(r.stats.max, 1.0);
  EXPECT_GE(r.stats.min, 0.0);
}

// mfr compare accepts any ppd in (0, 10000]: at one pixel per degree and below the feature
// detectors' off-centre weights underflow, which gave 0 / 0 = NaN everywhere. The error stays a
// number in [0, 1], zero for identical images and above zero where colours differ.
TEST(Flip, LowPixelsPerDegreeGiveNumbers) {
  const mfr::ImageRGBA8 reference = noiseImage(24, 16, 3);
  const mfr::ImageRGBA8 test = noiseImage(24, 16, 4);
  for (const double ppd : {0.01, 0.5, 1.0, 1.5}) {
    const mfr::FlipResult same = mfr::flip(reference, reference, ppd);
    EXPECT_EQ(same.stats.mean, 0.0) << ppd;
    const mfr::FlipResult r = mfr::flip(reference, test, ppd);
    EXPECT_TRUE(std::isfinite(r.stats.mean)) << ppd;
    EXPECT_GT(r.stats.mean, 0.0) << ppd;
    EXPECT_LE(r.stats.max, 1.0) << ppd;
    EXPECT_TRUE(std::all_of(r.errorMap.data.begin(), r.errorMap.data.end(), [](float v) {
      return std::isfinite(v) && v >= 0.0f && v <= 1.0f;
    })) << ppd;
  }
}

TEST(Flip, SizeMismatchThrows) {
  EXPECT_THROW(mfr::flip(flatImage(4, 4, 0, 0, 0), flatImage(4, 5, 0, 0, 0)), mfr::Error);
}

TEST(Rmse, IdenticalImagesGiveZero) {
  const mfr::ImageRGBA8 image = noiseImage(16, 9, 2);
  EXPECT_EQ(mfr::rmse(image, image), 0.0);
}

TEST(Rmse, HandComputedSinglePixelDifference) {
  // 2x2 image, one channel of one pixel off by 51/255 = 0.2: sqrt(0.2² / 12) over 4 pixels × RGB.
  const mfr::ImageRGBA8 reference = flatImage(2, 2, 10, 20, 30);
  mfr::ImageRGBA8 test = reference;
  test.at(1, 0)[1] = 20 + 51;
  test.at(0, 1)[3] = 0;  // alpha does not count
  EXPECT_NEAR(mfr::rmse(reference, test), 0.2 / std::sqrt(12.0), 1e-12);
}

TEST(Rmse, SizeMismatchThrowsNamingSizes) {
  try {
    (void)mfr::rmse(flatImage(2, 2, 0, 0, 0), flatImage(3, 2, 0, 0, 0));
    FAIL() << "expected mfr::Error";
  } catch (const mfr::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("2x2"), std::string::npos) << what;
    EXPECT_NE(what.find("3x2"), std::string::npos) << what;
  }
}

TEST(Metrics, WeightedPercentile) {
  // Sorted 1 2 3 4, total 10: running sums 1 3 6 10.
  const std::vector<float> v = {4, 1, 3, 2};
  EXPECT_EQ(mfr::weightedPercentile(v, 0.0), 1.0);   // first running sum > 0
  EXPECT_EQ(mfr::weightedPercentile(v, 0.25), 2.0);  // > 2.5
  EXPECT_EQ(mfr::weightedPercentile(v, 0.5), 3.0);   // > 5
  EXPECT_EQ(mfr::weightedPercentile(v, 0.6), 4.0);   // > 6: 6 itself does not exceed it
  EXPECT_EQ(mfr::weightedPercentile(v, 0.75), 4.0);  // > 7.5
  // Zero values carry no weight.
  EXPECT_EQ(mfr::weightedPercentile({0, 0, 0, 5}, 0.1), 5.0);
  EXPECT_EQ(mfr::weightedPercentile({}, 0.5), 0.0);
}

TEST(Metrics, AbsoluteDifferenceIsMaxOverRgb) {
  const mfr::ImageRGBA8 reference = flatImage(2, 1, 100, 100, 100);
  mfr::ImageRGBA8 test = reference;
  test.at(1, 0)[0] = 90;
  test.at(1, 0)[2] = 151;
  test.at(0, 0)[3] = 0;  // alpha ignored
  const mfr::ImageF d = mfr::absoluteDifference(reference, test);
  ASSERT_EQ(d.width, 2);
  ASSERT_EQ(d.channels, 1);
  EXPECT_EQ(d.at(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(d.at(1, 0), 51.0f / 255.0f);
  EXPECT_THROW(mfr::absoluteDifference(reference, flatImage(1, 2, 0, 0, 0)), mfr::Error);
}

TEST(Metrics, MagmaAndHeatmapColours) {
  mfr::ImageF values(4, 1, 1);
  values.at(0, 0) = 0.0f;
  values.at(1, 0) = 1.0f;
  values.at(2, 0) = -0.5f;  // clamps to the first entry
  values.at(3, 0) = 0.5f;   // round(127.5) = 128
  const mfr::ImageRGBA8 m = mfr::magma(values);
  const auto rgb = [&](int x) { return std::vector<int>{m.at(x, 0)[0], m.at(x, 0)[1], m.at(x, 0)[2], m.at(x, 0)[3]}; };
  EXPECT_EQ(rgb(0), (std::vector<int>{0, 0, 4, 255}));
  EXPECT_EQ(rgb(1), (std::vector<int>{252, 253, 191, 255}));
  EXPECT_EQ(rgb(2), rgb(0));
  EXPECT_EQ(rgb(3), (std::vector<int>{183, 55, 121, 255}));  // magma[128] = (0.716387, 0.214982, 0.475290)

  mfr::ImageF raw(2, 1, 1);
  raw.at(0, 0) = 2.0f;  // half of maxValue
  raw.at(1, 0) = 9.0f;  // saturates
  const mfr::ImageRGBA8 h = mfr::heatmap(raw, 4.0f);
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(h.at(0, 0)[c], m.at(3, 0)[c]);
    EXPECT_EQ(h.at(1, 0)[c], m.at(1, 0)[c]);
  }
  EXPECT_THROW(mfr::heatmap(raw, 0.0f), mfr::Error);
}

}  // namespace
