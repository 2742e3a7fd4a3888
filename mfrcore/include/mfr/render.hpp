#pragma once
// One entry point from a scene and settings to an image and Stats, shared by the CLI and the
// viewer so that both produce the same pixels. "oracle" is the exact CPU reference; every other
// name is a GPU method from the registry (methods/registry.hpp).
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mfr/image.hpp"
#include "mfr/methods/method.hpp"
#include "mfr/methods/stats.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

struct RenderRequest {
  std::string method = "oracle";
  // "oit", "hybrid", "csg", "zthickness", "volume", or "auto": the method's preferred one — or
  // "volume" for a scene with a visible volume (effectiveOperation)
  std::string operation = "oit";
  int width = 512;
  int height = 512;
  std::map<std::string, std::string> params;  // method parameters by name (k, budget_mib, …)
  // Operation "zthickness": slab thickness in scene units; 0 picks zThicknessDefault of the scene.
  double thickness = 0.0;
  // Operation "volume": ray-march step in scene units; 0 picks the volume's defaultStep().
  double volumeStep = 0.0;
  // Operation "volume": gradient shading on or off; unset: the volume's own Volume::shading.
  std::optional<bool> volumeShading;
};

// Why operation "csg" refuses a scene with a clip box (GPU and oracle say the same).
inline constexpr const char* kCsgClipRefusal =
    "a clip box cuts open the closed solids CSG needs (remove the clip box for this operation)";

// The operations render() and GpuRenderer accept, for messages: "auto, oit, hybrid, csg, zthickness, volume".
const std::string& operationNames();
// Throws mfr::Error("--op <name>", …) for a name not in operationNames().
void validateOperation(const std::string& operation);
// The default z-thickness: 1 % of the diagonal of the scene's bounds.
double zThicknessDefault(const Bounds& sceneBounds);
// The thickness a request asks for (its own, or the default); throws mfr::Error("--thickness", …)
// for a negative, infinite or NaN value, one below a millionth of the scene's diagonal (shorter
// than the float depth precision) or above 1e30.
double zThicknessOf(const RenderRequest& request, const Bounds& sceneBounds);
// The step a request asks for (its own, or the smallest default step of the volumes); throws
// mfr::Error("--step", …) for a negative, infinite or NaN value.
double volumeStepOf(const RenderRequest& request, std::span<const Volume> volumes);
inline double volumeStepOf(const RenderRequest& request, const Volume& volume) {
  return volumeStepOf(request, std::span<const Volume>(&volume, 1));
}
// The volume as a request draws it: a copy (sharing the grid) with the request's shading, if any.
Volume volumeAsRequested(const RenderRequest& request, const Volume& volume);
// The scene's visible volumes as the request draws them (Scene::visibleVolumes, volumeAsRequested).
std::vector<Volume> volumesAsRequested(const RenderRequest& request, const Scene& scene);
// The statistics note "volume shading": "on", "off", or "N of M" when only some volumes are shaded.
std::string volumeShadingNote(std::span<const Volume> volumes);
// The statistics note "volume fields": each volume's Volume::field in order, comma-separated ("-"
// for one without); empty (no note) when none has a named field.
std::string volumeFieldsNote(std::span<const Volume> volumes);
// The statistics note "field colours": each distinct colouring of the visible parts coloured by a
// field, "FIELD (MAP, LOW … HIGH) on N of M parts", "; "-separated; empty (no note) when none is.
std::string fieldColorsNote(const Scene& scene);
// What a request's operation means for a method (info; nullptr: the oracle) on a scene with or
// without a visible volume: "auto" is the method's preferredOperation, except that a scene with a
// volume gets "volume" from every method that prefers "oit" and resolves sorted lists.
std::string effectiveOperation(const std::string& operation, const MethodInfo* info, bool sceneHasVolume);

struct RenderOutput {
  ImageRGBA8 image;
  Stats stats;
  // optimal-k only: its k(p), indexed like the oracle's lists (FragmentLists::index). The GPU
  // methods' k(p) comes from GpuRenderer::kMap().
  std::vector<std::uint32_t> kMap;
  // oracle and optimal-k only: n(p) of the lists they cast, indexed like kMap (so a depth-complexity
  // view of a CPU method casts once).
  std::vector<std::uint32_t> depthComplexity;
};

// Throws mfr::Error for an unknown method or operation, a bad size or an empty scene.
RenderOutput render(const Scene& scene, const Camera& camera, const RenderRequest& request);

// Names accepted by render(): "oracle" first, then the registry's GPU methods, then the CPU
// reference "optimal-k" (hybrid transparency with the offline optimal k(p) under a budget).
std::vector<std::string> availableMethods();

// The description and parameters of the CPU method "optimal-k" (like a registry method's info).
const MethodInfo& optimalKInfo();
// The description and parameters of any method render() accepts: a registry method's info(), or
// optimal-k's; nullptr for "oracle" (no parameters) and unknown names. Thread-safe.
const MethodInfo* findMethodInfo(const std::string& name);

class GpuRenderer;
// The process's headless GL renderer (EGL context created on first use); the CLI uses it.
GpuRenderer& headlessRenderer();

// Checks an image size argument; throws mfr::Error(what, reason) when not 1..16384 each.
void validateImageSize(const std::string& what, int width, int height);

}  // namespace mfr
