#pragma once
// Image-quality metrics against a reference: RMSE and FLIP (Andersson et al., "FLIP: A Difference
// Evaluator for Alternating Images", Proc. ACM CGIT 3(2), 2020), plus error heat maps.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/image.hpp"

namespace mfr {

// Root-mean-square error over the R, G, B channels of two same-size images, computed on the
// stored 8-bit sRGB-encoded values scaled to [0,1] (not on linear values). Throws on size mismatch.
double rmse(const ImageRGBA8& reference, const ImageRGBA8& test);

struct FlipStats {
  double mean = 0, p25 = 0, p50 = 0, p75 = 0, min = 0, max = 0;  // percentiles are weighted
};

struct FlipResult {
  ImageF errorMap;  // 1 channel, per-pixel LDR-FLIP error in [0,1]
  FlipStats stats;
};

// LDR-FLIP on sRGB 8-bit inputs (converted to linear RGB first), pixelsPerDegree as in the paper
// (67 for a 0.7 m wide 4K monitor at 0.7 m). Throws mfr::Error on size mismatch.
FlipResult flip(const ImageRGBA8& reference, const ImageRGBA8& test, double pixelsPerDegree = 67.0);

// Weighted percentile as FLIP's tool reports it: sort ascending, return the first value at which
// the running sum exceeds p × total.
double weightedPercentile(std::vector<float> values, double p);

// Colour maps for error images: magma (FLIP's) and a generic heat map of a scalar image scaled by
// maxValue (values ≥ maxValue saturate). magma uses matplotlib's 256-entry table, index
// round(value·255) clamped to [0,255] as FLIP's tool does; heatmap is magma of value/maxValue
// (perceptually uniform and readable in grey). Both take 1-channel images and throw mfr::Error
// otherwise; heatmap also for maxValue ≤ 0.
ImageRGBA8 magma(const ImageF& values);  // values in [0,1]
// Entry `index` (clamped to [0, 255]) of matplotlib's magma table, RGB in [0, 1]; also a colour
// map for surfaces coloured by a field (scene/color_map.hpp).
glm::vec3 magmaEntry(int index);
ImageRGBA8 heatmap(const ImageF& values, float maxValue);
// A per-pixel count — depth complexity n(p), capacity k(p) — as mfrview's data views and mfr render
// --data-view show it: heatmap over 0 … max(1, largest count); with `under` (an image of the same
// size) every pixel with a count averaged with it, empty pixels left as it is (the views' Blend).
// Throws mfr::Error for counts that are not width·height or an `under` of another size.
ImageRGBA8 countHeatmap(const std::vector<std::uint32_t>& counts, int width, int height,
                        const ImageRGBA8* under = nullptr);

// Per-pixel absolute RGB difference (max over channels, in [0,1]) — input to heatmap().
ImageF absoluteDifference(const ImageRGBA8& reference, const ImageRGBA8& test);

}  // namespace mfr
