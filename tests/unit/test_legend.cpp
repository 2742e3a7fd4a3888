// The scalar bar drawn into images (legend.hpp): the bar's rows are the colour map's colours at
// their values (mapFieldValue, checked against the published maps in test_color_map.cpp), the
// text is there and says what it should (another range changes the labels' pixels, not the bar's),
// nothing outside the reported box changes, the text colour follows the background, and an image
// too small is refused.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/legend.hpp"
#include "mfr/scene/color_map.hpp"

namespace mfr::test {
namespace {

ImageRGBA8 filled(int w, int h, glm::u8vec3 rgb) {
  ImageRGBA8 image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = image.at(x, y);
      p[0] = rgb.r;
      p[1] = rgb.g;
      p[2] = rgb.b;
      p[3] = 255;
    }
  return image;
}

bool inside(const LegendLayout& l, int x, int y) {
  return x >= l.boxX && x < l.boxX + l.boxWidth && y >= l.boxY && y < l.boxY + l.boxHeight;
}

TEST(Legend, BarRowsAreTheMapsColoursAtTheirValues) {
  for (const char* map : {"viridis", "cool-warm", "rainbow"}) {
    SCOPED_TRACE(map);
    ImageRGBA8 image = filled(400, 300, {255, 255, 255});
    const FieldColors colors{"pressure", map, {-2.0, 3.0}};
    const LegendLayout l = drawColorLegend(image, colors, glm::vec3(1.0f));
    ASSERT_GT(l.barHeight, 50);
    ASSERT_GE(l.barX, 0);
    ASSERT_LE(l.barX + l.barWidth, image.width);
    ASSERT_LE(l.barY + l.barHeight, image.height);
    for (int r = 0; r < l.barHeight; ++r) {
      const double t = 1.0 - static_cast<double>(r) / (l.barHeight - 1);  // top row: the high end
      const glm::vec3 c = mapFieldValue(colorMap(map), static_cast<float>(-2.0 + 5.0 * t), glm::vec2(-2.0f, 3.0f));
      const std::uint8_t* p = image.at(l.barX + l.barWidth / 2, l.barY + r);
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_LE(std::abs(static_cast<int>(p[ch]) - static_cast<int>(std::lround(c[ch] * 255.0f))), 1)
            << "row " << r << " channel " << ch;
    }
  }
}

TEST(Legend, TextIsDrawnInsideTheBoxAndNothingOutsideChanges) {
  const ImageRGBA8 before = filled(400, 300, {255, 255, 255});
  ImageRGBA8 a = before, b = before;
  const LegendLayout la = drawColorLegend(a, {"pressure", "viridis", {0.0, 1.0}}, glm::vec3(1.0f));
  const LegendLayout lb = drawColorLegend(b, {"pressure", "viridis", {0.0, 1000.0}}, glm::vec3(1.0f));
  EXPECT_EQ(la.textColor, glm::u8vec3(0));  // black on white
  std::size_t dark = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const bool inBar = x >= la.barX && x < la.barX + la.barWidth && y >= la.barY && y < la.barY + la.barHeight;
      const std::uint8_t *pa = a.at(x, y), *p0 = before.at(x, y);
      if (!inside(la, x, y)) {
        ASSERT_TRUE(pa[0] == p0[0] && pa[1] == p0[1] && pa[2] == p0[2]) << x << ", " << y << " outside the box";
        continue;
      }
      if (!inBar && pa[0] < 128) ++dark;
    }
  EXPECT_GT(dark, 200u);  // frame, ticks, the title and three labels
  // The labels say the range: "1000", "500", "0" cover more pixels right of the bar than "1",
  // "0.5", "0"; the bar itself is the same (the same map over its own range), moved left.
  const auto darkRightOfBar = [](const ImageRGBA8& image, const LegendLayout& l) {
    std::size_t n = 0;
    for (int y = l.barY - l.barWidth; y < l.barY + l.barHeight + l.barWidth; ++y)
      for (int x = l.barX + l.barWidth + 1; x < image.width; ++x) n += image.at(x, y)[0] < 128;
    return n;
  };
  EXPECT_GT(darkRightOfBar(b, lb), darkRightOfBar(a, la) + 20);
  EXPECT_LT(lb.barX, la.barX);
  EXPECT_EQ(lb.barHeight, la.barHeight);
  for (int r = 0; r < la.barHeight; ++r)
    for (int c = 0; c < la.barWidth; ++c)
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_EQ(a.at(la.barX + c, la.barY + r)[ch], b.at(lb.barX + c, lb.barY + r)[ch]) << r << ", " << c;
  EXPECT_EQ(legendValueText(0.5), "0.5");
  EXPECT_EQ(legendValueText(1234.5678), "1235");
  EXPECT_EQ(legendValueText(-142.0), "-142");
  EXPECT_EQ(legendValueText(123456.0), "1.235e+05");
}

TEST(Legend, TheFieldsNameIsItsTitle) {
  // Two titles of different length: the longer one covers more pixels above the bar.
  ImageRGBA8 shortTitle = filled(400, 300, {255, 255, 255}), longTitle = shortTitle;
  const LegendLayout ls = drawColorLegend(shortTitle, {"p", "viridis", {0.0, 1.0}}, glm::vec3(1.0f));
  const LegendLayout ll = drawColorLegend(longTitle, {"pressure coefficient", "viridis", {0.0, 1.0}}, glm::vec3(1.0f));
  const auto darkAbove = [](const ImageRGBA8& image, const LegendLayout& l) {
    std::size_t n = 0;
    for (int y = 0; y < l.barY - 1; ++y)
      for (int x = 0; x < image.width; ++x) n += image.at(x, y)[0] < 128;
    return n;
  };
  EXPECT_GT(darkAbove(longTitle, ll), 3 * darkAbove(shortTitle, ls));
  EXPECT_GT(darkAbove(shortTitle, ls), 0u);
}

TEST(Legend, WhiteTextOnDarkBackgrounds) {
  ImageRGBA8 image = filled(200, 160, {20, 20, 30});
  const LegendLayout l = drawColorLegend(image, {"v", "magma", {0.0, 1.0}}, glm::vec3(0.08f, 0.08f, 0.12f));
  EXPECT_EQ(l.textColor, glm::u8vec3(255));
  std::size_t light = 0;
  for (int y = l.boxY; y < l.boxY + l.boxHeight; ++y)
    for (int x = l.boxX; x < l.boxX + l.boxWidth; ++x)
      if (!(x >= l.barX && x < l.barX + l.barWidth && y >= l.barY && y < l.barY + l.barHeight))
        light += image.at(x, y)[0] > 200;
  EXPECT_GT(light, 50u);
}

TEST(Legend, TicksMarkTheGivenValuesOnly) {
  // Ticks are one text-coloured row right of the bar, at the row of their value (top: the high end).
  const auto tickRows = [](const ImageRGBA8& image, const LegendLayout& l) {
    std::vector<int> rows;
    const int x = l.barX + l.barWidth + 2;  // inside every tick, left of every label
    for (int y = l.barY; y < l.barY + l.barHeight; ++y)
      if (image.at(x, y)[0] < 128) rows.push_back(y);
    return rows;
  };
  ImageRGBA8 image = filled(400, 300, {255, 255, 255});
  const LegendLayout l = drawColorLegend(image, {"ct", "cool-warm", {1.0, 3.0}}, glm::vec3(1.0f), {1.5, 3.0, 7.0});
  const auto rowOf = [&](double v) {
    return l.barY + static_cast<int>(std::lround((1.0 - (v - 1.0) / 2.0) * (l.barHeight - 1)));
  };
  EXPECT_EQ(tickRows(image, l), (std::vector<int>{rowOf(3.0), rowOf(1.5)}));  // 7 lies outside: no tick
  // The default: the ends and the middle.
  ImageRGBA8 plain = filled(400, 300, {255, 255, 255});
  const LegendLayout p = drawColorLegend(plain, {"ct", "cool-warm", {1.0, 3.0}}, glm::vec3(1.0f));
  EXPECT_EQ(tickRows(plain, p), (std::vector<int>{rowOf(3.0), rowOf(2.0), rowOf(1.0)}));
  // Two values a pixel apart: both ticks, one label — the higher one's; the lower one's would overlap it.
  ImageRGBA8 close = filled(400, 300, {255, 255, 255}), one = close;
  const LegendLayout lc = drawColorLegend(close, {"ct", "cool-warm", {1.0, 3.0}}, glm::vec3(1.0f), {2.0, 2.01});
  drawColorLegend(one, {"ct", "cool-warm", {1.0, 3.0}}, glm::vec3(1.0f), {2.01});
  EXPECT_EQ(tickRows(close, lc).size(), 2u);
  std::size_t labelPixels[2] = {0, 0};
  for (int y = 0; y < close.height; ++y)
    for (int x = lc.barX + lc.barWidth + 2 + lc.barWidth; x < close.width; ++x) {
      labelPixels[0] += close.at(x, y)[0] < 128;
      labelPixels[1] += one.at(x, y)[0] < 128;
    }
  EXPECT_EQ(labelPixels[0], labelPixels[1]);  // "2.01" drawn, "2" left out
  EXPECT_GT(labelPixels[1], 0u);
}

TEST(Legend, TooSmallAnImageIsRefused) {
  ImageRGBA8 image = filled(95, 300, {255, 255, 255});
  const ImageRGBA8 before = image;
  try {
    drawColorLegend(image, {"v", "viridis", {0.0, 1.0}}, glm::vec3(1.0f));
    ADD_FAILURE() << "drawn";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "legend: the image (95x300) is too small for one: at least 96 pixels a side");
  }
  EXPECT_EQ(image.pixels, before.pixels);
}

}  // namespace
}  // namespace mfr::test
