#pragma once
// Exact operations on the oracle's sorted lists.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/image.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/scene/csg.hpp"

namespace mfr {

// Front-to-back "over": C = Σ_i c_i α_i Π_{j<i}(1-α_j) + (Π_j (1-α_j))·background, in float,
// on the stored (display) values; result rounded to 8 bits, alpha 255.
glm::vec3 compositeOver(std::span<const Fragment> sorted, const glm::vec3& background);
ImageRGBA8 compositeOver(const FragmentLists& lists, const glm::vec3& background);

// Image-space CSG (scene.csg, rule of csgVisibleFragment with the scene's mirrored primitives):
// each pixel shows its visible fragment's colour as an opaque surface (RGB of the stored colour,
// its opacity ignored: solids), the scene's background where there is none; rounded to 8 bits,
// alpha 255. The lists must be the oracle's for this scene. Throws mfr::Error when the scene has
// no CSG tree.
ImageRGBA8 compositeCsg(const FragmentLists& lists, const Scene& scene);

// Depth complexity n(p) per pixel (as a 1-channel float image) and its histogram:
// histogram[n] = number of pixels with exactly n fragments (size maxCount+1).
ImageF depthComplexity(const FragmentLists& lists);
std::vector<std::uint64_t> depthComplexityHistogram(const FragmentLists& lists);

}  // namespace mfr
