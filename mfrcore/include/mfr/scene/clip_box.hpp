#pragma once
// The check both programs make of a clip box given on their command line (mfr render --clip,
// mfrview --clip), so that they refuse the same boxes in the same words.
#include <string>

#include "mfr/scene/scene.hpp"

namespace mfr {

// Throws mfr::Error(what, "holds nothing of scene …") for a clip box that is flat or lies outside
// the scene's bounds: it would draw an empty image.
void requireClipBoxHoldsScene(const Scene& scene, const Bounds& box, const std::string& what);

// Throws mfr::Error("scene '…'", "nothing to draw inside the clip box …") when the scene's clip
// box and section plane (the scene already cut by sectionedScene) leave nothing to draw: no
// triangle whose box meets the clip box, no visible volume whose box meets it and reaches the
// plane's kept side. Boxes, not shapes: it never refuses a scene that draws something. Both
// programs refuse such a picture (mfrview wrote a blank one, exit 0; a bug hunt).
void requireSomethingToDraw(const Scene& scene);

// Throws mfr::Error(what, …) for a corner beyond a float's range (±3.4e38): the GPU renderers take
// the box as floats, where it was infinite and held nothing, while the oracle drew everything.
void requireClipBoxInFloatRange(const Bounds& box, const std::string& what);

}  // namespace mfr
