#pragma once
// The CPU oracle: exact per-pixel fragment lists by ray casting in double precision, independent of
// any GPU code. One ray through each pixel centre — the sample point the rasteriser uses — and
// every intersection with every visible triangle between the near and far planes, shaded with the
// shared shading function (shaders/common/shading.h), sorted front to back.
#include <cstdint>
#include <span>
#include <vector>

#include "mfr/scene/scene.hpp"

namespace mfr {

// A fragment as the GPU methods store it, plus what operations beyond OIT need.
struct Fragment {
  float depth = 0.0f;       // window depth in [0,1] (gl_FragCoord.z)
  std::uint32_t color = 0;  // shaded RGBA, packed like GLSL packUnorm4x8 (R in the low byte)
  std::uint32_t objectId = 0;
  bool frontFacing = false;  // counter-clockwise in window space, like gl_FrontFacing
  // Oracle fragments: |∂z/∂x| + |∂z/∂y|, the window depth's change per pixel on the fragment's
  // plane (0 in fragments read back from a GPU). See rasterDepthTolerance.
  float depthSlope = 0.0f;
};

// GL rasterisers snap vertex positions to 2^-GL_SUBPIXEL_BITS of a pixel (8 bits on llvmpipe and
// on NVIDIA's driver), and some (NVIDIA) interpolate depth over the snapped triangle: its plane
// moves by up to this much along x and y, and gl_FragCoord.z with it.
inline constexpr double kSubpixelStep = 1.0 / 256.0;

// How far a rasteriser's window depth for an exact fragment may lie from the exact value:
// `relative` of the depth (float rounding) plus the plane's change over one subpixel step.
inline double rasterDepthTolerance(const Fragment& exact, double relative = 1e-5) {
  const double z = exact.depth < 0.0f ? -static_cast<double>(exact.depth) : static_cast<double>(exact.depth);
  return relative * (z > 1.0 ? z : 1.0) + kSubpixelStep * static_cast<double>(exact.depthSlope);
}

// A rectangle of pixels in image coordinates (y = 0 is the top row); empty means the whole image.
struct PixelRect {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
  [[nodiscard]] bool empty() const { return width <= 0 || height <= 0; }
  [[nodiscard]] bool contains(int px, int py) const { return px >= x && py >= y && px - x < width && py - y < height; }
};

struct OracleOptions {
  // Screen-space distance (pixels) under which a pixel centre counts as lying on a triangle edge:
  // there rasterisation tie rules and vertex snapping (1/256 px) decide, so tests exclude it.
  double edgeEpsilon = 0.02;
  // Relative depth difference under which two fragments of a pixel count as tied in depth; the
  // subpixel step is added too (each fragment's kSubpixelStep · depthSlope): a rasteriser that
  // snaps vertices may order such fragments either way.
  double depthTieEpsilon = 1e-6;
  int threads = 0;  // 0: hardware concurrency
  // Cast only these pixels (a probe of one pixel, a zoomed-in check); the others get empty lists
  // and no flags. Empty: the whole image. A rectangle not inside the image throws mfr::Error.
  PixelRect region;
  // Test every triangle against every ray instead of each pixel's bin of the triangles near it:
  // the reference that the broad phase's tests compare with (pixels × triangles exact tests).
  bool everyTriangleACandidate = false;
  // Count the fragments without keeping them: offsets and flags are filled, `fragments` stays
  // empty (so pixel() must not be called). For depth-complexity statistics (`mfr info`), whose
  // lists would need 20 bytes a fragment (1.8 GB for 1,000 coincident atoms at 256x256).
  bool countsOnly = false;
};

// Exact fragment lists of one image. Pixel (x, y) uses image coordinates: y = 0 is the top row.
struct FragmentLists {
  int width = 0;
  int height = 0;
  std::vector<std::uint32_t> offsets;  // width*height+1 prefix offsets into fragments
  std::vector<Fragment> fragments;     // per pixel, sorted by depth (near first)
  // Per pixel bit flags: kEdge (centre within edgeEpsilon of a projected triangle edge, hit or
  // missed), kDepthTie (two fragments closer than depthTieEpsilon plus their subpixel-snap
  // tolerance: their order is undefined).
  std::vector<std::uint8_t> flags;

  static constexpr std::uint8_t kEdge = 1;
  static constexpr std::uint8_t kDepthTie = 2;

  [[nodiscard]] std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * width + x; }
  [[nodiscard]] std::span<const Fragment> pixel(int x, int y) const {
    const std::size_t i = index(x, y);
    return {fragments.data() + offsets[i], fragments.data() + offsets[i + 1]};
  }
  [[nodiscard]] std::uint32_t count(int x, int y) const {
    const std::size_t i = index(x, y);
    return offsets[i + 1] - offsets[i];
  }
  // The same by pixel index (index(x, y)).
  [[nodiscard]] std::span<const Fragment> pixel(std::size_t i) const {
    return {fragments.data() + offsets[i], fragments.data() + offsets[i + 1]};
  }
  // n(p) of every pixel, in index order.
  [[nodiscard]] std::vector<std::uint32_t> counts() const;
  [[nodiscard]] std::uint32_t maxCount() const;
  [[nodiscard]] bool isEdge(int x, int y) const { return (flags[index(x, y)] & kEdge) != 0; }
  [[nodiscard]] bool isAmbiguous(int x, int y) const { return flags[index(x, y)] != 0; }
};

// What castFragments refuses before it casts, for the GPU renderers to refuse the same (they drew
// nothing, or garbage, and said nothing): a singular camera (a scene scaled to infinity), a visible
// mesh that fails Mesh::validate (a non-finite vertex), no visible triangle of non-zero world
// area and no visible volume. The scene as given (a section is not applied). Throws mfr::Error;
// "nothing to render" names `what`, by default "scene 'NAME'" (a command that loaded the scene from
// a file names the file).
void checkDrawable(const Scene& scene, const Camera& camera, int width, int height, const std::string& what = {});

// Throws mfr::Error for a zero-size image or an empty scene.
FragmentLists castFragments(const Scene& scene, const Camera& camera, int width, int height,
                            const OracleOptions& options = {});

}  // namespace mfr
