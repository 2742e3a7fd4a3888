#pragma once
// Training data of the deep variable k-buffer (Tsopouridis, Fudos, Vasilakis, "Deep hybrid
// order-independent transparency", The Visual Computer 2022, §4): per sampled non-empty pixel of
// a frame, its 12 dkb features (mfr/budget/neural_importance.hpp) and its optimal k(p) under the
// frame's slot budget F (optimalKBest on the oracle's exact lists, mfr/budget/optimal_k.hpp).
//
// File format (docs/methods.md, "dkb training data"), little-endian:
//   8 bytes   magic "MFRDKB1\n"
//   uint32    columns C (= 15)
//   uint64    rows R
//   uint32    metadata length L, then L bytes of UTF-8 JSON (scenes, views, budgets, command)
//   R·C float32, row-major: features[12], k(p)/F, k(p), n(p)
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/budget/neural_importance.hpp"
#include "mfr/budget/optimal_k.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr {

inline constexpr int kDatasetColumns = kDkbFeatures + 3;
// How deeply a dataset's metadata JSON may nest: mfr dataset writes 3 levels; mfr train nests it 3
// levels deeper in the weights file, which is read up to kJsonNestingLimit (256).
inline constexpr std::size_t kDatasetMetadataNestingLimit = 64;
inline constexpr int kDatasetLabel = kDkbFeatures;  // k(p) / F
inline constexpr int kDatasetK = kDkbFeatures + 1;  // k(p)
inline constexpr int kDatasetN = kDkbFeatures + 2;  // n(p)

struct DkbDataset {
  std::vector<float> rows;      // kDatasetColumns floats per row
  std::string metadata = "{}";  // JSON text
  [[nodiscard]] std::size_t size() const { return rows.size() / kDatasetColumns; }
  [[nodiscard]] const float* row(std::size_t i) const { return rows.data() + i * kDatasetColumns; }
};

struct DatasetFrame {
  std::uint64_t budgetSlots = 0;
  std::uint64_t nonEmptyPixels = 0;
  std::uint64_t totalFragments = 0;
  std::uint64_t sampled = 0;  // rows appended
  double optimalError = 0.0;  // Σ_p e_p(k(p)) of the labels' allocation
  std::string solver;         // which optimalKBest solver won
};

// How pixels are drawn: each non-empty pixel with probability s (Pixels), or with probability
// min(1, s·max(1, n(p)/n̄)), n̄ the frame's mean depth complexity (DeepPixels: pixels deeper
// than average in proportion to n(p), where one wrong k costs most slots).
enum class DatasetSampling { Pixels, DeepPixels };

// Appends the non-empty pixels of one frame drawn with sampleFraction = s. errors is the
// frame's hybridErrorTable (reused across budgets). Throws mfr::Error when budgetSlots is below
// one slot per non-empty pixel.
DatasetFrame appendDatasetFrame(DkbDataset& dataset, const FragmentLists& lists, const HybridErrorTable& errors,
                                std::uint64_t budgetSlots, double sampleFraction, std::mt19937_64& rng,
                                DatasetSampling sampling = DatasetSampling::Pixels);

// Both throw mfr::Error naming the path: unwritable; missing, truncated, corrupt or foreign file.
void writeDataset(const std::filesystem::path& path, const DkbDataset& dataset);
DkbDataset readDataset(const std::filesystem::path& path);

}  // namespace mfr
