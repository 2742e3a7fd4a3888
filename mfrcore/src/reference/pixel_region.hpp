#pragma once
// The region of an image a pass works on (OracleOptions::region, GpuRenderer::capture): the
// oracle and the GPU dump check it the same way.
#include <string>

#include "mfr/error.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr {

// `region`, or the whole width × height image when it is empty; throws mfr::Error("pixel region",
// …) for a rectangle not inside the image.
inline PixelRect regionInImage(const PixelRect& region, int width, int height) {
  if (region.empty()) return {0, 0, width, height};
  if (region.x < 0 || region.y < 0 || static_cast<long long>(region.x) + region.width > width ||
      static_cast<long long>(region.y) + region.height > height)
    throw Error("pixel region", std::to_string(region.width) + "x" + std::to_string(region.height) + " at (" +
                                    std::to_string(region.x) + ", " + std::to_string(region.y) +
                                    ") is not inside the " + std::to_string(width) + "x" + std::to_string(height) +
                                    " image");
  return region;
}

}  // namespace mfr
