#pragma once
// The deep variable k-buffer's network (Tsopouridis, Fudos, Vasilakis, "Deep hybrid
// order-independent transparency", The Visual Computer 2022, §4): 12 per-pixel features →
// 128 → 64 → 1 (ReLU, ReLU, sigmoid), standardised inputs. This header holds the model as the GPU
// reads it (the float layout of shaders/budget/mlp.h), its JSON weights file, the CPU forward pass
// (the shader's own code: same accumulation order, 8-bit weights and row scales once quantised) and the features of
// exact per-pixel lists (the CPU twin of dkb's feature passes, for training data).
//
// Weights file (JSON): {"format": "mfr-dkb-weights", "version": 1, "architecture": [12,128,64,1],
// "target": "k_over_n" | "k_over_budget", "input_mean": [12], "input_std": [12],
// "layers": [{"weights": [[...] × outputs], "bias": [...]} × 3], "training": {…free-form…}}.
// target says what the sigmoid output predicts: k(p)/n(p) (importance = y·n(p)) or k(p)/F(M)
// (importance = y).
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mfr/reference/oracle.hpp"

namespace mfr {

inline constexpr int kDkbFeatures = 12;
using DkbFeatureVector = std::array<float, kDkbFeatures>;

struct NeuralImportanceModel {
  std::vector<float> weights;       // the shaders/budget/mlp.h layout (MFR_MLP_FLOATS floats)
  std::string target = "k_over_n";  // or "k_over_budget"
  std::string trainingJson = "{}";  // the file's "training" object, verbatim (provenance)
  std::string source;               // the path it was read from, or "built-in"
  std::vector<float> rowScales;     // per output row (MFR_MLP_ROWS) once quantised(), else empty
  std::vector<std::int8_t> quant;   // every weight's q (MFR_MLP_Q_COUNT, weight = scale(row)·q) once quantised()

  [[nodiscard]] bool predictsFractionOfList() const { return target == "k_over_n"; }
  static std::size_t floatCount();
  // The model as dkb runs it on the GPU: input statistics and biases in 32-bit floats, every
  // weight rounded to scale(row)·q with q a signed 8-bit integer and scale(row) = max|w| / 127 of
  // its output row (under a third of the float weights' GPU memory, which the budget pays for; the
  // forward pass still computes in 32-bit floats). `weights` then holds the dequantised values.
  [[nodiscard]] NeuralImportanceModel quantised() const;
  // The GPU buffer of a quantised() model (shaders/budget/mlp_layout.h): statistics, biases and
  // row scales as float words, then the weights four signed bytes per word.
  [[nodiscard]] std::vector<std::uint32_t> packedWords() const;
  static std::size_t packedBytes();
};

// Reads a weights file; "" means the built-in weights shipped in resources/dkb/weights.json.
// Throws mfr::Error("<path>", reason) for a missing, malformed or wrongly shaped file.
NeuralImportanceModel loadNeuralImportance(const std::string& path);
// Parses the JSON text of a weights file; `source` names it in errors.
NeuralImportanceModel parseNeuralImportance(const std::string& json, const std::string& source);
// JSON text of a model (the inverse of parseNeuralImportance).
std::string neuralImportanceJson(const NeuralImportanceModel& model);

// The network's output y ∈ (0, 1) for raw (not yet standardised) features.
float predictNeuralImportance(const NeuralImportanceModel& model, const DkbFeatureVector& features);
// The importance dkb allocates by (mfrDkbImportance of shaders/budget/mlp.h): y·n + ½ (k_over_n;
// the rule's floor then rounds the predicted k) or y (k_over_budget), before sanitising.
float neuralImportance(const NeuralImportanceModel& model, const DkbFeatureVector& features, std::uint32_t n);

// Image-wide inputs of the features: Σn(p), the nearest and farthest depth of the image.
struct DkbImageStats {
  std::uint64_t totalFragments = 0;
  std::uint64_t nonEmptyPixels = 0;
  float imageNear = 0.0f, imageFar = 0.0f;
};
DkbImageStats dkbImageStats(const FragmentLists& lists);
// Features of one pixel's sorted list (non-empty) under a budget of F slots, as dkb computes them.
DkbFeatureVector dkbFeatures(std::span<const Fragment> sorted, const DkbImageStats& image, std::uint64_t budgetSlots);

}  // namespace mfr
