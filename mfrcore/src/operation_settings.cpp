#include "mfr/operation_settings.hpp"

#include <algorithm>
#include <vector>

#include "mfr/error.hpp"

namespace mfr {

namespace {

// The operation the request runs, "auto" resolved, or nullopt for a method or operation render()
// does not know (render() names those; a misspelt --op was blamed on the thickness:
// "operation is zthicknes").
std::optional<std::string> knownOperation(const RenderRequest& request, bool sceneHasVolume) {
  const std::vector<std::string> methods = availableMethods();
  if (std::find(methods.begin(), methods.end(), request.method) == methods.end()) return std::nullopt;
  try {
    validateOperation(request.operation);
  } catch (const Error&) {
    return std::nullopt;
  }
  return effectiveOperation(request.operation, findMethodInfo(request.method), sceneHasVolume);
}

std::string thisRendersOperation(const RenderRequest& request, const std::string& operation) {
  std::string text = "this render's operation is " + operation;
  if (request.operation == "auto") text += " (auto, for " + request.method + ")";
  return text;
}

}  // namespace

std::optional<UnusedOperationSetting> unusedOperationSetting(const RenderRequest& request, bool sceneHasVolume) {
  const std::optional<std::string> operation = knownOperation(request, sceneHasVolume);
  if (!operation) return std::nullopt;
  const auto unused = [&](const char* name, const char* user) -> std::optional<UnusedOperationSetting> {
    return UnusedOperationSetting{
        name, std::string("only operation ") + user + " uses it; " + thisRendersOperation(request, *operation)};
  };
  if (request.thickness > 0.0 && *operation != "zthickness") return unused("thickness", "zthickness");
  if (request.volumeStep > 0.0 && *operation != "volume") return unused("step", "volume");
  if (request.volumeShading.has_value() && *operation != "volume") return unused("shade", "volume");
  return std::nullopt;
}

std::optional<UnusedOperationSetting> unusedMethodParam(const RenderRequest& request) {
  const MethodInfo* info = findMethodInfo(request.method);
  if (!info) return std::nullopt;
  // A flag in its one spelling ("on", "1" → "true"), as Params reads it.
  const auto asFlag = [](const std::string& v) { return v == "true" || v == "1" || v == "on" ? "true" : "false"; };
  const auto valueOf = [&](const std::string& name) -> std::string {
    for (const ParamSpec& spec : info->params)
      if (spec.name == name) {
        const auto it = request.params.find(name);
        const std::string& value = it != request.params.end() ? it->second : spec.defaultValue;
        return spec.type == ParamSpec::Type::Bool ? asFlag(value) : value;
      }
    return {};
  };
  for (const ParamSpec& spec : info->params) {
    const auto given = request.params.find(spec.name);
    const std::size_t eq = spec.onlyWith.find('=');
    if (given == request.params.end() || eq == std::string::npos) continue;
    // A flag turned off asks for nothing (tail_runs=false beside exact_tail=false).
    if (spec.type == ParamSpec::Type::Bool && std::string(asFlag(given->second)) == "false") continue;
    const std::string other = spec.onlyWith.substr(0, eq), wanted = spec.onlyWith.substr(eq + 1);
    if (const std::string value = valueOf(other); value != wanted)
      return UnusedOperationSetting{"param " + spec.name + "=" + given->second,
                                    "only " + spec.onlyWith + " uses it; this render's " + other + " is " + value};
  }
  return std::nullopt;
}

std::optional<UnusedOperationSetting> unusedOperationSetting(const RenderRequest& request, const Scene& scene) {
  std::optional<UnusedOperationSetting> unused = unusedOperationSetting(request, scene.hasVisibleVolume());
  if (unused && unused->name != "thickness" && !scene.volumes.empty() && !scene.hasVisibleVolume())
    unused->reason += "; the scene's volume is hidden";
  return unused;
}

std::optional<std::string> volumeNotDrawnReason(const RenderRequest& request, const Scene& scene) {
  if (!scene.hasVisibleVolume()) return std::nullopt;
  const std::optional<std::string> operation = knownOperation(request, true);
  if (!operation || *operation == "volume") return std::nullopt;
  return thisRendersOperation(request, *operation) + "; only operation volume draws the volume";
}

}  // namespace mfr
