#include "mfr/gpu_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include "common/bindings.h"
#include "gl/grid_upload.hpp"
#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/scene/section.hpp"
#include "methods/kbuffer_common.hpp"
#include "methods/method_util.hpp"
#include "reference/pixel_region.hpp"
#include "number_text.hpp"
#include "volume_step_note.hpp"

namespace mfr {

bool GpuRenderer::defaultFinishTiming() {
  return gl::queryContextInfo().renderer.find("llvmpipe") != std::string::npos;
}

Operation oitOperation() {
  return {"oit", "ops/oit.glsl", nullptr};
}

// Hybrid transparency (deep hybrid OIT, The Visual Computer 2022, §3.3): core from the resolve's
// sorted fragments, tail from the k-buffer family's tail SSBO, which the method binds itself.
static Operation hybridOperation() {
  return {"hybrid", "ops/hybrid.glsl", nullptr};
}

struct GpuRenderer::GpuVolume {
  Volume volume;
  std::shared_ptr<gl::Texture> grid;  // R32F, dims; shared by volumes with the same samples
  gl::Texture transfer;               // RGBA32F, MFR_VOLUME_TF_SIZE: (rgb, σ)
  std::size_t bytes = 0;              // the transfer table's, and the grid's unless an earlier volume holds it
  std::size_t sceneGridBytes = 0;     // the grid's when the scene holds it (surfaces coloured by it: a slice)
  double valueScale = 1.0;            // gl::gridValueScale: the texture's samples are the grid's times this
};

GpuRenderer::~GpuRenderer() = default;

void GpuRenderer::uploadVolumes(const Scene& scene) {
  const std::vector<Volume> visible = scene.visibleVolumes();
  // Grids the previous upload holds keep their textures, and volumes sharing samples share one;
  // textures no longer needed are freed (previous cleared) before new ones are allocated.
  std::vector<std::shared_ptr<gl::Texture>> textures(visible.size());
  const auto find = [&](const std::vector<std::shared_ptr<GpuVolume>>& among, const Volume& v) {
    for (const auto& g : among)
      if (g && g->volume.grid == v.grid) return g->grid;
    return std::shared_ptr<gl::Texture>();
  };
  for (std::size_t i = 0; i < visible.size(); ++i) textures[i] = find(volumes_, visible[i]);
  volumes_.clear();
  for (std::size_t i = 0; i < visible.size(); ++i) {
    const Volume& v = visible[i];
    auto gpu = std::make_shared<GpuVolume>();
    gpu->volume = v;
    const std::shared_ptr<gl::Texture> earlier = find(volumes_, v);
    gpu->grid = earlier ? earlier : textures[i];
    // A surface coloured by the volume holds its grid already (counted in the scene's bytes).
    const std::shared_ptr<gl::Texture> inScene = scene_->fieldGrid(v.grid.get());
    if (!gpu->grid) gpu->grid = inScene;
    if (!gpu->grid) gpu->grid = gl::uploadGrid(v.grid);
    gpu->valueScale = gl::gridValueScale(v.grid);
    const std::vector<glm::vec4> table = v.transfer.table();
    gpu->transfer = gl::createTexture1D(GL_RGBA32F, MFR_VOLUME_TF_SIZE);
    glTextureSubImage1D(gpu->transfer.id(), 0, 0, MFR_VOLUME_TF_SIZE, GL_RGBA, GL_FLOAT, table.data());
    gpu->bytes = (earlier || inScene ? 0 : v.grid->values.size() * sizeof(float)) + table.size() * sizeof(glm::vec4);
    gpu->sceneGridBytes = !earlier && inScene ? v.grid->values.size() * sizeof(float) : 0;
    volumes_.push_back(std::move(gpu));
  }
}

GpuRenderer::GpuRenderer(bool finishTiming) : finishTiming_(finishTiming) {}

void GpuRenderer::setScene(const Scene& original) {
  original.validate();
  // A section plane is applied as geometry (cut surfaces, caps); the volume keeps the plane. Without
  // one (or already cut) the scene is used as it is, not copied.
  std::optional<Scene> cut;
  if (original.section && !original.sectionCut) cut = sectionedScene(original);
  const Scene& scene = cut ? *cut : original;
  // Meshes the previous upload holds are shared, not uploaded again (an edit of colours, visibility,
  // the clip box, or a section that leaves parts uncut).
  scene_ = std::make_shared<const gl::GpuScene>(scene, scene_.get(), [this](const VolumeGrid* grid) {
    for (const auto& v : volumes_)
      if (v->volume.grid.get() == grid) return v->grid;
    return std::shared_ptr<gl::Texture>();
  });
  background_ = scene.background;
  csg_ = scene.csg;
  csgMirrored_ = csgMirroredPrimitives(scene);
  sceneName_ = scene.name;
  sceneBounds_ = scene.bounds();
  clipBox_ = scene.clipBox;
  section_ = scene.section;
  fieldColorsNote_ = fieldColorsNote(scene);
  uploadVolumes(scene);
  gl::checkErrors("scene upload");
}

void GpuRenderer::shareScene(const GpuRenderer& other) {
  if (!other.scene_) throw Error("render", "no scene loaded");
  scene_ = other.scene_;
  background_ = other.background_;
  csg_ = other.csg_;
  csgMirrored_ = other.csgMirrored_;
  sceneName_ = other.sceneName_;
  sceneBounds_ = other.sceneBounds_;
  clipBox_ = other.clipBox_;
  section_ = other.section_;
  fieldColorsNote_ = other.fieldColorsNote_;
  volumes_ = other.volumes_;
}

Method& GpuRenderer::prepare(const RenderRequest& request) {
  validateImageSize("--size", request.width, request.height);
  if (!scene_) throw Error("render", "no scene loaded");
  validateOperation(request.operation);
  if (!method_ || methodName_ != request.method) {
    method_ = createMethod(request.method);
    methodName_ = request.method;
  }
  operation_ = effectiveOperation(request.operation, &method_->info(), !volumes_.empty());
  thickness_ = zThicknessOf(request, sceneBounds_);
  if (operation_ == "volume") {
    if (volumes_.empty()) throw Error("--op volume", "scene '" + sceneName_ + "' has no visible volume");
    drawnVolumes_.clear();
    for (const auto& v : volumes_) drawnVolumes_.push_back(volumeAsRequested(request, v->volume));
    volumeStep_ = volumeStepOf(request, drawnVolumes_);
  }
  std::map<std::string, std::string> given = request.params;
  const auto& specs = method_->info().params;
  // Outside hybrid nothing reads a tail, and a flag that asks for one is refused rather than taken
  // without effect (bug hunts): a k-buffer's tail (its 20 bytes a pixel spent on nothing), vkb's
  // and dkb's exact tail (their notes said "every pixel exact" over a wrong image; off by default
  // there) and tail_runs, which refines the exact tail's bound.
  if (operation_ != "hybrid") {
    static constexpr std::pair<const char*, const char*> kHybridOnly[] = {
        {"tail", "only operation hybrid reads the tail (--op hybrid)"},
        {"exact_tail", "only operation hybrid composites a tail"},
        {"tail_runs", "refines exact_tail, which only operation hybrid uses"}};
    const Params asGiven(specs, given, request.method);  // a value that is no flag is named as such first
    for (const auto& [name, reason] : kHybridOnly)
      if (const auto it = given.find(name); it != given.end() && asGiven.flag(name))
        throw Error("--param " + std::string(name) + "=" + it->second,
                    std::string(reason) + "; this render's operation is " + operation_);
  }
  // Defaults of this operation (defaultValueFor: fkb's tail and the exact tail are off outside hybrid).
  for (const ParamSpec& spec : specs)
    if (!given.contains(spec.name) && defaultValueFor(spec, operation_) != spec.defaultValue)
      given[spec.name] = defaultValueFor(spec, operation_);
  const Params params(specs, given, request.method);
  method_->configure(request.width, request.height, params);
  if (operation_ == "hybrid") {
    // The tail sums exist only in the k-buffer family's tail hook.
    const auto* kb = dynamic_cast<const KBufferFamily*>(method_.get());
    if (!kb)
      throw Error("--op hybrid",
                  "method " + request.method + " keeps no tail (use a k-buffer method with --param tail=true)");
    if (!kb->tailEnabled()) throw Error("--op hybrid", "needs --param tail=true with method " + request.method);
  }
  if (operation_ == "csg") {
    if (clipBox_) throw Error("--op csg", kCsgClipRefusal);
    if (csg_.empty())
      throw Error("--op csg", "scene '" + sceneName_ + "' has no CSG tree (a \"csg\" key in an .mfrscene file)");
    if (!method_->info().objectPayload) {
      std::string list;
      for (const RegistryEntry& e : methodRegistry())
        if (const MethodInfo* info = findMethodInfo(e.name); info && info->objectPayload)
          list += (list.empty() ? "" : ", ") + e.name;
      throw Error("--op csg", "method " + request.method + " cannot store object ids (use " + list + ")");
    }
  }
  gl::checkErrors(("configure " + request.method).c_str());
  return *method_;
}

void GpuRenderer::beginResolveCount() {
  if (resolveCut_.id() == 0) resolveCut_ = gl::createBuffer(sizeof(std::uint32_t));
  const std::uint32_t zero = 0;
  glClearNamedBufferData(resolveCut_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_RESOLVE_CUT, resolveCut_.id());
}

std::uint32_t GpuRenderer::resolveCount() const {
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::uint32_t cut = 0;
  glGetNamedBufferSubData(resolveCut_.id(), 0, sizeof cut, &cut);
  return cut;
}

namespace {

// The point the GPU's float positions are taken relative to (GpuScene::relativeFrame): on the view
// axis, at the depth d that keeps a float's rounding smallest against the size of a pixel over the
// depths [z0, z1] where the scene lies (within near … far). A pixel spans a length proportional
// to z in a perspective view, so the worst of |z − d| / z is least at the harmonic mean
// 2·z0·z1 / (z0 + z1) — the eye itself when something lies at it, the scene's depth in a narrow
// view from far away. In an orthographic view a pixel spans the same length at every depth, so no
// depth is finer than another: the target's, where the user looks (the viewer zooms towards the
// cursor by moving it there), within [z0, z1] (review 29: the middle of a 100-unit hull's depths
// drew a 1e-4 assembly just in front of the eye, inside the hull, 28-62 pixels off the oracle). Relative to the eye in
// every view (hunt 31), an orthographic view from 3.7e4 away, 0.05 high, or a perspective one 8e-5° wide, drew 0.01
// spheres jagged and mis-sorted (review 28): the viewer zooms an orthographic view by its height, leaving the eye far
// back.
glm::dvec3 floatOrigin(const Camera& camera, const Bounds& scene) {
  const glm::dvec3 forward = camera.forward();
  if (!scene.valid()) return camera.eye;
  double z0 = std::numeric_limits<double>::infinity(), z1 = -z0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p((corner & 1) ? scene.max.x : scene.min.x, (corner & 2) ? scene.max.y : scene.min.y,
                       (corner & 4) ? scene.max.z : scene.min.z);
    const double z = glm::dot(p - camera.eye, forward);
    z0 = std::min(z0, z);
    z1 = std::max(z1, z);
  }
  z0 = std::max(z0, camera.nearPlane);
  z1 = std::min(z1, camera.farPlane);
  if (!(z0 <= z1) || !std::isfinite(z0) || !std::isfinite(z1)) return camera.eye;
  const double depth = camera.projection == Projection::Orthographic
                           ? std::clamp(glm::dot(camera.target - camera.eye, forward), z0, z1)
                       : z0 <= 0.0 ? 0.0
                                   : 2.0 * z0 * z1 / (z0 + z1);
  return camera.eye + forward * depth;
}

}  // namespace

FrameContext GpuRenderer::frameContext(const Camera& camera, int width, int height, gl::PassTimer& timer) const {
  const double aspect = static_cast<double>(width) / height;
  gl::FrameUniforms frame = gl::GpuScene::relativeFrame(camera.projectionMatrix(aspect) * camera.viewMatrix(), clipBox_,
                                                        floatOrigin(camera, sceneBounds_));
  frame.viewDir = glm::vec3(camera.forward());
  frame.payload = operation_ == "csg" ? MFR_PAYLOAD_OBJECT : MFR_PAYLOAD_COLOR;
  return FrameContext{*scene_,
                      frame,
                      background_,
                      width,
                      height,
                      timer,
                      static_cast<float>(thickness_),
                      glm::vec4(camera.depthToEye())};
}

Stats GpuRenderer::renderTo(GLuint target, const Camera& camera, const RenderRequest& request) {
  Method& method = prepare(request);
  gl::PassTimer timer(finishTiming_);
  const FrameContext ctx = frameContext(camera, request.width, request.height, timer);
  glBindFramebuffer(GL_FRAMEBUFFER, target);
  glViewport(0, 0, request.width, request.height);
  method.capture(ctx);
  gl::checkErrors(("capture " + request.method).c_str());
  glBindFramebuffer(GL_FRAMEBUFFER, target);
  glViewport(0, 0, request.width, request.height);
  beginResolveCount();
  if (operation_ == "csg") {
    renderCsg(ctx, method);
  } else if (operation_ == "volume") {
    const VolumeRaySetup setup =
        volumeRaySetup(drawnVolumes_, camera, request.width, request.height, volumeStep_, clipBox_, section_);
    method.resolve(
        ctx,
        Operation{"volume", "ops/volume.glsl", [&](const gl::Program& p) {
                    p.set("uInvViewProj", setup.invViewProj);
                    p.set("uViewport", setup.viewport);
                    p.set("uVolumeStep", setup.step);
                    p.set("uVolumeCount", static_cast<int>(setup.media.size()));
                    for (std::size_t i = 0; i < setup.media.size(); ++i) {
                      const VolumeMedium& m = setup.media[i];
                      const std::string at = "[" + std::to_string(i) + "]";
                      p.set(("uWorldToGrid" + at).c_str(), m.worldToGrid);
                      p.set(("uGridDims" + at).c_str(), m.dims);
                      // Scaled as the texture's samples are (gl::uploadGrid).
                      const double scale = volumes_[i]->valueScale;
                      const TransferFunction& tf = drawnVolumes_[i].transfer;
                      p.set(("uTfLow" + at).c_str(), scale == 1.0 ? m.tfLow : static_cast<float>(tf.low() * scale));
                      p.set(("uTfHigh" + at).c_str(), scale == 1.0 ? m.tfHigh : static_cast<float>(tf.high() * scale));
                      p.set(("uVolumeShading" + at).c_str(), m.shading ? 1 : 0);
                      glBindTextureUnit(MFR_TEX_VOLUME + static_cast<GLuint>(i), volumes_[i]->grid->id());
                      glBindTextureUnit(MFR_TEX_VOLUME_TF + static_cast<GLuint>(i), volumes_[i]->transfer.id());
                    }
                    p.set("uClip", setup.clip ? 1 : 0);
                    p.set("uClipMin", setup.clipMin);
                    p.set("uClipMax", setup.clipMax);
                    p.set("uSection", setup.section ? 1 : 0);
                    p.set("uSectionPlane", setup.sectionPlane);
                  }});
  } else if (operation_ == "zthickness") {
    method.resolve(ctx, Operation{"zthickness", "ops/zthickness.glsl", [&](const gl::Program& p) {
                                    p.set("uZThickness", ctx.zThickness);
                                    p.set("uDepthToEye", ctx.depthToEye);
                                  }});
  } else {
    method.resolve(ctx, operation_ == "hybrid" ? hybridOperation() : oitOperation());
  }
  gl::checkErrors(("resolve " + request.method).c_str());
  Stats stats = method.stats();
  if (const std::uint32_t cut = resolveCount(); cut > 0) {
    // The same pixels may have lost fragments to a full structure too: at least this many did.
    stats.overflow = true;
    stats.overflowPixels = std::max<std::uint64_t>(stats.overflowPixels, cut);
    stats.notes.emplace_back("resolve cut", std::to_string(cut) +
                                                " pixels resolved short: this GL ended their loops early "
                                                "(llvmpipe: 65,535 loop steps per pixel, which lists of about 700 "
                                                "fragments reach); their images lack fragments");
  }
  if (operation_ == "csg") {
    // The operation's own buffer: each pixel's visible (object + 1, depth), 8 bytes.
    const std::uint64_t csgBytes = 8ull * static_cast<std::uint64_t>(request.width) * request.height;
    stats.bytesAllocated += csgBytes;
    stats.bytesUsed += csgBytes;
    stats.passes += 1;  // the shading pass
    stats.notes.emplace_back("csg buffer (bytes)", std::to_string(csgBytes));
  }
  if (!fieldColorsNote_.empty()) stats.notes.emplace_back("field colours", fieldColorsNote_);
  // Window depths are 32-bit floats: given near and far planes that cannot order what is drawn
  // are said, by every program that draws through here (mfrview said nothing).
  if (const std::optional<std::string> note = camera.depthPrecisionNote(sceneBounds_))
    stats.notes.emplace_back("depth precision", *note);
  if (operation_ == "zthickness") stats.notes.emplace_back("z-thickness", numberText(thickness_));
  if (operation_ == "volume") {
    stats.notes.emplace_back("volume step", numberText(volumeStep_));
    if (const auto longer = volumeLongRayStepNote(drawnVolumes_, volumeStep_))
      stats.notes.emplace_back("volume step, long rays", *longer);
    std::size_t bytes = 0, shared = 0;
    for (const auto& v : volumes_) {
      bytes += v->bytes;
      shared += v->sceneGridBytes;
    }
    stats.notes.emplace_back("volumes", std::to_string(volumes_.size()));
    stats.notes.emplace_back("volume (bytes)", std::to_string(bytes));
    // Grids that surfaces coloured by the volume hold (a section's slice): counted with the scene,
    // not above, but on the GPU all the same.
    if (shared > 0) stats.notes.emplace_back("volume grid held by the scene (bytes)", std::to_string(shared));
    stats.notes.emplace_back("volume shading", volumeShadingNote(drawnVolumes_));
    if (const std::string fields = volumeFieldsNote(drawnVolumes_); !fields.empty())
      stats.notes.emplace_back("volume fields", fields);
  } else if (!volumes_.empty()) {
    stats.notes.emplace_back("volume", "not drawn (operation " + operation_ + ")");
  }
  lastWidth_ = request.width;
  lastHeight_ = request.height;
  stats.operation = operation_;
  stats.passTimesMs = timer.collect();
  return stats;
}

// Image-space CSG: the method's resolve runs ops/csg.glsl, which records each pixel's visible
// surface (object + 1, depth bits) and writes the background; then the scene is drawn once more
// and only the recorded fragment of each pixel writes its shaded colour (ops/csg_shade.geom.frag).
void GpuRenderer::renderCsg(const FrameContext& ctx, Method& method) {
  const std::size_t pixels = static_cast<std::size_t>(ctx.width) * ctx.height;
  if (csgPixels_ != pixels) {
    csgVisible_ = gl::createBuffer(pixels * 8);
    csgPixels_ = pixels;
  }
  const std::vector<std::uint32_t> program = csg_.program();
  const std::vector<std::uint32_t> primitives = csg_.primitives();
  const Operation csg{"csg", "ops/csg.glsl", [&](const gl::Program& p) {
                        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_CSG, csgVisible_.id());
                        p.set("uCsgWidth", ctx.width);
                        p.set("uCsgProgramLength", static_cast<unsigned>(program.size()));
                        p.set("uCsgPrimitiveCount", static_cast<unsigned>(primitives.size()));
                        p.set("uCsgMirrored", csgMirrored_);
                        p.set("uCsgProgram", std::span<const std::uint32_t>(program));
                        p.set("uCsgPrimitives", std::span<const std::uint32_t>(primitives));
                      }};
  method.resolve(ctx, csg);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  if (!csgShade_.id())
    csgShade_ = gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "ops/csg_shade.geom.frag"}});
  GeometryPassState state(true, false);  // colour writes on, no depth test: one fragment per pixel passes
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_CSG, csgVisible_.id());
  csgShade_.set("uCsgWidth", ctx.width);
  gl::FrameUniforms frame = ctx.frame;
  frame.payload = MFR_PAYLOAD_COLOR;
  ctx.timer.begin("csg shade");
  ctx.scene.draw(csgShade_, frame);
  ctx.timer.end();
}

void GpuRenderer::ensureFramebuffer(int width, int height) {
  if (fbo_ && fboWidth_ == width && fboHeight_ == height) return;
  color_ = gl::createTexture2D(GL_RGBA8, width, height);
  fbo_ = gl::createFramebuffer();
  glNamedFramebufferTexture(fbo_.id(), GL_COLOR_ATTACHMENT0, color_.id(), 0);
  fboWidth_ = width;
  fboHeight_ = height;
}

RenderOutput GpuRenderer::render(const Camera& camera, const RenderRequest& request) {
  validateImageSize("--size", request.width, request.height);
  ensureFramebuffer(request.width, request.height);
  RenderOutput out;
  out.stats = renderTo(fbo_.id(), camera, request);
  out.image = ImageRGBA8(request.width, request.height);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(color_.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(out.image.pixels.size()),
                    out.image.pixels.data());
  flipVertically(out.image);
  gl::checkErrors("read-back");
  return out;
}

// GL rows (bottom-up) → image rows (top-down).
static std::vector<std::uint32_t> flipRows(const std::vector<std::uint32_t>& gl, int width, int height) {
  std::vector<std::uint32_t> out(gl.size());
  for (int y = 0; y < height; ++y)
    std::copy_n(gl.begin() + static_cast<std::ptrdiff_t>(height - 1 - y) * width, width,
                out.begin() + static_cast<std::ptrdiff_t>(y) * width);
  return out;
}

std::vector<std::uint32_t> GpuRenderer::kMap() const {
  if (!method_ || lastWidth_ == 0) return {};
  const std::vector<std::uint32_t> map = method_->capacityMap();
  if (map.size() != static_cast<std::size_t>(lastWidth_) * lastHeight_) return {};
  return flipRows(map, lastWidth_, lastHeight_);
}

std::vector<std::uint32_t> GpuRenderer::depthComplexity(const Camera& camera, int width, int height) {
  validateImageSize("--size", width, height);
  if (!scene_) throw Error("depth complexity", "no scene loaded");
  if (!countProgram_.id())
    countProgram_ = gl::Program(
        {{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "common/depth_complexity.geom.frag"}});
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  if (countPixels_ != pixels) {  // kept between calls: the viewer asks again on every view change
    counts_ = gl::createBuffer(pixels * 4);
    countPixels_ = pixels;
  }
  const GLuint zero = 0;
  glClearNamedBufferData(counts_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  // The render framebuffer gives the pass its size; colour writes stay off (GeometryPassState).
  ensureFramebuffer(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
  glViewport(0, 0, width, height);
  gl::PassTimer timer;
  const FrameContext ctx = frameContext(camera, width, height, timer);
  {
    GeometryPassState state;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, counts_.id());
    countProgram_.use();
    countProgram_.set("uDcWidth", width);
    scene_->draw(countProgram_, ctx.frame);
  }
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> raw(pixels);
  glGetNamedBufferSubData(counts_.id(), 0, static_cast<GLsizeiptr>(pixels * 4), raw.data());
  gl::checkErrors("depth complexity");
  timer.collect();
  return flipRows(raw, width, height);
}

CapturedLists GpuRenderer::capture(const Camera& camera, const RenderRequest& request, int maxPerPixel,
                                   const PixelRect& region) {
  Method& method = prepare(request);
  const int w = request.width, h = request.height;
  const PixelRect r = regionInImage(region, w, h);
  if (maxPerPixel < 1) throw Error("capture", "at least one fragment per pixel must be kept");
  const std::size_t pixels = static_cast<std::size_t>(r.width) * r.height;
  gl::Buffer fragments = gl::createBuffer(pixels * static_cast<std::size_t>(maxPerPixel) * 8);
  gl::Buffer counts = gl::createBuffer(pixels * 4);
  const GLuint zero = 0;
  glClearNamedBufferData(counts.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearNamedBufferData(fragments.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  // The region in GL window coordinates (rows bottom-up).
  const glm::ivec2 glOrigin(r.x, h - r.y - r.height);
  Operation dump{"dump", "ops/dump.glsl", [&](const gl::Program& p) {
                   glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_DUMP, fragments.id());
                   glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_DUMP_COUNT, counts.id());
                   p.set("uDumpMax", static_cast<unsigned>(maxPerPixel));
                   p.set("uDumpOrigin", glOrigin);
                   p.set("uDumpSize", glm::ivec2(r.width, r.height));
                 }};
  gl::Texture color = gl::createTexture2D(GL_RGBA8, w, h);
  gl::Framebuffer fbo = gl::createFramebuffer();
  glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0, color.id(), 0);
  gl::PassTimer timer;
  const FrameContext ctx = frameContext(camera, w, h, timer);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, w, h);
  method.capture(ctx);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, w, h);
  beginResolveCount();  // the shared resolve writes it: bound, as for a render
  method.resolve(ctx, dump);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  gl::checkErrors(("capture (dump) " + request.method).c_str());
  timer.collect();

  CapturedLists out;
  out.x0 = r.x;
  out.y0 = r.y;
  out.width = r.width;
  out.height = r.height;
  out.maxPerPixel = maxPerPixel;
  std::vector<std::uint32_t> rawCounts(pixels);
  std::vector<std::uint32_t> raw(pixels * static_cast<std::size_t>(maxPerPixel) * 2);
  glGetNamedBufferSubData(counts.id(), 0, static_cast<GLsizeiptr>(rawCounts.size() * 4), rawCounts.data());
  glGetNamedBufferSubData(fragments.id(), 0, static_cast<GLsizeiptr>(raw.size() * 4), raw.data());
  out.counts.resize(pixels);
  out.fragments.resize(pixels * static_cast<std::size_t>(maxPerPixel));
  // GL rows are bottom-up; CapturedLists uses image rows (top-down) like the oracle.
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const std::size_t src = static_cast<std::size_t>(r.height - 1 - y) * r.width + x;
      const std::size_t dst = static_cast<std::size_t>(y) * r.width + x;
      out.counts[dst] = rawCounts[src];
      for (int i = 0; i < maxPerPixel; ++i) {
        const std::size_t s = (src * static_cast<std::size_t>(maxPerPixel) + static_cast<std::size_t>(i)) * 2;
        Fragment& f = out.fragments[dst * static_cast<std::size_t>(maxPerPixel) + static_cast<std::size_t>(i)];
        f.color = raw[s];
        std::memcpy(&f.depth, &raw[s + 1], sizeof(float));
      }
    }
  return out;
}

}  // namespace mfr
