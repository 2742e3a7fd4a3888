// dkb training data: frames → rows of features and optimal-k labels; the binary file format
// (mfr/budget/dataset.hpp).
#include "mfr/budget/dataset.hpp"

#include <cmath>
#include <cstring>
#include <string_view>

#include <nlohmann/json.hpp>

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/json_text.hpp"
#include "number_text.hpp"
#include "mfr/io_util.hpp"

namespace mfr {

namespace {
constexpr char kMagic[8] = {'M', 'F', 'R', 'D', 'K', 'B', '1', '\n'};

template <class T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}
}  // namespace

DatasetFrame appendDatasetFrame(DkbDataset& dataset, const FragmentLists& lists, const HybridErrorTable& errors,
                                std::uint64_t budgetSlots, double sampleFraction, std::mt19937_64& rng,
                                DatasetSampling sampling) {
  DatasetFrame frame;
  const DkbImageStats image = dkbImageStats(lists);
  frame.budgetSlots = budgetSlots;
  frame.nonEmptyPixels = image.nonEmptyPixels;
  frame.totalFragments = image.totalFragments;
  const KAllocation best = optimalKBest(errors, budgetSlots, &frame.solver);
  frame.optimalError = best.error;
  // Deep pixels are few but hold most of the slots; DeepPixels keeps more of them.
  const double meanDepth =
      static_cast<double>(image.totalFragments) / static_cast<double>(std::max<std::uint64_t>(image.nonEmptyPixels, 1));
  for (int y = 0; y < lists.height; ++y)
    for (int x = 0; x < lists.width; ++x) {
      const auto list = lists.pixel(x, y);
      if (list.empty()) continue;
      const double boost =
          sampling == DatasetSampling::DeepPixels ? std::max(1.0, static_cast<double>(list.size()) / meanDepth) : 1.0;
      if (!std::bernoulli_distribution(std::min(1.0, sampleFraction * boost))(rng)) continue;  // one draw each
      const DkbFeatureVector f = dkbFeatures(list, image, budgetSlots);
      const std::uint32_t k = best.k[lists.index(x, y)];
      dataset.rows.insert(dataset.rows.end(), f.begin(), f.end());
      dataset.rows.push_back(static_cast<float>(static_cast<double>(k) / static_cast<double>(budgetSlots)));
      dataset.rows.push_back(static_cast<float>(k));
      dataset.rows.push_back(static_cast<float>(list.size()));
      ++frame.sampled;
    }
  return frame;
}

void writeDataset(const std::filesystem::path& path, const DkbDataset& dataset) {
  std::string bytes(kMagic, sizeof kMagic);
  put<std::uint32_t>(bytes, kDatasetColumns);
  put<std::uint64_t>(bytes, dataset.size());
  put<std::uint32_t>(bytes, static_cast<std::uint32_t>(dataset.metadata.size()));
  bytes += dataset.metadata;
  bytes.append(reinterpret_cast<const char*>(dataset.rows.data()), dataset.size() * kDatasetColumns * sizeof(float));
  writeFileAtomically(path, bytes);
}

DkbDataset readDataset(const std::filesystem::path& path) {
  const std::string bytes = readFile(path);
  const std::string where = path.string();
  constexpr std::size_t header = sizeof kMagic + 4 + 8 + 4;
  if (bytes.size() < header || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw Error(where, "not an mfr dkb dataset (no MFRDKB1 header)");
  std::uint32_t columns = 0, metaLength = 0;
  std::uint64_t rows = 0;
  std::memcpy(&columns, bytes.data() + 8, 4);
  std::memcpy(&rows, bytes.data() + 12, 8);
  std::memcpy(&metaLength, bytes.data() + 20, 4);
  if (columns != kDatasetColumns)
    throw Error(where, "has " + std::to_string(columns) + " columns, expected " + std::to_string(kDatasetColumns));
  const std::uint64_t payload = rows * kDatasetColumns * sizeof(float);
  if (rows > (1ull << 40) || bytes.size() != header + metaLength + payload)
    throw Error(where, "truncated or corrupt (" + std::to_string(bytes.size()) + " bytes for " + std::to_string(rows) +
                           " rows)");
  DkbDataset d;
  d.metadata = bytes.substr(header, metaLength);
  if (!d.metadata.empty() && !nlohmann::json::accept(d.metadata))
    throw Error(where, "corrupt (its metadata is not JSON)");
  // Room for the record mfr train nests it in (training.dataset[i]), so that its weights file stays
  // readable (a review).
  requireJsonNesting(d.metadata, where, "corrupt: its metadata ", kDatasetMetadataNestingLimit);
  // The rows beside the file's bytes, asked of the host's memory first (a bug hunt).
  requireHostMemory(where, "its " + std::to_string(rows) + " rows (" + formatMemory(payload) + ")", payload);
  d.rows.resize(rows * kDatasetColumns);
  std::memcpy(d.rows.data(), bytes.data() + header + metaLength, payload);
  for (std::size_t i = 0; i < d.rows.size(); ++i)
    if (!std::isfinite(d.rows[i]))  // with its row and column, as docs/methods.md says
      throw Error(where, "row " + std::to_string(i / kDatasetColumns) + ", column " +
                             std::to_string(i % kDatasetColumns) + ": a non-finite value");
  // Features a weights file can hold the mean and spread of (its parameters lie within ±1e4; mfr
  // dataset's are shares, depths and colours, within [0, 1]): a feature of 3e38 trained weights
  // that mfr then refused (a bug hunt).
  for (std::size_t i = 0; i < d.size(); ++i)
    for (int f = 0; f < kDkbFeatures; ++f)
      if (const float v = d.row(i)[f]; !(std::abs(v) <= 1e4f))
        throw Error(where, "row " + std::to_string(i) + ", column " + std::to_string(f) + ": feature " + numberText(v) +
                               " beyond ±10000 (mfr dataset's features lie within [0, 1])");
  // The labels as mfr dataset writes them: n(p) ≥ 1 and k(p) whole, 1 ≤ k(p) ≤ n(p), k(p)/F in
  // (0, 1]. A row outside them trained on (a label of 1e30 drove the loss to NaN).
  for (std::size_t i = 0; i < d.size(); ++i) {
    const float* row = d.row(i);
    const float n = row[kDatasetN], k = row[kDatasetK], label = row[kDatasetLabel];
    if (!(n >= 1.0f && n == std::floor(n) && k >= 1.0f && k <= n && k == std::floor(k) && label > 0.0f &&
          label <= 1.0f))
      throw Error(where, "row " + std::to_string(i) + ": labels out of range (n(p) " + numberText(n) + ", k(p) " +
                             numberText(k) + ", k(p)/F " + numberText(label) +
                             "; expected whole numbers 1 <= k <= n and 0 < k/F <= 1)");
  }
  return d;
}

}  // namespace mfr
