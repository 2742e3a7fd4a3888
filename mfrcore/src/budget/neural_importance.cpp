// The dkb network's weights, CPU forward pass and features (mfr/budget/neural_importance.hpp).
// The forward pass and the features are the shaders' own definitions (shaders/budget/mlp.h,
// features.h) compiled as C++.
#include "mfr/budget/neural_importance.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <limits>
#include <map>
#include <string_view>

#include <nlohmann/json.hpp>

#include "budget/glsl_shared.hpp"
#include "budget/mlp_layout.h"
#include "mfr/error.hpp"
#include "mfr/io_util.hpp"
#include "mfr/json_text.hpp"
#include "number_text.hpp"

namespace mfr {

namespace detail {
const std::map<std::string, std::string_view, std::less<>>& embeddedResources();  // generated
}  // namespace detail

namespace {
// Float index (in NeuralImportanceModel::weights) of the weight at 8-bit index q, and of row r's
// bias: the quantised weights are contiguous, the float layout interleaves each layer's biases.
constexpr int floatIndexOfWeight(int q) {
  return q < MFR_MLP_Q_W2 ? MFR_MLP_W1 + q
                          : (q < MFR_MLP_Q_W3 ? MFR_MLP_W2 + (q - MFR_MLP_Q_W2) : MFR_MLP_W3 + (q - MFR_MLP_Q_W3));
}
constexpr int floatIndexOfBias(int r) {
  return r < MFR_MLP_HIDDEN1
             ? MFR_MLP_B1 + r
             : (r < MFR_MLP_HIDDEN1 + MFR_MLP_HIDDEN2 ? MFR_MLP_B2 + (r - MFR_MLP_HIDDEN1) : MFR_MLP_B3);
}
}  // namespace

namespace glsl {
namespace {
// The model the shared forward pass reads: a quantised one as the GPU does (q and the row's
// scale), an unquantised one (fresh from training) with scale 1 and the float weights as q.
thread_local const NeuralImportanceModel* tMlp = nullptr;
vec4 cpuQuad(int q) {
  if (!tMlp->quant.empty()) {
    const std::int8_t* w = tMlp->quant.data() + q;
    return {static_cast<float>(w[0]), static_cast<float>(w[1]), static_cast<float>(w[2]), static_cast<float>(w[3])};
  }
  const float* w = tMlp->weights.data() + floatIndexOfWeight(q);
  return {w[0], w[1], w[2], w[3]};
}
}  // namespace
#define MFR_MLP_STAT(i) tMlp->weights[static_cast<std::size_t>(i)]
#define MFR_MLP_BIAS(r) tMlp->weights[static_cast<std::size_t>(floatIndexOfBias(r))]
#define MFR_MLP_SCALE(r) (tMlp->quant.empty() ? 1.0f : tMlp->rowScales[static_cast<std::size_t>(r)])
#define MFR_MLP_QUAD(q) cpuQuad(q)
#include "budget/mlp.h"
#undef MFR_MLP_STAT
#undef MFR_MLP_BIAS
#undef MFR_MLP_SCALE
#undef MFR_MLP_QUAD
}  // namespace glsl

namespace {

constexpr int kLayerShape[3][2] = {
    {MFR_MLP_HIDDEN1, MFR_MLP_INPUTS}, {MFR_MLP_HIDDEN2, MFR_MLP_HIDDEN1}, {1, MFR_MLP_HIDDEN2}};
constexpr int kLayerWeights[3] = {MFR_MLP_W1, MFR_MLP_W2, MFR_MLP_W3};
constexpr int kLayerBias[3] = {MFR_MLP_B1, MFR_MLP_B2, MFR_MLP_B3};
constexpr int kLayerRows[3] = {0, MFR_MLP_HIDDEN1, MFR_MLP_HIDDEN1 + MFR_MLP_HIDDEN2};  // first row of each layer
constexpr int kLayerQuant[3] = {MFR_MLP_Q_W1, MFR_MLP_Q_W2, MFR_MLP_Q_W3};

// The largest magnitude of a mean, weight or bias. With features below ~1e10 (F(M)/Σn, the largest)
// and std at least 1e-6, every layer's sums then stay below ~1e33, inside a float, so the CPU and
// GPU networks never meet inf or NaN. A mean of 1e38 was taken, the network's output was NaN, and
// the CPU and GPU fell back to different allocations without a word (a bug hunt). Trained weights
// stay below 1 (the shipped ones: 0.97).
constexpr double kLargestParameter = 1e4;

std::vector<float> floats(const nlohmann::json& j, std::size_t count, const std::string& where,
                          const std::string& source, double limit = kLargestParameter) {
  if (!j.is_array() || j.size() != count)
    throw Error(source, where + " must be an array of " + std::to_string(count) + " numbers");
  std::vector<float> out;
  out.reserve(count);
  for (const auto& v : j) {
    if (!v.is_number()) throw Error(source, where + " holds a non-number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw Error(source, where + " holds a non-finite number");
    // Both the CPU and the GPU network compute in floats: 1e39 became infinite, and dkb quietly
    // fell back to the flat allocation.
    if (std::abs(d) > std::numeric_limits<float>::max())
      throw Error(source, where + " holds a number beyond a float's range (±3.4e38)");
    if (std::abs(d) > limit)
      throw Error(source, where + " holds " + numberText(d) + ", beyond ±" + numberText(limit) +
                              ": no trained network's, and the network's float sums could overflow");
    out.push_back(static_cast<float>(d));
  }
  return out;
}

}  // namespace

std::size_t NeuralImportanceModel::floatCount() {
  return MFR_MLP_FLOATS;
}

std::size_t NeuralImportanceModel::packedBytes() {
  return 4 * MFR_MLP_PACKED_WORDS;
}

NeuralImportanceModel NeuralImportanceModel::quantised() const {
  if (weights.size() != MFR_MLP_FLOATS) throw Error("dkb weights", "model has the wrong number of weights");
  NeuralImportanceModel m = *this;
  m.rowScales.assign(MFR_MLP_ROWS, 0.0f);
  m.quant.assign(MFR_MLP_Q_COUNT, 0);
  for (int l = 0; l < 3; ++l) {
    const int rows = kLayerShape[l][0], cols = kLayerShape[l][1];
    for (int r = 0; r < rows; ++r) {
      float* w = m.weights.data() + kLayerWeights[l] + r * cols;
      std::int8_t* q = m.quant.data() + kLayerQuant[l] + r * cols;
      float maxAbs = 0.0f;
      for (int c = 0; c < cols; ++c) maxAbs = std::max(maxAbs, std::abs(w[c]));
      const float scale = maxAbs / 127.0f;
      m.rowScales[static_cast<std::size_t>(kLayerRows[l]) + static_cast<std::size_t>(r)] = scale;
      for (int c = 0; c < cols; ++c) {
        q[c] = static_cast<std::int8_t>(scale > 0.0f ? std::clamp(std::round(w[c] / scale), -127.0f, 127.0f) : 0.0f);
        w[c] = scale * static_cast<float>(q[c]);
      }
    }
  }
  return m;
}

std::vector<std::uint32_t> NeuralImportanceModel::packedWords() const {
  if (weights.size() != MFR_MLP_FLOATS) throw Error("dkb weights", "model has the wrong number of weights");
  if (rowScales.size() != MFR_MLP_ROWS || quant.size() != MFR_MLP_Q_COUNT)
    throw Error("dkb weights", "model is not quantised");
  std::vector<std::uint32_t> words(MFR_MLP_PACKED_WORDS, 0);
  const auto bits = [](float f) {
    std::uint32_t u = 0;
    std::memcpy(&u, &f, 4);
    return u;
  };
  for (std::size_t i = 0; i < MFR_MLP_W1; ++i) words[i] = bits(weights[i]);
  for (int row = 0; row < MFR_MLP_ROWS; ++row) {
    words[static_cast<std::size_t>(MFR_MLP_GPU_BIAS + row)] =
        bits(weights[static_cast<std::size_t>(floatIndexOfBias(row))]);
    words[static_cast<std::size_t>(MFR_MLP_GPU_SCALE + row)] = bits(rowScales[static_cast<std::size_t>(row)]);
  }
  for (std::size_t j = 0; j < quant.size(); ++j)
    words[static_cast<std::size_t>(MFR_MLP_GPU_QUANT) + j / 4] |=
        static_cast<std::uint32_t>(static_cast<std::uint8_t>(quant[j])) << (8 * (j % 4));
  return words;
}

namespace {
NeuralImportanceModel parseWeightsJson(const std::string& text, const std::string& source) {
  const nlohmann::json j = nlohmann::json::parse(text);
  if (!j.is_object() || j.value("format", "") != "mfr-dkb-weights")
    throw Error(source, "not an mfr dkb weights file (\"format\": \"mfr-dkb-weights\" missing)");
  // The number 1 (1.0 too): j.value("version", 0) read 1.7 as 1.
  if (!j.contains("version") || !j["version"].is_number() || j["version"].get<double>() != 1.0)
    throw Error(source, "unsupported weights file version " +
                            (j.contains("version") ? jsonText(j["version"]) : std::string("(none)")) + " (expected 1)");
  const nlohmann::json arch = j.value("architecture", nlohmann::json());
  if (arch != nlohmann::json::array({MFR_MLP_INPUTS, MFR_MLP_HIDDEN1, MFR_MLP_HIDDEN2, 1}))
    throw Error(source, "architecture must be [12, 128, 64, 1]");
  NeuralImportanceModel m;
  m.source = source;
  m.target = j.value("target", "");
  if (m.target != "k_over_n" && m.target != "k_over_budget")
    throw Error(source, "target must be \"k_over_n\" or \"k_over_budget\"");
  m.weights.assign(MFR_MLP_FLOATS, 0.0f);
  const std::vector<float> mean = floats(j.value("input_mean", nlohmann::json()), MFR_MLP_INPUTS, "input_mean", source);
  const std::vector<float> stddev = floats(j.value("input_std", nlohmann::json()), MFR_MLP_INPUTS, "input_std", source,
                                           std::numeric_limits<float>::max());
  for (int i = 0; i < MFR_MLP_INPUTS; ++i) {
    // mfr train's floor: below it a standardised feature overflows the network's floats, and the
    // CPU and GPU inferences fell back differently (1e-45 was taken; a bug hunt).
    if (!(stddev[static_cast<std::size_t>(i)] >= 1e-6f))
      throw Error(source, "input_std must be at least 1e-6 (mfr train's floor; got " +
                              numberText(stddev[static_cast<std::size_t>(i)]) + ")");
    m.weights[MFR_MLP_MEAN + i] = mean[static_cast<std::size_t>(i)];
    m.weights[MFR_MLP_STD + i] = stddev[static_cast<std::size_t>(i)];
  }
  const nlohmann::json layers = j.value("layers", nlohmann::json());
  if (!layers.is_array() || layers.size() != 3) throw Error(source, "layers must hold 3 layers");
  for (int l = 0; l < 3; ++l) {
    const auto& layer = layers[static_cast<std::size_t>(l)];
    const std::string where = "layers[" + std::to_string(l) + "]";
    const int outputs = kLayerShape[l][0], inputs = kLayerShape[l][1];
    const nlohmann::json rows = layer.is_object() ? layer.value("weights", nlohmann::json()) : nlohmann::json();
    if (!rows.is_array() || rows.size() != static_cast<std::size_t>(outputs))
      throw Error(source, where + ".weights must hold " + std::to_string(outputs) + " rows");
    for (int o = 0; o < outputs; ++o) {
      const std::vector<float> row = floats(rows[static_cast<std::size_t>(o)], static_cast<std::size_t>(inputs),
                                            where + ".weights[" + std::to_string(o) + "]", source);
      std::copy(row.begin(), row.end(), m.weights.begin() + kLayerWeights[l] + o * inputs);
    }
    const std::vector<float> bias =
        floats(layer.value("bias", nlohmann::json()), static_cast<std::size_t>(outputs), where + ".bias", source);
    std::copy(bias.begin(), bias.end(), m.weights.begin() + kLayerBias[l]);
  }
  m.trainingJson = j.contains("training") ? jsonText(j["training"]) : "{}";
  return m;
}
}  // namespace

namespace {
// nlohmann quotes the bytes it last read: a PNG given as weights put a raw 0x89 and control bytes
// into the one-line message (a bug hunt). Shown as \xNN.
std::string printable(const std::string& s) {
  std::string out;
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02X", u);
      out += hex;
    }
  }
  return out;
}
}  // namespace

NeuralImportanceModel parseNeuralImportance(const std::string& text, const std::string& source) {
  // A number past double's range ("1e999") or a key of the wrong type is nlohmann's out_of_range
  // or type_error, not parse_error: every JSON error names the file (was "internal error").
  requireJsonNesting(text, source, "not a weights file: its JSON ");
  try {
    return parseWeightsJson(text, source);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(source, "not valid JSON (" + printable(e.what()) + ")");
  } catch (const nlohmann::json::exception& e) {
    throw Error(source, "not a valid weights file (" + printable(e.what()) + ")");
  }
}

std::string neuralImportanceJson(const NeuralImportanceModel& m) {
  if (m.weights.size() != MFR_MLP_FLOATS) throw Error("dkb weights", "model has the wrong number of weights");
  nlohmann::ordered_json j;
  j["format"] = "mfr-dkb-weights";
  j["version"] = 1;
  j["architecture"] = {MFR_MLP_INPUTS, MFR_MLP_HIDDEN1, MFR_MLP_HIDDEN2, 1};
  j["target"] = m.target;
  j["input_mean"] =
      std::vector<float>(m.weights.begin() + MFR_MLP_MEAN, m.weights.begin() + MFR_MLP_MEAN + MFR_MLP_INPUTS);
  j["input_std"] =
      std::vector<float>(m.weights.begin() + MFR_MLP_STD, m.weights.begin() + MFR_MLP_STD + MFR_MLP_INPUTS);
  nlohmann::ordered_json layers = nlohmann::ordered_json::array();
  for (int l = 0; l < 3; ++l) {
    const int outputs = kLayerShape[l][0], inputs = kLayerShape[l][1];
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (int o = 0; o < outputs; ++o) {
      const auto begin = m.weights.begin() + kLayerWeights[l] + o * inputs;
      rows.push_back(std::vector<float>(begin, begin + inputs));
    }
    layers.push_back(
        {{"weights", rows},
         {"bias", std::vector<float>(m.weights.begin() + kLayerBias[l], m.weights.begin() + kLayerBias[l] + outputs)}});
  }
  j["layers"] = layers;
  j["training"] = nlohmann::ordered_json::parse(m.trainingJson.empty() ? "{}" : m.trainingJson);
  return jsonText(j, 1) + "\n";
}

NeuralImportanceModel loadNeuralImportance(const std::string& path) {
  if (!path.empty()) return parseNeuralImportance(readFile(path), path);
  const auto& files = detail::embeddedResources();
  const auto it = files.find("dkb/weights.json");
  if (it == files.end())
    throw Error("dkb", "no built-in weights (resources/dkb/weights.json); give --param weights=FILE");
  NeuralImportanceModel m = parseNeuralImportance(std::string(it->second), "resources/dkb/weights.json");
  m.source = "built-in";
  return m;
}

float predictNeuralImportance(const NeuralImportanceModel& model, const DkbFeatureVector& f) {
  if (model.weights.size() != MFR_MLP_FLOATS) throw Error("dkb weights", "model has the wrong number of weights");
  if (!model.quant.empty() && (model.quant.size() != MFR_MLP_Q_COUNT || model.rowScales.size() != MFR_MLP_ROWS))
    throw Error("dkb weights", "model is quantised inconsistently");
  glsl::tMlp = &model;
  const float y = glsl::mfrMlpForward(glm::vec4(f[0], f[1], f[2], f[3]), glm::vec4(f[4], f[5], f[6], f[7]),
                                      glm::vec4(f[8], f[9], f[10], f[11]));
  glsl::tMlp = nullptr;
  return y;
}

float neuralImportance(const NeuralImportanceModel& model, const DkbFeatureVector& features, std::uint32_t n) {
  return glsl::mfrDkbImportance(predictNeuralImportance(model, features), n, model.predictsFractionOfList());
}

DkbImageStats dkbImageStats(const FragmentLists& lists) {
  DkbImageStats s;
  s.imageNear = std::numeric_limits<float>::infinity();
  s.imageFar = 0.0f;
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const auto l = lists.pixel(x, y);
      if (l.empty()) continue;
      s.totalFragments += l.size();
      ++s.nonEmptyPixels;
      s.imageNear = std::min(s.imageNear, l.front().depth);
      s.imageFar = std::max(s.imageFar, l.back().depth);
    }
  if (s.nonEmptyPixels == 0) s.imageNear = 0.0f;
  return s;
}

DkbFeatureVector dkbFeatures(std::span<const Fragment> sorted, const DkbImageStats& image, std::uint64_t budgetSlots) {
  // The GPU's integer sums and tie rule: colour sums of the 8-bit values; among fragments at the
  // nearest depth the largest packed colour.
  std::uint32_t sum[3] = {0, 0, 0};
  float nearDepth = std::numeric_limits<float>::infinity(), farDepth = 0.0f;
  for (const Fragment& f : sorted) {
    for (int c = 0; c < 3; ++c) sum[c] += (f.color >> (8 * c)) & 0xFFu;
    nearDepth = std::min(nearDepth, f.depth);
    farDepth = std::max(farDepth, f.depth);
  }
  std::uint32_t nearest = 0;
  for (const Fragment& f : sorted)
    if (f.depth == nearDepth) nearest = std::max(nearest, f.color);
  glm::vec4 a, b, c;
  glsl::mfrDkbFeatures(
      static_cast<std::uint32_t>(sorted.size()), static_cast<float>(static_cast<std::uint32_t>(image.totalFragments)),
      static_cast<float>(static_cast<std::uint32_t>(budgetSlots)), nearDepth, farDepth, image.imageNear, image.imageFar,
      nearest, glm::vec3(static_cast<float>(sum[0]), static_cast<float>(sum[1]), static_cast<float>(sum[2])), a, b, c);
  return {a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x, c.y, c.z, c.w};
}

}  // namespace mfr
