#include "mfr/operation_settings.hpp"

#include <algorithm>
#include <vector>

#include "mfr/error.hpp"

namespace mfr {

std::optional<UnusedOperationSetting> unusedOperationSetting(const RenderRequest& request, bool sceneHasVolume) {
  const std::vector<std::string> methods = availableMethods();
  if (std::find(methods.begin(), methods.end(), request.method) == methods.end()) return std::nullopt;
  // A misspelt --op is render()'s to name (it was blamed on the thickness: "operation is zthicknes").
  try {
    validateOperation(request.operation);
  } catch (const Error&) {
    return std::nullopt;
  }
  const std::string operation = effectiveOperation(request.operation, findMethodInfo(request.method), sceneHasVolume);
  const auto unused = [&](const char* name, const char* user) -> std::optional<UnusedOperationSetting> {
    std::string reason = std::string("only operation ") + user + " uses it; this render's operation is " + operation;
    if (request.operation == "auto") reason += " (auto, for " + request.method + ")";
    return UnusedOperationSetting{name, reason};
  };
  if (request.thickness > 0.0 && operation != "zthickness") return unused("thickness", "zthickness");
  if (request.volumeStep > 0.0 && operation != "volume") return unused("step", "volume");
  if (request.volumeShading.has_value() && operation != "volume") return unused("shade", "volume");
  return std::nullopt;
}

std::optional<UnusedOperationSetting> unusedOperationSetting(const RenderRequest& request, const Scene& scene) {
  std::optional<UnusedOperationSetting> unused = unusedOperationSetting(request, scene.hasVisibleVolume());
  if (unused && unused->name != "thickness" && !scene.volumes.empty() && !scene.hasVisibleVolume())
    unused->reason += "; the scene's volume is hidden";
  return unused;
}

}  // namespace mfr
