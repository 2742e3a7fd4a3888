#pragma once
// The settings of one operation (zthickness's thickness, volume's step and shading) that a
// command line gives for a render whose operation does not use them. mfr render, probe, bench,
// evaluate and mfrview refuse them in the same words: an ignored option gave the same image as
// without it, with no hint that it was not applied.
#include <optional>
#include <string>

#include "mfr/render.hpp"

namespace mfr {

struct UnusedOperationSetting {
  std::string name;    // the option's word: "thickness", "step" or "shade"
  std::string reason;  // e.g. "only operation zthickness uses it; this render's operation is oit"
};

// The first method parameter the request gives that acts only with another's value it does not
// have (ParamSpec::onlyWith: abuffer-ll's pool_mib without pool=fixed): name "param pool_mib=1",
// reason "only pool=fixed uses it; this render's pool is count". nullopt for an unknown method.
std::optional<UnusedOperationSetting> unusedMethodParam(const RenderRequest& request);

// The first of the request's thickness (> 0), volumeStep (> 0) and volumeShading (set) that its
// operation, "auto" resolved for its method on a scene with or without a visible volume, does not
// use; nullopt when each is used or unset, and for a method or operation render() does not know
// (render() names those).
std::optional<UnusedOperationSetting> unusedOperationSetting(const RenderRequest& request, bool sceneHasVolume);
// The same for a scene: its visible volume decides "auto", and a reason about the volume's step
// or shading says when the scene's volume is there but hidden (--contour hides it).
std::optional<UnusedOperationSetting> unusedOperationSetting(const RenderRequest& request, const Scene& scene);

// Why the request's operation leaves the scene's visible volume undrawn (e.g. "this render's
// operation is oit; only operation volume draws the volume"), or nullopt when it draws it, when
// the scene shows no volume, and for a method or operation render() does not know. For
// --keep-volume, which asks for the volume beside its isosurfaces: it was taken and changed nothing.
std::optional<std::string> volumeNotDrawnReason(const RenderRequest& request, const Scene& scene);

}  // namespace mfr
