#pragma once
// ParaView's scalar bar, drawn into a rendered image: the colour map of a field colouring as a
// vertical bar in the lower right corner, the field's name above it and the values at its ends and
// middle beside it, so that a PNG of a field-coloured scene reads without the viewer. Text by VTK's
// FreeType tools (their embedded sans-serif font), in black or white, whichever stands out from
// the background.
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/image.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

// Where drawColorLegend drew (pixels, row 0 the top row). Outside `box` the image is untouched.
struct LegendLayout {
  int barX = 0, barY = 0, barWidth = 0, barHeight = 0;  // the colour bar: its top row is the range's high end
  int boxX = 0, boxY = 0, boxWidth = 0, boxHeight = 0;  // everything drawn: bar, frame, ticks, text
  glm::u8vec3 textColor{0};
};

// The smallest image a legend fits in.
inline constexpr int kMinLegendImageSize = 96;

// Draws the legend of `colors` (field, map, range) onto `image` over a scene with `background`.
// The bar's row at height t ∈ [0, 1] from its bottom shows the map's colour of
// range.x + t·(range.y − range.x) (mapFieldValue). Ticks and labels (four significant digits) mark
// `ticks` — the isosurfaces' values, say — or, when empty, the range's ends and middle; values
// outside the range are left out, and so is a label that would overlap the one above it (not its
// tick). Throws mfr::Error("legend", …) for an image smaller than kMinLegendImageSize on a side.
LegendLayout drawColorLegend(ImageRGBA8& image, const FieldColors& colors, const glm::vec3& background,
                             const std::vector<double>& ticks = {});

// A legend's value: four significant digits, as %.4g ("0.5", "1234", "1.235e+05").
std::string legendValueText(double value);

}  // namespace mfr
