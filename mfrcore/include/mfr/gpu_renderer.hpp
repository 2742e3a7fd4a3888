#pragma once
// Renders a scene with a registered GPU method into an offscreen RGBA8 framebuffer on the
// current OpenGL 4.5 context (the CLI's headless EGL context or the viewer's Qt context), and
// reads back images, Stats, or — for tests — every pixel's sorted fragment list.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mfr/gl/gpu_scene.hpp"
#include "mfr/methods/method.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/render.hpp"

namespace mfr {

// Per-pixel sorted lists as a GPU method captured them, for a rectangle of the image (x0, y0:
// its top-left pixel; width × height: its size; the whole image unless a region was asked for).
// Pixels are addressed in image coordinates (y = 0 top row).
struct CapturedLists {
  int x0 = 0;
  int y0 = 0;
  int width = 0;
  int height = 0;
  int maxPerPixel = 0;                // fragments kept per pixel in `fragments`
  std::vector<std::uint32_t> counts;  // fragments the method holds per pixel
  std::vector<Fragment> fragments;    // width*height*maxPerPixel, the first min(count, max) valid
  [[nodiscard]] std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y - y0) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x - x0);
  }
  [[nodiscard]] std::uint32_t count(int x, int y) const { return counts[index(x, y)]; }
  [[nodiscard]] const Fragment* pixel(int x, int y) const {
    return &fragments[index(x, y) * static_cast<std::size_t>(maxPerPixel)];
  }
};

class GpuRenderer {
 public:
  // Needs a current 4.5 core context. finishTiming: time passes with glFinish + CPU clock (see
  // gl::PassTimer); the default picks it on llvmpipe.
  GpuRenderer() : GpuRenderer(defaultFinishTiming()) {}
  explicit GpuRenderer(bool finishTiming);
  static bool defaultFinishTiming();
  ~GpuRenderer();
  GpuRenderer(const GpuRenderer&) = delete;
  GpuRenderer& operator=(const GpuRenderer&) = delete;

  // Uploads the scene (validated: throws mfr::Error when empty).
  void setScene(const Scene& scene);
  // Draws the scene `other` uploaded, without a second copy of its buffers (the viewer's preview
  // renderers); a later setScene on either renderer replaces only its own.
  void shareScene(const GpuRenderer& other);
  // Renders into the internal framebuffer and reads it back. Throws mfr::Error for an unknown
  // method/operation/parameter or a bad size.
  RenderOutput render(const Camera& camera, const RenderRequest& request);
  // Renders into framebuffer `target` (0 = default) at the request size, no read-back (viewer).
  Stats renderTo(GLuint target, const Camera& camera, const RenderRequest& request);
  // Per-pixel capacity k(p) of the last frame's method (image rows top-down, width·height of that
  // frame); empty when the method has none (A-buffers, peeling, WBOIT, MBOIT) or before a frame.
  [[nodiscard]] std::vector<std::uint32_t> kMap() const;
  // Exact fragment count n(p) per pixel of the scene from this camera (image rows top-down), by
  // one rasterisation pass with colour writes off: the GPU's depth complexity.
  std::vector<std::uint32_t> depthComplexity(const Camera& camera, int width, int height);
  // The method object of the last request (nullptr before one): tests and diagnostics reach a
  // method's own read-backs through it.
  [[nodiscard]] Method* method() const { return method_.get(); }
  // Captures with the method and resolves with the "dump" operation (tests, diagnostics, the
  // pixel probe): the sorted lists of `region` (image coordinates; empty: the whole image), at most
  // maxPerPixel fragments each. Throws mfr::Error for a region outside the image or maxPerPixel < 1.
  CapturedLists capture(const Camera& camera, const RenderRequest& request, int maxPerPixel,
                        const PixelRect& region = {});

 private:
  Method& prepare(const RenderRequest& request);
  // The internal RGBA8 framebuffer (render(), depthComplexity()) at this size.
  void ensureFramebuffer(int width, int height);
  FrameContext frameContext(const Camera& camera, int width, int height, gl::PassTimer& timer) const;

  std::shared_ptr<const gl::GpuScene> scene_;
  glm::vec3 background_{1.0f};
  std::string methodName_;
  std::string operation_ = "oit";  // of the prepared request, "auto" resolved
  std::unique_ptr<Method> method_;
  int lastWidth_ = 0, lastHeight_ = 0;
  gl::Program countProgram_;
  gl::Framebuffer fbo_;
  gl::Texture color_;
  int fboWidth_ = 0, fboHeight_ = 0;
  gl::Buffer counts_;  // depthComplexity's per-pixel counters
  std::size_t countPixels_ = 0;
  // Operation "csg": the scene's tree, the per-pixel visible (object + 1, depth) of the resolve,
  // and the shading pass that draws it.
  void renderCsg(const FrameContext& ctx, Method& method);
  CsgTree csg_;
  std::uint32_t csgMirrored_ = 0;  // csgMirroredPrimitives of the scene
  std::string sceneName_;
  Bounds sceneBounds_;
  std::optional<Bounds> clipBox_;        // Scene::clipBox
  std::optional<SectionPlane> section_;  // Scene::section (the surfaces come cut; the volume march is cropped)
  double thickness_ = 0.0;               // operation "zthickness" of the prepared request (scene units)
  // Operation "volume": the scene's visible volumes on the GPU (shared with shareScene; a new
  // scene with the same grids keeps their textures and uploads only the transfer tables).
  struct GpuVolume;
  std::vector<std::shared_ptr<GpuVolume>> volumes_;
  double volumeStep_ = 0.0;           // of the prepared request (scene units)
  std::string fieldColorsNote_;       // of the scene set (fieldColorsNote)
  std::vector<Volume> drawnVolumes_;  // of the prepared request (volumesAsRequested: its shading)
  void uploadVolumes(const Scene& scene);
  gl::Buffer csgVisible_;
  gl::Buffer resolveCut_;  // common/resolve.glsl's count of pixels it could not resolve whole
  // Zeroes and binds resolveCut_ before a resolve (every resolve that includes the shared driver
  // writes it); resolveCount() reads it after.
  void beginResolveCount();
  [[nodiscard]] std::uint32_t resolveCount() const;
  std::size_t csgPixels_ = 0;
  gl::Program csgShade_;
  bool finishTiming_ = false;
};

// The oracle-independent OIT operation ("over" with the background) and the test dump operation.
Operation oitOperation();

}  // namespace mfr
