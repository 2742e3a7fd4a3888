#include "gl_fixture.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace mfr::test {

gl::HeadlessContext& context() {
  static gl::HeadlessContext ctx(true);
  ctx.makeCurrent();
  return ctx;
}

namespace {
int channelDiff(std::uint32_t a, std::uint32_t b) {
  int m = 0;
  for (int c = 0; c < 4; ++c) m = std::max(m, std::abs(static_cast<int>((a >> (8 * c)) & 0xFF) - static_cast<int>((b >> (8 * c)) & 0xFF)));
  return m;
}
}  // namespace

ListComparison compareLists(const FragmentLists& oracle, const CapturedLists& gpu, std::uint32_t kNearest) {
  ListComparison r;
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x) {
      ++r.pixels;
      if (oracle.isAmbiguous(x, y)) continue;
      ++r.compared;
      const auto exact = oracle.pixel(x, y);
      const std::uint32_t n = static_cast<std::uint32_t>(exact.size());
      const std::uint32_t expected = kNearest > 0 ? std::min(n, kNearest) : n;
      const std::uint32_t got = gpu.count(x, y);
      std::ostringstream why;
      if (got != expected) {
        ++r.countMismatches;
        why << "pixel (" << x << "," << y << "): count " << got << ", oracle " << expected;
      } else {
        const Fragment* f = gpu.pixel(x, y);
        const std::uint32_t m = std::min<std::uint32_t>(expected, static_cast<std::uint32_t>(gpu.maxPerPixel));
        bool depthBad = false, colorBad = false;
        for (std::uint32_t i = 0; i < m; ++i) {
          const double tol = 1e-5 * std::max(1.0, std::abs(static_cast<double>(exact[i].depth)));
          if (std::abs(static_cast<double>(f[i].depth) - exact[i].depth) > tol) {
            if (!depthBad) why << "pixel (" << x << "," << y << ") fragment " << i << ": depth " << f[i].depth << ", oracle " << exact[i].depth;
            depthBad = true;
          } else if (channelDiff(f[i].color, exact[i].color) > 2) {
            if (!colorBad && !depthBad)
              why << "pixel (" << x << "," << y << ") fragment " << i << ": colour differs by " << channelDiff(f[i].color, exact[i].color);
            colorBad = true;
          }
        }
        r.depthMismatches += depthBad;
        r.colorMismatches += colorBad;
      }
      if (r.firstMismatch.empty()) r.firstMismatch = why.str();
    }
  return r;
}

ImageComparison compareImages(const FragmentLists& oracle, const ImageRGBA8& expected, const ImageRGBA8& actual,
                              int tolerance) {
  ImageComparison r;
  for (int y = 0; y < oracle.height; ++y)
    for (int x = 0; x < oracle.width; ++x) {
      if (oracle.isAmbiguous(x, y)) continue;
      ++r.compared;
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(expected.at(x, y)[c] - actual.at(x, y)[c]));
      r.maxDifference = std::max(r.maxDifference, d);
      if (d <= tolerance) ++r.within;
    }
  return r;
}

}  // namespace mfr::test
