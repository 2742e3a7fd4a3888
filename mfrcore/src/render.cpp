#include "mfr/render.hpp"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <mutex>

#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/budget/memory_model.hpp"
#include "mfr/budget/optimal_k.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/reference/oracle.hpp"
#include "number_text.hpp"
#include "volume_step_note.hpp"
#include "common/bindings.h"

namespace mfr {

void validateImageSize(const std::string& what, int width, int height) {
  if (width <= 0 || height <= 0)
    throw Error(what, "image size must be positive (got " + std::to_string(width) + "x" + std::to_string(height) + ")");
  if (width > 16384 || height > 16384) throw Error(what, "image size above 16384 pixels per side");
}

const std::string& operationNames() {
  static const std::string names = "auto, oit, hybrid, csg, zthickness, volume";
  return names;
}

void validateOperation(const std::string& operation) {
  for (const char* name : {"auto", "oit", "hybrid", "csg", "zthickness", "volume"})
    if (operation == name) return;
  throw Error("--op " + operation, "unknown operation (available: " + operationNames() + ")");
}

double zThicknessDefault(const Bounds& sceneBounds) {
  return sceneBounds.valid() ? 0.01 * glm::length(sceneBounds.max - sceneBounds.min) : 0.01;
}

double zThicknessOf(const RenderRequest& request, const Bounds& sceneBounds) {
  if (!std::isfinite(request.thickness) || request.thickness < 0.0)
    throw Error("--thickness", "must be a positive length in scene units (got " + numberText(request.thickness) + ")");
  if (request.thickness > 0.0) {
    // Both renderers take eye depths and the slab σ = −ln(1 − α)/τ as floats: a slab shorter than
    // a few units of a depth's last place ends where it begins (the image came out blank, and the
    // oracle agreed), and above 1e30 σ falls towards the denormals (a τ of 3.4e38 was infinite).
    const double diagonal = sceneBounds.valid() ? glm::length(sceneBounds.max - sceneBounds.min) : 0.0;
    const double least = 1e-6 * diagonal;
    if (request.thickness < least)
      throw Error("--thickness " + numberText(request.thickness),
                  "below a millionth of the scene's diagonal (" + numberText(least) +
                      "): the slabs would be shorter than the depth precision");
    if (request.thickness > 1e30) throw Error("--thickness " + numberText(request.thickness), "above 1e30 scene units");
    return request.thickness;
  }
  const double d = zThicknessDefault(sceneBounds);
  return d > 0.0 ? d : 0.01;  // a flat or point-like scene still gets a usable slab
}

Volume volumeAsRequested(const RenderRequest& request, const Volume& volume) {
  Volume v = volume;
  v.shading = request.volumeShading.value_or(volume.shading);
  return v;
}

std::string volumeShadingNote(std::span<const Volume> volumes) {
  std::size_t on = 0;
  for (const Volume& v : volumes) on += v.shading ? 1 : 0;
  return on == 0 ? "off" : on == volumes.size() ? "on" : std::to_string(on) + " of " + std::to_string(volumes.size());
}

std::optional<std::string> volumeLongRayStepNote(std::span<const Volume> volumes, double step) {
  if (volumes.empty()) return std::nullopt;
  Bounds all = volumes.front().bounds();
  for (const Volume& v : volumes) {
    const Bounds b = v.bounds();
    all.min = glm::min(all.min, b.min);
    all.max = glm::max(all.max, b.max);
  }
  const double longest = glm::length(glm::dvec3(all.max - all.min)) / MFR_VOLUME_MAX_STEPS;
  if (!(longest > step)) return std::nullopt;
  return "up to " + numberText(longest) + " (a ray longer than " + std::to_string(MFR_VOLUME_MAX_STEPS) +
         " steps takes its length / " + std::to_string(MFR_VOLUME_MAX_STEPS) + ")";
}

std::string volumeFieldsNote(std::span<const Volume> volumes) {
  std::string note;
  bool named = false;
  for (const Volume& v : volumes) {
    note += (note.empty() ? "" : ", ") + (v.field.empty() ? std::string("-") : v.field);
    named = named || !v.field.empty();
  }
  return named ? note : std::string();
}

std::string fieldColorsNote(const Scene& scene) {
  std::vector<std::pair<FieldColors, std::size_t>> colourings;
  std::size_t visible = 0;
  for (const Object& o : scene.objects) {
    if (!o.visible || !o.mesh) continue;
    ++visible;
    if (!o.material.fieldColors) continue;
    auto it = std::find_if(colourings.begin(), colourings.end(),
                           [&](const auto& c) { return c.first == *o.material.fieldColors; });
    if (it == colourings.end()) it = colourings.insert(colourings.end(), {*o.material.fieldColors, 0});
    ++it->second;
  }
  std::string note;
  for (const auto& [c, parts] : colourings) {
    std::ostringstream one;
    one << c.field << " (" << c.map << ", " << c.range.x << " … " << c.range.y << ") on " << parts << " of " << visible
        << " parts";
    note += (note.empty() ? "" : "; ") + one.str();
  }
  return note;
}

std::vector<Volume> volumesAsRequested(const RenderRequest& request, const Scene& scene) {
  std::vector<Volume> volumes = scene.visibleVolumes();
  for (Volume& v : volumes) v = volumeAsRequested(request, v);
  return volumes;
}

double volumeStepOf(const RenderRequest& request, std::span<const Volume> volumes) {
  if (!std::isfinite(request.volumeStep) || request.volumeStep < 0.0)
    throw Error("--step", "must be a positive length in scene units (got " + numberText(request.volumeStep) + ")");
  if (request.volumeStep > 0.0) return request.volumeStep;
  double step = std::numeric_limits<double>::infinity();
  for (const Volume& v : volumes) step = std::min(step, v.defaultStep());
  return std::isfinite(step) ? step : 0.0;
}

std::string effectiveOperation(const std::string& operation, const MethodInfo* info, bool sceneHasVolume) {
  if (operation != "auto") return operation;
  std::string preferred = info ? info->preferredOperation : "oit";
  if (sceneHasVolume && preferred == "oit" && (!info || info->sortedLists)) return "volume";
  return preferred;
}

std::vector<std::string> availableMethods() {
  std::vector<std::string> names{"oracle"};
  for (const RegistryEntry& e : methodRegistry()) names.push_back(e.name);
  names.push_back("optimal-k");
  return names;
}

const MethodInfo& optimalKInfo() {
  static const MethodInfo i{
      "optimal-k",
      "Hybrid transparency with the offline optimal k(p) under a memory budget (CPU reference)",
      "Tsopouridis, Fudos, Vasilakis: Deep hybrid order-independent transparency. The Visual Computer 2022 (Alg. 1, "
      "eq. 2); the better of its backward greedy and an exact-on-the-convex-hull Lagrangian allocation",
      false,
      {{"budget_mib",
        "Memory budget M (MiB)",
        ParamSpec::Type::Float,
        "16",
        0,
        65536,
        {},
        "the budget of the variable-k buffers' layout (vkb without a network): F(M) slots to allocate",
        true}},
      "hybrid"};
  return i;
}

const MethodInfo* findMethodInfo(const std::string& name) {
  if (name == "optimal-k") return &optimalKInfo();
  // One instance per registry method, kept only for its description (a method allocates no GL
  // objects before configure()).
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<Method>> described;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = described.find(name);
  if (it == described.end()) {
    for (const RegistryEntry& e : methodRegistry())
      if (e.name == name) it = described.emplace(name, e.create()).first;
    if (it == described.end()) return nullptr;
  }
  return &it->second->info();
}

namespace {

// optimal-k: the oracle's exact lists, the F(M) of the variable-k layout at this size, the best
// allocation of optimalKBest, composited by the CPU hybrid operation.
RenderOutput renderOptimalK(const Scene& scene, const Camera& camera, const RenderRequest& request) {
  if (request.operation != "hybrid" && request.operation != "auto")
    throw Error("--op " + request.operation, "optimal-k is a hybrid-transparency reference: use --op hybrid (or auto)");
  const Params params(optimalKInfo().params, request.params, "optimal-k");
  const auto budgetBytes = static_cast<std::uint64_t>(std::floor(params.real("budget_mib") * 1024.0 * 1024.0));
  const std::uint64_t pixels = static_cast<std::uint64_t>(request.width) * static_cast<std::uint64_t>(request.height);
  const VariableKLayout layout = variableKLayout(pixels);
  if (budgetBytes < layout.bytes(1))
    throw Error("--param budget_mib=" + params.text("budget_mib"),
                "below the fixed part of optimal-k's variable-k layout at " + std::to_string(request.width) + "x" +
                    std::to_string(request.height) + " (" + std::to_string(layout.bytes(1)) +
                    " bytes with one slot; it needs a slot per non-empty pixel)");
  const FragmentLists lists = castFragments(scene, camera, request.width, request.height);
  const HybridErrorTable errors = hybridErrorTable(lists, scene.background);
  const std::uint64_t slots = std::min<std::uint64_t>(layout.slotBudget(budgetBytes), lists.fragments.size());
  const std::uint64_t nonEmpty = minimumSlots(errors);
  if (slots < nonEmpty)
    throw Error("--param budget_mib=" + params.text("budget_mib"),
                "holds " + std::to_string(slots) + " slots, fewer than the " + std::to_string(nonEmpty) +
                    " non-empty pixels: optimal-k needs one per non-empty pixel (" +
                    std::to_string(layout.bytes(nonEmpty)) + " bytes here)");
  std::string solver;
  const KAllocation best = optimalKBest(errors, slots, &solver);
  RenderOutput out;
  out.image = compositeHybrid(lists, best.k, scene.background);
  Stats& s = out.stats;
  s.method = "optimal-k";
  s.operation = "hybrid";
  s.sync = "none";
  s.fragmentsGenerated = lists.fragments.size();
  s.fragmentsStored = best.slots;
  s.fragmentsDropped = lists.fragments.size() - best.slots;
  s.bytesAllocated = layout.bytes(slots);
  s.bytesUsed = layout.bytes(best.slots);
  std::uint32_t kMin = 0xFFFFFFFFu, kMax = 0;
  for (std::size_t p = 0; p < best.k.size(); ++p)
    if (lists.offsets[p + 1] > lists.offsets[p]) {
      kMin = std::min(kMin, best.k[p]);
      kMax = std::max(kMax, best.k[p]);
    }
  s.kMin = nonEmpty > 0 ? kMin : 0;
  s.kMax = kMax;
  s.notes.emplace_back("F(M)", std::to_string(layout.slotBudget(budgetBytes)) + " slots");
  s.notes.emplace_back("solver", solver);
  s.notes.emplace_back("error", std::to_string(best.error));
  s.notes.emplace_back("device", "CPU ray casting (double precision)");
  // As the oracle and the GPU methods say it: hybrid composites the surfaces only.
  if (scene.hasVisibleVolume()) s.notes.emplace_back("volume", "not drawn (operation hybrid)");
  out.kMap = best.k;
  out.depthComplexity = lists.counts();
  return out;
}

}  // namespace

// One headless context and renderer for the process, created on first use.
GpuRenderer& headlessRenderer() {
  static gl::HeadlessContext context(true);
  static GpuRenderer renderer;
  context.makeCurrent();
  return renderer;
}

RenderOutput render(const Scene& scene, const Camera& camera, const RenderRequest& request) {
  validateImageSize("--size", request.width, request.height);
  scene.validate();
  const std::vector<std::string> methods = availableMethods();
  if (std::find(methods.begin(), methods.end(), request.method) == methods.end()) {
    std::string list;
    for (const auto& m : methods) list += (list.empty() ? "" : ", ") + m;
    throw Error("--method " + request.method, "unknown method (available: " + list + ")");
  }
  validateOperation(request.operation);
  if (request.method == "optimal-k") return renderOptimalK(scene, camera, request);
  if (request.method != "oracle") {
    checkDrawable(scene, camera, request.width, request.height);  // what the oracle would refuse
    GpuRenderer& gpu = headlessRenderer();
    gpu.setScene(scene);
    RenderOutput out = gpu.render(camera, request);
    out.stats.notes.emplace_back("device", gl::queryContextInfo().renderer);
    return out;
  }
  RenderOutput out;
  if (const std::string fields = fieldColorsNote(scene); !fields.empty())
    out.stats.notes.emplace_back("field colours", fields);
  const std::string operation = effectiveOperation(request.operation, nullptr, scene.hasVisibleVolume());
  // Its one parameter, the core size of the exact hybrid image (--op hybrid -p k=N), checked before
  // the cast; any other parameter is a mistake, not something to ignore.
  std::uint32_t coreSize = 0;
  for (const auto& [key, value] : request.params) {
    const std::string what = "--param " + key + "=" + value;
    if (key != "k" || operation != "hybrid")
      throw Error(what, "the oracle takes no parameters but k=N (the core size) with --op hybrid");
    const bool digits = !value.empty() && value.size() <= 9 &&
                        std::all_of(value.begin(), value.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
    if (!digits) throw Error(what, "not a non-negative integer (below 10^9)");
    coreSize = static_cast<std::uint32_t>(std::stoul(value));
  }
  if (operation == "hybrid" && request.params.count("k") == 0)
    throw Error("--op hybrid", "the oracle needs --param k=N (core size)");
  const FragmentLists lists = castFragments(scene, camera, request.width, request.height);
  if (operation == "hybrid") {
    // The exact hybrid image for a uniform core size: --method oracle --op hybrid -p k=N.
    out.image = compositeHybrid(lists, coreSize, scene.background);
  } else if (operation == "volume") {
    const std::vector<Volume> drawn = volumesAsRequested(request, scene);
    if (drawn.empty()) throw Error("--op volume", "scene '" + scene.name + "' has no visible volume");
    const double step = volumeStepOf(request, drawn);
    out.image = compositeVolume(lists, camera, drawn, step, scene.background, scene.clipBox, scene.section);
    out.stats.notes.emplace_back("volume step", numberText(step));
    if (const auto longer = volumeLongRayStepNote(drawn, step))
      out.stats.notes.emplace_back("volume step, long rays", *longer);
    out.stats.notes.emplace_back("volumes", std::to_string(drawn.size()));
    out.stats.notes.emplace_back("volume shading", volumeShadingNote(drawn));
    if (const std::string fields = volumeFieldsNote(drawn); !fields.empty())
      out.stats.notes.emplace_back("volume fields", fields);
  } else if (operation == "zthickness") {
    const double thickness = zThicknessOf(request, scene.bounds());
    out.image = compositeZThickness(lists, camera, thickness, scene.background);
    out.stats.notes.emplace_back("z-thickness", numberText(thickness));
  } else if (operation == "csg") {
    if (scene.clipBox) throw Error("--op csg", kCsgClipRefusal);
    if (scene.csg.empty())
      throw Error("--op csg", "scene '" + scene.name + "' has no CSG tree (a \"csg\" key in an .mfrscene file)");
    out.image = compositeCsg(lists, scene);
  } else {
    out.image = compositeOver(lists, scene.background);
  }
  if (operation != "volume" && scene.hasVisibleVolume())
    out.stats.notes.emplace_back("volume", "not drawn (operation " + operation + ")");
  out.stats.method = "oracle";
  out.stats.operation = operation;
  out.stats.sync = "none";
  out.stats.fragmentsGenerated = lists.fragments.size();
  out.stats.fragmentsStored = lists.fragments.size();
  out.stats.bytesAllocated = lists.fragments.size() * sizeof(Fragment) + lists.offsets.size() * sizeof(std::uint32_t);
  out.stats.bytesUsed = out.stats.bytesAllocated;
  out.stats.kMax = lists.maxCount();
  out.stats.notes.emplace_back("device", "CPU ray casting (double precision)");
  out.depthComplexity = lists.counts();
  return out;
}

}  // namespace mfr
