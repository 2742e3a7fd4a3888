#pragma once
// A stats note shared by the oracle's and the GPU renderer's volume operation.
#include <optional>
#include <span>
#include <string>

#include "mfr/scene/volume.hpp"

namespace mfr {

// A ray marches at most MFR_VOLUME_MAX_STEPS steps (shaders/ops/volume.glsl), so a ray through the
// volumes longer than that many steps takes its length / MFR_VOLUME_MAX_STEPS instead: the "volume
// step" note is the step asked for, and this one, present only when some ray may be that long (the
// diagonal of the volumes' world bounds bounds every ray's chord), says how far the step may grow.
std::optional<std::string> volumeLongRayStepNote(std::span<const Volume> volumes, double step);

}  // namespace mfr
