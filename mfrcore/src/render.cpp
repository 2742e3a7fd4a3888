#include "mfr/render.hpp"

#include <algorithm>
#include <exception>

#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/methods/registry.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr {

void validateImageSize(const std::string& what, int width, int height) {
  if (width <= 0 || height <= 0) throw Error(what, "image size must be positive (got " + std::to_string(width) + "x" + std::to_string(height) + ")");
  if (width > 16384 || height > 16384) throw Error(what, "image size above 16384 pixels per side");
}

std::vector<std::string> availableMethods() {
  std::vector<std::string> names{"oracle"};
  for (const RegistryEntry& e : methodRegistry()) names.push_back(e.name);
  return names;
}

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
  if (request.operation != "oit" && request.operation != "hybrid")
    throw Error("--op " + request.operation, "unknown operation (available: oit, hybrid)");
  if (request.method != "oracle") {
    GpuRenderer& gpu = headlessRenderer();
    gpu.setScene(scene);
    RenderOutput out = gpu.render(camera, request);
    out.stats.notes.emplace_back("device", gl::queryContextInfo().renderer);
    return out;
  }
  RenderOutput out;
  const FragmentLists lists = castFragments(scene, camera, request.width, request.height);
  if (request.operation == "hybrid") {
    // The exact hybrid image for a uniform core size: --method oracle --op hybrid -p k=N.
    const auto k = request.params.find("k");
    if (k == request.params.end()) throw Error("--op hybrid", "the oracle needs --param k=N (core size)");
    unsigned long value = 0;
    try {
      value = std::stoul(k->second);
    } catch (const std::exception&) {
      throw Error("--param k=" + k->second, "not a non-negative integer");
    }
    out.image = compositeHybrid(lists, static_cast<std::uint32_t>(value), scene.background);
  } else {
    out.image = compositeOver(lists, scene.background);
  }
  out.stats.method = "oracle";
  out.stats.operation = request.operation;
  out.stats.sync = "none";
  out.stats.fragmentsGenerated = lists.fragments.size();
  out.stats.fragmentsStored = lists.fragments.size();
  out.stats.bytesAllocated = lists.fragments.size() * sizeof(Fragment) + lists.offsets.size() * sizeof(std::uint32_t);
  out.stats.bytesUsed = out.stats.bytesAllocated;
  out.stats.kMax = lists.maxCount();
  out.stats.notes.emplace_back("device", "CPU ray casting (CGAL AABB tree)");
  return out;
}

}  // namespace mfr
