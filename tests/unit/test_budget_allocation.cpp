// The variable-k budget machinery on the CPU: the allocation rule shared by vkb and dkb (against
// its stated properties, and against the papers' floor(F·I/ΣI)), the dkb features of a hand-made
// list, the weights file, the dataset file, and the dlib training export (the exported weights,
// run by the shaders' own forward pass, reproduce the loss dlib reported).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <random>
#include <span>

#include <nlohmann/json.hpp>

#include "budget/mlp_layout.h"

#include "fragments.hpp"
#include "mfr/budget/dataset.hpp"
#include "mfr/budget/k_allocation.hpp"
#include "mfr/budget/memory_model.hpp"
#include "mfr/budget/neural_importance.hpp"
#include "mfr/budget/neural_training.hpp"
#include "mfr/error.hpp"
#include "mfr/io_util.hpp"
#include "mfr/scene/sample.hpp"
#include "test_files.hpp"

namespace {

using mfr::test::frag;

std::uint64_t sum(const std::vector<std::uint32_t>& v) {
  return std::accumulate(v.begin(), v.end(), std::uint64_t{0});
}

TEST(KAllocation, PropertiesOnRandomCases) {
  std::mt19937 rng(5);
  for (int c = 0; c < 400; ++c) {
    const std::size_t pixels = std::uniform_int_distribution<std::size_t>(1, 300)(rng);
    std::vector<std::uint32_t> n(pixels);
    std::vector<float> importance(pixels);
    std::uniform_int_distribution<std::uint32_t> depth(0, c % 3 == 0 ? 3 : 40);
    std::lognormal_distribution<float> imp(0.0f, 1.5f);
    for (std::size_t p = 0; p < pixels; ++p) {
      n[p] = depth(rng);
      importance[p] = c % 5 == 0 ? 1.0f : imp(rng);  // every fifth case: all importances equal
    }
    const std::uint64_t total = sum(n);
    const std::uint64_t nonEmpty =
        static_cast<std::uint64_t>(std::count_if(n.begin(), n.end(), [](auto v) { return v > 0; }));
    // Tail runs: none (m = 1), or a random final run m(p) ∈ [0, n(p)] of one colour.
    std::vector<std::uint32_t> runs(pixels);
    for (std::size_t p = 0; p < pixels; ++p) runs[p] = std::uniform_int_distribution<std::uint32_t>(0, n[p])(rng);
    for (bool withRuns : {false, true}) {
      // e(p): the core size from which the pixel's hybrid result is exact — max(1, n − 1), or
      // max(1, n − m) with a run of m ≥ 1 (m = 0 counts as 1: one fragment is always exact).
      auto exact = [&](std::size_t p) -> std::uint32_t {
        const std::uint32_t m = withRuns ? std::max<std::uint32_t>(runs[p], 1) : 1;
        if (n[p] == 0) return 0;
        return n[p] > m ? n[p] - m : 1;
      };
      std::uint64_t exactSlots = 0;
      for (std::size_t p = 0; p < pixels; ++p) exactSlots += exact(p);
      for (bool exactTail : {true, false}) {
        for (std::uint64_t F :
             {std::uint64_t{0}, nonEmpty / 2, nonEmpty, nonEmpty + 1, (nonEmpty + exactSlots) / 2, exactSlots,
              exactSlots + 1, (nonEmpty + total) / 2, total > 0 ? total - 1 : 0, total, total + 17}) {
          const mfr::ImportanceAllocation a = mfr::allocateKFromImportance(
              importance, n, F, exactTail,
              withRuns ? std::span<const std::uint32_t>(runs) : std::span<const std::uint32_t>{});
          ASSERT_EQ(a.k.size(), pixels);
          EXPECT_EQ(a.assigned, sum(a.k));
          EXPECT_EQ(a.assigned, std::min(F, total)) << "case " << c << " F " << F;  // the budget is used up
          EXPECT_EQ(a.kFloor, F >= nonEmpty ? 1u : 0u);
          // The bounds of k(p), written out from the rule's statement.
          auto lower = [&](std::size_t p) -> std::uint32_t {
            if (n[p] == 0) return 0;
            if (exactTail && F > exactSlots) return exact(p);
            return F >= nonEmpty ? 1 : 0;
          };
          auto upper = [&](std::size_t p) -> std::uint32_t { return exactTail && F <= exactSlots ? exact(p) : n[p]; };
          for (std::size_t p = 0; p < pixels; ++p) {
            ASSERT_GE(a.k[p], lower(p)) << "case " << c << " F " << F << " n " << n[p] << " m " << runs[p];
            ASSERT_LE(a.k[p], upper(p)) << "case " << c << " F " << F << " n " << n[p] << " m " << runs[p];
          }
          // Monotone in importance (up to the one slot of the remainder): a more important pixel
          // that is not full never has fewer slots than a less important one, minus one.
          for (std::size_t p = 0; p + 1 < pixels; ++p) {
            const std::size_t q = p + 1;
            if (importance[p] >= importance[q] && a.k[p] < upper(p) && n[q] > 0 && a.k[q] > lower(q)) {
              EXPECT_GE(a.k[p] + 1, a.k[q]) << "case " << c << " pixels " << p << "," << q;
            }
          }
        }
      }
    }
  }
}

// The papers' rule floor(F·I(p)/ΣI) (capped at n) wastes slots; ours uses all of them.
TEST(KAllocation, UsesTheSlotsTheFloorRuleWastes) {
  std::vector<std::uint32_t> n(1000);
  std::vector<float> importance(1000);
  std::mt19937 rng(11);
  for (std::size_t p = 0; p < n.size(); ++p) {
    n[p] = 1 + static_cast<std::uint32_t>(p % 7) * 3;
    importance[p] = std::uniform_real_distribution<float>(0.1f, 1.0f)(rng);
  }
  const std::uint64_t F = 4321;
  const double sumI = std::accumulate(importance.begin(), importance.end(), 0.0);
  std::uint64_t floorRule = 0;
  for (std::size_t p = 0; p < n.size(); ++p)
    floorRule += std::clamp<std::uint64_t>(static_cast<std::uint64_t>(std::floor(F * importance[p] / sumI)), 1, n[p]);
  const mfr::ImportanceAllocation a = mfr::allocateKFromImportance(importance, n, F);
  EXPECT_EQ(a.assigned, F);
  EXPECT_LT(floorRule, static_cast<std::uint64_t>(0.97 * F));  // the floor rule leaves > 3 % unused here
  std::cout << "[ allocation ] F = " << F << ": ours assigns " << a.assigned << ", floor(F·I/ΣI) capped at n assigns "
            << floorRule << "\n";
}

TEST(KAllocation, EqualImportanceGivesEqualK) {
  const std::vector<std::uint32_t> n(100, 50);
  const std::vector<float> importance(100, 0.5f);
  const mfr::ImportanceAllocation a = mfr::allocateKFromImportance(importance, n, 730);
  EXPECT_EQ(a.assigned, 730u);
  const auto [lo, hi] = std::minmax_element(a.k.begin(), a.k.end());
  EXPECT_LE(*hi - *lo, 1u);
  EXPECT_EQ(*lo, 7u);
}

TEST(KAllocation, BadImportancesCountAsTheFloor) {
  const std::vector<std::uint32_t> n{5, 5, 5, 5};
  const std::vector<float> importance{std::numeric_limits<float>::quiet_NaN(), -3.0f, 0.0f, 1.0f};
  const mfr::ImportanceAllocation a = mfr::allocateKFromImportance(importance, n, 12);
  EXPECT_EQ(a.assigned, 12u);
  EXPECT_EQ(a.k[3], 4u);  // the only important pixel fills up first, to n − 1 (its tail is exact)
  const mfr::ImportanceAllocation paper = mfr::allocateKFromImportance(importance, n, 12, false);
  EXPECT_EQ(paper.assigned, 12u);
  EXPECT_EQ(paper.k[3], 5u);  // the papers' bounds: up to n
  EXPECT_THROW(mfr::allocateKFromImportance(importance, std::vector<std::uint32_t>{1, 2}, 3), mfr::Error);
}

TEST(DkbFeatures, HandMadeList) {
  const std::vector<mfr::Fragment> list{frag(0.25f, 255, 0, 51, 128), frag(0.5f, 0, 102, 51, 64),
                                        frag(0.75f, 0, 0, 51, 32)};
  mfr::DkbImageStats image;
  image.totalFragments = 60;
  image.nonEmptyPixels = 20;
  image.imageNear = 0.125f;
  image.imageFar = 0.875f;
  const mfr::DkbFeatureVector f = mfr::dkbFeatures(list, image, 30);
  const float expected[12] = {3.0f / 60, 30.0f / 60, 0.25f, 0.75f,        0.125f,       0.875f,
                              1.0f,      0.0f,       0.2f,  255.0f / 765, 102.0f / 765, 153.0f / 765};
  for (int i = 0; i < 12; ++i) EXPECT_NEAR(f[static_cast<std::size_t>(i)], expected[i], 1e-6f) << "feature " << i;
}

mfr::NeuralImportanceModel randomModel(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> w(0.0f, 0.2f);
  mfr::NeuralImportanceModel m;
  m.weights.resize(mfr::NeuralImportanceModel::floatCount());
  for (float& x : m.weights) x = w(rng);
  for (int i = 0; i < 12; ++i)
    m.weights[static_cast<std::size_t>(12 + i)] = 0.5f + static_cast<float>(i) * 0.1f;  // std > 0
  return m;
}

TEST(NeuralImportance, WeightsFileRoundTripAndErrors) {
  const mfr::NeuralImportanceModel m = randomModel(3);
  const mfr::NeuralImportanceModel back = mfr::parseNeuralImportance(mfr::neuralImportanceJson(m), "w.json");
  ASSERT_EQ(back.weights.size(), m.weights.size());
  for (std::size_t i = 0; i < m.weights.size(); ++i) ASSERT_EQ(back.weights[i], m.weights[i]) << i;
  const mfr::DkbFeatureVector x{0.001f, 0.5f, 0.3f, 0.6f, 0.1f, 0.9f, 0.2f, 0.4f, 0.6f, 0.3f, 0.3f, 0.3f};
  const float y = mfr::predictNeuralImportance(m, x);
  EXPECT_GT(y, 0.0f);
  EXPECT_LT(y, 1.0f);
  EXPECT_EQ(mfr::predictNeuralImportance(back, x), y);
  EXPECT_FLOAT_EQ(mfr::neuralImportance(m, x, 10), 10 * y + 0.5f);  // k_over_n: y·n + ½ (rounds k)

  for (const std::string bad : {"", "{", "[]", R"({"format":"mfr-dkb-weights","version":2})",
                                R"({"format":"mfr-dkb-weights","version":1,"architecture":[12,64,1]})"}) {
    try {
      mfr::parseNeuralImportance(bad, "bad.json");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const mfr::Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("bad.json: ", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos);
    }
  }
  std::string text = mfr::neuralImportanceJson(m);
  text.replace(text.find("\"input_std\": ["), 14, "\"input_std\": [-1,");  // a wrong-length, negative std
  EXPECT_THROW(mfr::parseNeuralImportance(text, "bad.json"), mfr::Error);
  EXPECT_THROW(mfr::loadNeuralImportance("/nonexistent/weights.json"), mfr::Error);
  // A finite double beyond a float (the network runs in floats: 1e39 was infinite there).
  nlohmann::json huge = nlohmann::json::parse(mfr::neuralImportanceJson(m));
  huge["input_mean"][0] = 1e39;
  try {
    mfr::parseNeuralImportance(huge.dump(), "huge.json");
    ADD_FAILURE() << "accepted a mean of 1e39";
  } catch (const mfr::Error& e) {
    EXPECT_NE(std::string(e.what()).find("beyond a float's range"), std::string::npos) << e.what();
  }
}

// dkb's GPU copy: input statistics and biases exact, each weight scale(row)·q with q a signed byte
// and scale(row) = max|w| / 127 of its output row, packed four per word; the packing reads back.
TEST(NeuralImportance, EightBitPacking) {
  const mfr::NeuralImportanceModel m = randomModel(9);
  const mfr::NeuralImportanceModel h = m.quantised();
  const std::vector<std::uint32_t> words = h.packedWords();
  ASSERT_EQ(words.size() * 4, mfr::NeuralImportanceModel::packedBytes());
  EXPECT_LT(mfr::NeuralImportanceModel::packedBytes(), m.weights.size() * 4 * 30 / 100);  // under a third
  EXPECT_THROW((void)m.packedWords(), mfr::Error);                                        // not quantised
  const auto wordFloat = [&](std::size_t i) {
    float f = 0;
    std::memcpy(&f, &words[i], 4);
    return f;
  };
  for (std::size_t i = 0; i < MFR_MLP_W1; ++i) {
    EXPECT_EQ(h.weights[i], m.weights[i]);
    EXPECT_EQ(wordFloat(i), m.weights[i]);
  }
  struct Layer {
    int weights, bias, rows, cols, firstRow, quant;
  };
  const Layer layers[3] = {
      {MFR_MLP_W1, MFR_MLP_B1, MFR_MLP_HIDDEN1, MFR_MLP_INPUTS, 0, MFR_MLP_Q_W1},
      {MFR_MLP_W2, MFR_MLP_B2, MFR_MLP_HIDDEN2, MFR_MLP_HIDDEN1, MFR_MLP_HIDDEN1, MFR_MLP_Q_W2},
      {MFR_MLP_W3, MFR_MLP_B3, 1, MFR_MLP_HIDDEN2, MFR_MLP_HIDDEN1 + MFR_MLP_HIDDEN2, MFR_MLP_Q_W3}};
  std::size_t changed = 0, extremes = 0;
  for (const Layer& l : layers)
    for (int r = 0; r < l.rows; ++r) {
      const auto row = static_cast<std::size_t>(l.firstRow + r);
      const auto bias = static_cast<std::size_t>(l.bias + r);
      EXPECT_EQ(h.weights[bias], m.weights[bias]);
      EXPECT_EQ(wordFloat(MFR_MLP_GPU_BIAS + row), m.weights[bias]);
      float maxAbs = 0;
      for (int c = 0; c < l.cols; ++c)
        maxAbs = std::max(maxAbs, std::abs(m.weights[static_cast<std::size_t>(l.weights + r * l.cols + c)]));
      const float scale = wordFloat(MFR_MLP_GPU_SCALE + row);
      ASSERT_EQ(scale, h.rowScales[row]);
      EXPECT_FLOAT_EQ(scale, maxAbs / 127.0f);
      for (int c = 0; c < l.cols; ++c) {
        const auto i = static_cast<std::size_t>(l.weights + r * l.cols + c);
        const int j = l.quant + r * l.cols + c;
        const auto q =
            static_cast<std::int8_t>(words[MFR_MLP_GPU_QUANT + static_cast<std::size_t>(j / 4)] >> (8 * (j % 4)));
        ASSERT_EQ(scale * static_cast<float>(q), h.weights[i]) << i;
        EXPECT_LE(std::abs(h.weights[i] - m.weights[i]), 0.5f * scale * 1.0001f) << i;
        changed += h.weights[i] != m.weights[i];
        extremes += q == 127 || q == -127;
      }
    }
  EXPECT_GT(changed, m.weights.size() / 2);                     // really rounded
  EXPECT_GE(extremes, static_cast<std::size_t>(MFR_MLP_ROWS));  // each row's largest weight is ±127
}

TEST(DkbDataset, FramesFileRoundTripAndCorruptFiles) {
  const mfr::Scene scene = mfr::makeSampleScene();
  const mfr::FragmentLists lists = mfr::castFragments(scene, scene.view("front"), 32, 24);
  const mfr::HybridErrorTable errors = mfr::hybridErrorTable(lists, scene.background);
  const std::uint64_t nonEmpty = mfr::minimumSlots(errors);
  mfr::DkbDataset d;
  std::mt19937_64 rng(1);
  const mfr::DatasetFrame f = mfr::appendDatasetFrame(d, lists, errors, 2 * nonEmpty, 1.0, rng);
  EXPECT_EQ(f.sampled, nonEmpty);  // sample = 1: every non-empty pixel
  EXPECT_EQ(d.size(), nonEmpty);
  // Labels: the optimal allocation's k, Σk within the budget, k/F consistent, 1 ≤ k ≤ n.
  double sumK = 0;
  for (std::size_t r = 0; r < d.size(); ++r) {
    const float* row = d.row(r);
    EXPECT_GE(row[mfr::kDatasetK], 1.0f);
    EXPECT_LE(row[mfr::kDatasetK], row[mfr::kDatasetN]);
    EXPECT_NEAR(row[mfr::kDatasetLabel], row[mfr::kDatasetK] / static_cast<float>(2 * nonEmpty), 1e-9);
    sumK += row[mfr::kDatasetK];
  }
  EXPECT_LE(sumK, static_cast<double>(2 * nonEmpty));
  d.metadata = R"({"test":true})";
  const mfr::test::TempDir tmp;
  const std::filesystem::path& dir = tmp.path();
  const auto path = dir / "d.bin";
  mfr::writeDataset(path, d);
  const mfr::DkbDataset back = mfr::readDataset(path);
  EXPECT_EQ(back.rows, d.rows);
  EXPECT_EQ(back.metadata, d.metadata);
  // Truncated and foreign files: one line naming the file.
  const std::string bytes = mfr::readFile(path);
  mfr::writeFileAtomically(dir / "cut.bin", bytes.substr(0, bytes.size() - 5));
  mfr::writeFileAtomically(dir / "foreign.bin", "PNG\x89 not a dataset at all, really");
  // A row whose labels mfr dataset cannot have written (k/F of 1e30: training went to NaN).
  std::uint32_t metaLength = 0;
  std::memcpy(&metaLength, bytes.data() + 20, 4);
  std::string absurd = bytes;
  const float huge = 1e30f;
  std::memcpy(absurd.data() + 24 + metaLength + 4 * mfr::kDatasetLabel, &huge, 4);
  mfr::writeFileAtomically(dir / "absurd.bin", absurd);
  try {
    mfr::readDataset(dir / "absurd.bin");
    ADD_FAILURE() << "absurd.bin";
  } catch (const mfr::Error& e) {
    EXPECT_NE(std::string(e.what()).find("absurd.bin: row 0: labels out of range"), std::string::npos) << e.what();
  }
  // A NaN is named by its row and column, as docs/methods.md says (it was "holds a non-finite value").
  if (d.size() > 1) {
    std::string nan = bytes;
    const float notANumber = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(nan.data() + 24 + metaLength + 4 * (mfr::kDatasetColumns + 3), &notANumber, 4);
    mfr::writeFileAtomically(dir / "nan.bin", nan);
    try {
      mfr::readDataset(dir / "nan.bin");
      ADD_FAILURE() << "nan.bin";
    } catch (const mfr::Error& e) {
      EXPECT_NE(std::string(e.what()).find("nan.bin: row 1, column 3: a non-finite value"), std::string::npos)
          << e.what();
    }
  } else {
    ADD_FAILURE() << "the dataset has one row: no second row to corrupt";
  }
  for (const char* name : {"cut.bin", "foreign.bin", "missing.bin"}) {
    try {
      mfr::readDataset(dir / name);
      ADD_FAILURE() << name;
    } catch (const mfr::Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

// --sample-by: Pixels draws every non-empty pixel with probability s; DeepPixels draws a pixel of
// depth n with min(1, s·max(1, n/n̄)). Observed row counts, split at the mean depth n̄, must match the
// expected counts of each rule within 4 standard deviations (and the two rules must differ).
TEST(DkbDataset, DeepPixelSampling) {
  const mfr::Scene scene = mfr::makeSampleScene();
  const mfr::FragmentLists lists = mfr::castFragments(scene, scene.view("iso"), 160, 120);
  const mfr::HybridErrorTable errors = mfr::hybridErrorTable(lists, scene.background);
  const std::uint64_t nonEmpty = mfr::minimumSlots(errors);
  const double meanDepth = static_cast<double>(lists.fragments.size()) / static_cast<double>(nonEmpty);
  const double s = 0.1;
  for (const auto sampling : {mfr::DatasetSampling::Pixels, mfr::DatasetSampling::DeepPixels}) {
    const bool deep = sampling == mfr::DatasetSampling::DeepPixels;
    double expected[2] = {0, 0}, variance[2] = {0, 0}, pixels[2] = {0, 0};  // [shallow, deep]
    for (int y = 0; y < lists.height; ++y)
      for (int x = 0; x < lists.width; ++x) {
        const double n = static_cast<double>(lists.count(x, y));
        if (n == 0) continue;
        const double p = deep ? std::min(1.0, s * std::max(1.0, n / meanDepth)) : s;
        expected[n > meanDepth] += p;
        pixels[n > meanDepth] += 1;
        variance[n > meanDepth] += p * (1 - p);
      }
    mfr::DkbDataset d;
    std::mt19937_64 rng(7);
    mfr::appendDatasetFrame(d, lists, errors, 2 * nonEmpty, s, rng, sampling);
    double observed[2] = {0, 0};
    for (std::size_t r = 0; r < d.size(); ++r) observed[d.row(r)[mfr::kDatasetN] > meanDepth] += 1;
    for (int part = 0; part < 2; ++part)
      EXPECT_NEAR(observed[part], expected[part], 4 * std::sqrt(variance[part]) + 1) << deep << " " << part;
    if (deep) {
      EXPECT_GT(observed[1], 1.3 * s * pixels[1]);  // deep pixels really drawn more often
    }
    EXPECT_GT(pixels[1], 200);
  }
}

// Mean squared error of k/n over every row, run through the shaders' forward pass on the CPU;
// weightByN: each row weighted by its n(p).
double cpuLoss(const mfr::NeuralImportanceModel& model, const mfr::DkbDataset& d, bool weightByN) {
  double sq = 0, weights = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const float* row = d.row(i);
    mfr::DkbFeatureVector x;
    std::copy(row, row + 12, x.begin());
    const double diff = mfr::predictNeuralImportance(model, x) - row[mfr::kDatasetK] / row[mfr::kDatasetN];
    const double w = weightByN ? row[mfr::kDatasetN] : 1.0;
    sq += w * diff * diff;
    weights += w;
  }
  return sq / weights;
}

// A training set whose label is a known function of the features: per row 12 uniform features
// (feature f scaled by scale(f)), n uniform in 1..nRange, k = kOf(features, n), k/F with F = 1000.
template <class Scale, class KOf>
mfr::DkbDataset syntheticDataset(unsigned seed, int rows, float nRange, Scale scale, KOf kOf) {
  mfr::DkbDataset d;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int r = 0; r < rows; ++r) {
    float row[mfr::kDatasetColumns];
    for (int f = 0; f < 12; ++f) row[f] = u(rng) * scale(f);
    const float n = 1.0f + std::floor(u(rng) * nRange);
    row[mfr::kDatasetN] = n;
    row[mfr::kDatasetK] = kOf(row, n);
    row[mfr::kDatasetLabel] = row[mfr::kDatasetK] / 1000.0f;
    d.rows.insert(d.rows.end(), row, row + mfr::kDatasetColumns);
  }
  return d;
}

// Trains on a small synthetic dataset whose target is a known function of the features, then runs
// the exported weights through the shaders' forward pass (predictNeuralImportance): its MSE over
// all rows must equal the mix of dlib's training and validation MSE — a wrong export of dlib's
// fc layout (transposed weights, bias in the wrong row) would not reproduce it.
TEST(NeuralTraining, ExportedWeightsReproduceDlibsLoss) {
  const mfr::DkbDataset d = syntheticDataset(
      2, 3000, 20.0f, [](int f) { return static_cast<float>(f + 1); },
      [](const float* row, float n) { return (0.2f + 0.6f / (1.0f + std::exp(2.0f - row[0] - 0.3f * row[5]))) * n; });
  mfr::NeuralTrainingOptions o;
  o.epochs = 4;
  o.batchSize = 64;
  o.learningRate = 0.01;
  std::vector<double> losses;
  o.progress = [&](std::size_t, double train, double) { losses.push_back(train); };
  const mfr::NeuralTrainingResult r = mfr::trainNeuralImportance(d, o);
  ASSERT_EQ(losses.size(), 4u);
  EXPECT_LT(losses.back(), losses.front());  // it learns
  EXPECT_EQ(r.trainingRows + r.validationRows, d.size());
  const double cpu = cpuLoss(r.model, d, false);
  const double mixed = (r.trainingLoss * static_cast<double>(r.trainingRows) +
                        r.validationLoss * static_cast<double>(r.validationRows)) /
                       static_cast<double>(d.size());
  EXPECT_NEAR(cpu, mixed, 1e-4 * mixed + 1e-9);
  // And through the weights file.
  const mfr::NeuralImportanceModel back = mfr::parseNeuralImportance(mfr::neuralImportanceJson(r.model), "t.json");
  mfr::DkbFeatureVector x;
  std::copy(d.row(0), d.row(0) + 12, x.begin());
  EXPECT_EQ(mfr::predictNeuralImportance(back, x), mfr::predictNeuralImportance(r.model, x));
}

// A run whose loss stops being finite (labels far outside [0, 1], which mfr dataset files can no
// longer hold) is one error saying so: it ended in "unexpected dlib fc layer size" (a bug hunt).
TEST(NeuralTraining, ADivergedRunIsAnError) {
  const mfr::DkbDataset d = syntheticDataset(
      3, 200, 8.0f, [](int) { return 1.0f; }, [](const float*, float) { return 1e30f; });
  mfr::NeuralTrainingOptions o;
  o.epochs = 2;
  o.batchSize = 32;
  o.target = "k_over_budget";
  try {
    (void)mfr::trainNeuralImportance(d, o);
    ADD_FAILURE() << "trained on labels of 1e27";
  } catch (const mfr::Error& e) {
    EXPECT_NE(std::string(e.what()).find("the loss is not finite after epoch 1"), std::string::npos) << e.what();
  }
}

// Rows drawn in proportion to n(p): the network still learns, the reported losses are weighted by
// n (so they differ from the unweighted ones of the same weights), and a bad option is refused.
TEST(NeuralTraining, FragmentWeighting) {
  const mfr::DkbDataset d = syntheticDataset(
      4, 2000, 30.0f, [](int) { return 1.0f; },
      [](const float* row, float n) { return std::max(1.0f, std::round(n * (0.2f + 0.6f * row[3]))); });
  mfr::NeuralTrainingOptions o;
  o.epochs = 4;
  o.batchSize = 64;
  o.learningRate = 0.01;
  o.weighting = "fragments";
  std::vector<double> losses;
  o.progress = [&](std::size_t, double train, double) { losses.push_back(train); };
  const mfr::NeuralTrainingResult r = mfr::trainNeuralImportance(d, o);
  EXPECT_LT(losses.back(), losses.front());
  // The weighted loss of the exported model, recomputed on the CPU over all rows, is close to the
  // mix of the reported (weighted) ones.
  EXPECT_NEAR(cpuLoss(r.model, d, true), r.trainingLoss, 0.15 * r.trainingLoss);
  o.weighting = "by-colour";
  EXPECT_THROW(mfr::trainNeuralImportance(d, o), mfr::Error);
}

TEST(VariableKLayout, BytesAndSlotBudget) {
  const mfr::VariableKLayout l = mfr::variableKLayout(1000, 40);
  // Regions: 1000 → 1024 words (lock), 5 × 1024 (stride for 1001), 1024 (k): 7168 words.
  EXPECT_EQ(l.tailBase, 1024u);
  EXPECT_EQ(l.stride, 1024u);
  EXPECT_EQ(l.kBase, 1024u + 5 * 1024u);
  EXPECT_EQ(l.arenaWords, 7168u);
  EXPECT_EQ(l.fixedBytes, 32u + 128u + 40u);
  EXPECT_EQ(l.bytes(10), 80 + 4 * 7168 + l.scanScratchBytes + 200);
  EXPECT_EQ(l.slotBudget(l.bytes(10)), 10u);
  EXPECT_EQ(l.slotBudget(l.bytes(10) + 7), 10u);
  EXPECT_EQ(l.slotBudget(l.bytesBeforeSlots()), 0u);
  EXPECT_EQ(l.slotBudget(0), 0u);
  EXPECT_EQ(mfr::variableKLayout(1024).stride, 1088u);  // 1025 words round up to 17 × 64
}

}  // namespace
