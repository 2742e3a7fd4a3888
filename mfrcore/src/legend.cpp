// The scalar bar of a field colouring, drawn into an image. The glyphs are VTK's (vtkFreeTypeTools
// and its embedded fonts); the layout and the bar are ours, the bar's colours mapFieldValue's.
#include "mfr/legend.hpp"

#include <vtkFreeTypeTools.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <vector>
#include <mutex>

#include "mfr/error.hpp"
#include "mfr/scene/color_map.hpp"

namespace mfr {

namespace {

// A line of text as coverage (alpha) per pixel, row 0 the top row.
struct Glyphs {
  int width = 0, height = 0;
  std::vector<std::uint8_t> alpha;
};

Glyphs renderText(const std::string& text, int pixelSize) {
  // vtkFreeTypeTools is a process-wide singleton with a glyph cache: one caller at a time.
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  vtkFreeTypeTools* tools = vtkFreeTypeTools::GetInstance();
  tools->ScaleToPowerTwoOff();
  vtkNew<vtkTextProperty> property;
  property->SetFontFamilyToArial();
  property->SetFontSize(pixelSize);  // points at 72 dpi: pixels
  property->SetColor(1.0, 1.0, 1.0);
  property->SetJustificationToLeft();
  property->SetVerticalJustificationToBottom();
  vtkNew<vtkImageData> image;
  int dims[2] = {0, 0};
  Glyphs g;
  if (text.empty() || !tools->RenderString(property, vtkStdString(text), 72, image, dims)) return g;
  int extent[6];
  image->GetExtent(extent);
  g.width = std::min(dims[0], extent[1] - extent[0] + 1);
  g.height = std::min(dims[1], extent[3] - extent[2] + 1);
  if (image->GetNumberOfScalarComponents() != 4 || g.width <= 0 || g.height <= 0) return {};
  g.alpha.resize(static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height));
  for (int y = 0; y < g.height; ++y)  // VTK's rows go up
    for (int x = 0; x < g.width; ++x) {
      const auto* p = static_cast<const unsigned char*>(image->GetScalarPointer(extent[0] + x, extent[2] + y, 0));
      g.alpha[static_cast<std::size_t>(g.height - 1 - y) * static_cast<std::size_t>(g.width) +
              static_cast<std::size_t>(x)] = p[3];
    }
  return g;
}

void blend(ImageRGBA8& image, int x, int y, const glm::u8vec3& color, int alpha) {
  if (x < 0 || y < 0 || x >= image.width || y >= image.height || alpha <= 0) return;
  std::uint8_t* p = image.at(x, y);
  for (int c = 0; c < 3; ++c) p[c] = static_cast<std::uint8_t>((color[c] * alpha + p[c] * (255 - alpha) + 127) / 255);
}

void drawText(ImageRGBA8& image, const Glyphs& g, int left, int top, const glm::u8vec3& color) {
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x)
      blend(image, left + x, top + y, color,
            g.alpha[static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(x)]);
}

void fill(ImageRGBA8& image, int x0, int y0, int w, int h, const glm::u8vec3& color) {
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x) blend(image, x, y, color, 255);
}

}  // namespace

std::string legendValueText(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

LegendLayout drawColorLegend(ImageRGBA8& image, const FieldColors& colors, const glm::vec3& background,
                             const std::vector<double>& ticks) {
  if (image.width < kMinLegendImageSize || image.height < kMinLegendImageSize)
    throw Error("legend", "the image (" + std::to_string(image.width) + "x" + std::to_string(image.height) +
                              ") is too small for one: at least " + std::to_string(kMinLegendImageSize) +
                              " pixels a side");
  const ColorMap& map = colorMap(colors.map);
  const glm::vec2 range(colors.range);
  LegendLayout l;
  // Black on light backgrounds, white on dark ones (Rec. 709 luminance of the display values).
  const float luminance = glm::dot(background, glm::vec3(0.2126f, 0.7152f, 0.0722f));
  l.textColor = luminance > 0.5f ? glm::u8vec3(0) : glm::u8vec3(255);

  const int side = std::min(image.width, image.height);
  const int font = std::clamp(side / 32, 10, 24);
  const int margin = font;
  const double low = colors.range.x, high = colors.range.y;
  // The labelled values, highest first: the ends and the middle, or the caller's inside the range.
  std::vector<double> values = ticks.empty() ? std::vector<double>{high, 0.5 * (low + high), low} : ticks;
  std::erase_if(values, [&](double v) { return !(v >= low && v <= high); });
  std::sort(values.begin(), values.end(), std::greater<>());
  std::vector<Glyphs> labels;
  labels.reserve(values.size());
  for (const double v : values) labels.push_back(renderText(legendValueText(v), font));
  const Glyphs title = renderText(colors.field, font);
  int labelWidth = 0;
  for (const Glyphs& g : labels) labelWidth = std::max(labelWidth, g.width);
  const int tick = std::max(3, font / 3), gap = std::max(2, font / 4);

  l.barWidth = font;
  l.barHeight = std::max(16, static_cast<int>(std::lround(0.35 * image.height)));
  l.barX = image.width - margin - labelWidth - gap - tick - l.barWidth;
  l.barY = image.height - margin - font / 2 - l.barHeight;
  // The row of value v: the top row is the high end.
  const auto rowOf = [&](double v) {
    const double t = high > low ? (v - low) / (high - low) : 0.5;
    return l.barY + static_cast<int>(std::lround((1.0 - t) * (l.barHeight - 1)));
  };
  const int topLabel = labels.empty() ? l.barY : rowOf(values.front()) - labels.front().height / 2;
  // The title above the bar and above the highest label.
  const int titleTop = std::min(l.barY - 1, topLabel) - gap - title.height;
  const int titleLeft = std::max(0, std::min(l.barX, image.width - margin - title.width));

  // The bar: top row the high end, bottom row the low end.
  for (int r = 0; r < l.barHeight; ++r) {
    const double t = l.barHeight > 1 ? 1.0 - static_cast<double>(r) / (l.barHeight - 1) : 0.5;
    const glm::vec3 c = mapFieldValue(map, static_cast<float>(low + t * (high - low)), range);
    const glm::u8vec3 rgb(glm::round(glm::clamp(c, 0.0f, 1.0f) * 255.0f));
    fill(image, l.barX, l.barY + r, l.barWidth, 1, rgb);
  }
  // A one-pixel frame around it, and a tick and label per value; a label that would overlap the
  // one above it is left out (its tick stays).
  fill(image, l.barX - 1, l.barY - 1, l.barWidth + 2, 1, l.textColor);
  fill(image, l.barX - 1, l.barY + l.barHeight, l.barWidth + 2, 1, l.textColor);
  fill(image, l.barX - 1, l.barY, 1, l.barHeight, l.textColor);
  fill(image, l.barX + l.barWidth, l.barY, 1, l.barHeight, l.textColor);
  int labelBottom = std::numeric_limits<int>::min();
  int boxBottom = l.barY + l.barHeight + 1;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const int row = rowOf(values[i]);
    fill(image, l.barX + l.barWidth + 1, row, tick, 1, l.textColor);
    const int top = row - labels[i].height / 2;
    if (top < labelBottom) continue;
    drawText(image, labels[i], l.barX + l.barWidth + 1 + tick + gap, top, l.textColor);
    labelBottom = top + labels[i].height;
    boxBottom = std::max(boxBottom, labelBottom);
  }
  drawText(image, title, titleLeft, titleTop, l.textColor);

  const int boxLeft = std::min(l.barX - 1, titleLeft);
  const int boxTop = std::max(0, std::min(titleTop, topLabel));
  int boxRight = l.barX + l.barWidth + 1 + tick + gap + labelWidth;
  boxRight = std::max(boxRight, titleLeft + title.width);
  l.boxX = std::max(0, boxLeft);
  l.boxY = boxTop;
  l.boxWidth = std::min(image.width, boxRight) - l.boxX;
  l.boxHeight = std::min(image.height, boxBottom) - l.boxY;
  return l;
}

}  // namespace mfr
