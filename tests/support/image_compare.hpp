#pragma once
// Image against image at every pixel off the projected triangle edges (where rasterisation tie
// rules, not the method, decide which surface a pixel sees): the comparison the operation tests
// (volume, zthickness) share. Header-only, so that both tests/gl and tests/data can use it.
#include <algorithm>
#include <cstddef>
#include <cstdlib>

#include "mfr/image.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr::test {

// The largest difference of the RGB channels of one pixel (alpha is not compared).
inline int rgbDifference(const ImageRGBA8& a, const ImageRGBA8& b, int x, int y) {
  int diff = 0;
  for (int ch = 0; ch < 3; ++ch) diff = std::max(diff, std::abs(int(a.at(x, y)[ch]) - int(b.at(x, y)[ch])));
  return diff;
}

// The largest rgbDifference over the whole image.
inline int maxRgbDifference(const ImageRGBA8& a, const ImageRGBA8& b) {
  int diff = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) diff = std::max(diff, rgbDifference(a, b, x, y));
  return diff;
}

// How many pixels differ by more than `threshold` in some RGB channel (an edit is not a no-op).
inline std::size_t pixelsDifferingBy(const ImageRGBA8& a, const ImageRGBA8& b, int threshold) {
  std::size_t n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) n += rgbDifference(a, b, x, y) > threshold ? 1 : 0;
  return n;
}

// Pixels whose RGB differs, by where they lie: in the corner a legend is drawn in (the right half,
// below the top quarter: mfr render --legend) or anywhere else.
struct CornerDifference {
  std::size_t inCorner = 0, elsewhere = 0;
};
inline CornerDifference legendCornerDifference(const ImageRGBA8& a, const ImageRGBA8& b) {
  CornerDifference d;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (rgbDifference(a, b, x, y) > 0) ++(x >= a.width / 2 && y >= a.height / 4 ? d.inCorner : d.elsewhere);
  return d;
}

struct OffEdgeComparison {
  std::size_t compared = 0;  // pixels off the edges
  std::size_t within = 0;    // of those, within the tolerance
  int maxDifference = 0;
};

// Compares every pixel the oracle does not mark as an edge; visit(x, y, diff) sees each one, for
// a test's own counts (which pixels are coincident, which only the medium covers, …).
template <class Visit>
OffEdgeComparison compareOffEdges(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                                  int tolerance, Visit&& visit) {
  OffEdgeComparison c;
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x) {
      if (oracle.isEdge(x, y)) continue;
      const int diff = rgbDifference(expected, actual, x, y);
      ++c.compared;
      c.within += diff <= tolerance;
      c.maxDifference = std::max(c.maxDifference, diff);
      visit(x, y, diff);
    }
  return c;
}

}  // namespace mfr::test
