// dkb training with dlib (mfr/budget/neural_training.hpp). The network is dlib's; this file only
// feeds it rows, runs epochs and copies its layers into the shader layout of
// shaders/budget/mlp.h.
#include "mfr/budget/neural_training.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wcast-align"
#include <dlib/dnn.h>
#include <dlib/revision.h>
#pragma GCC diagnostic pop
#include <nlohmann/json.hpp>

#include "budget/mlp_layout.h"
#include "mfr/error.hpp"
#include "mfr/json_text.hpp"

namespace mfr {

namespace {

using Sample = dlib::matrix<float, kDkbFeatures, 1>;
// loss ← sigmoid ← fc(1) ← relu ← fc(64) ← relu ← fc(128) ← input(12)
using DkbNet = dlib::loss_mean_squared<
    dlib::sig<dlib::fc<1, dlib::relu<dlib::fc<64, dlib::relu<dlib::fc<128, dlib::input<Sample>>>>>>>>;

// Copies an fc layer (dlib params: (inputs + 1) × outputs, row i = input i, the last row the bias;
// output = x·W + b) into the row-major [output][input] layout of mlp.h.
template <class Layer>
void exportFc(const Layer& layer, int inputs, int outputs, int weightBase, int biasBase, std::vector<float>& out) {
  const dlib::tensor& params = layer.layer_details().get_layer_params();
  if (params.size() != (static_cast<std::size_t>(inputs) + 1) * static_cast<std::size_t>(outputs))
    throw Error("dkb training", "unexpected dlib fc layer size");
  const float* p = params.host();
  const auto in = static_cast<std::size_t>(inputs), outs = static_cast<std::size_t>(outputs);
  for (std::size_t o = 0; o < outs; ++o) {
    for (std::size_t i = 0; i < in; ++i) out[static_cast<std::size_t>(weightBase) + o * in + i] = p[i * outs + o];
    out[static_cast<std::size_t>(biasBase) + o] = p[in * outs + o];
  }
}

// Mean squared error, weighted by w when w is not empty.
double meanSquaredError(DkbNet& net, const std::vector<Sample>& x, const std::vector<float>& y,
                        const std::vector<float>& w) {
  if (x.empty()) return 0.0;
  double sum = 0.0, weights = 0.0;
  const std::size_t batch = 4096;
  for (std::size_t i = 0; i < x.size(); i += batch) {
    const std::size_t end = std::min(x.size(), i + batch);
    const std::vector<Sample> part(x.begin() + static_cast<std::ptrdiff_t>(i),
                                   x.begin() + static_cast<std::ptrdiff_t>(end));
    const std::vector<float> pred = net(part);
    for (std::size_t j = 0; j < pred.size(); ++j) {
      const double d = static_cast<double>(pred[j]) - y[i + j];
      const double weight = w.empty() ? 1.0 : w[i + j];
      sum += weight * d * d;
      weights += weight;
    }
  }
  return weights > 0.0 ? sum / weights : 0.0;
}

}  // namespace

NeuralTrainingResult trainNeuralImportance(const DkbDataset& dataset, const NeuralTrainingOptions& options) {
  if (dataset.size() < 2) throw Error("train", "the dataset has fewer than 2 rows");
  if (options.target != "k_over_n" && options.target != "k_over_budget")
    throw Error("--target " + options.target, "expected k_over_n or k_over_budget");
  if (options.batchSize == 0 || options.epochs == 0) throw Error("train", "epochs and batch size must be positive");
  if (options.weighting != "none" && options.weighting != "fragments")
    throw Error("--weighting " + options.weighting, "expected none or fragments");
  const bool weighted = options.weighting == "fragments";

  // Standardisation from all rows (the same for training and validation rows).
  std::vector<double> mean(kDkbFeatures, 0.0), var(kDkbFeatures, 0.0);
  for (std::size_t r = 0; r < dataset.size(); ++r)
    for (int f = 0; f < kDkbFeatures; ++f) mean[static_cast<std::size_t>(f)] += dataset.row(r)[f];
  for (double& m : mean) m /= static_cast<double>(dataset.size());
  for (std::size_t r = 0; r < dataset.size(); ++r)
    for (int f = 0; f < kDkbFeatures; ++f) {
      const double d = dataset.row(r)[f] - mean[static_cast<std::size_t>(f)];
      var[static_cast<std::size_t>(f)] += d * d;
    }
  std::vector<float> stddev(kDkbFeatures);
  for (int f = 0; f < kDkbFeatures; ++f)
    stddev[static_cast<std::size_t>(f)] = static_cast<float>(
        std::max(std::sqrt(var[static_cast<std::size_t>(f)] / static_cast<double>(dataset.size())), 1e-6));

  // Rows → standardised samples and targets; a random validation split.
  std::mt19937_64 rng(options.seed);
  std::vector<std::size_t> order(dataset.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), rng);
  const std::size_t validation = std::min<std::size_t>(
      dataset.size() - 1, static_cast<std::size_t>(options.validationFraction * static_cast<double>(dataset.size())));
  std::vector<Sample> trainX, validX;
  std::vector<float> trainY, validY, trainW, validW;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const float* row = dataset.row(order[i]);
    Sample s;
    for (int f = 0; f < kDkbFeatures; ++f)
      s(f) = static_cast<float>((row[f] - mean[static_cast<std::size_t>(f)]) / stddev[static_cast<std::size_t>(f)]);
    const float n = std::max(row[kDatasetN], 1.0f);
    const float y = options.target == "k_over_n" ? row[kDatasetK] / n : row[kDatasetLabel];
    (i < validation ? validX : trainX).push_back(s);
    (i < validation ? validY : trainY).push_back(y);
    if (weighted) (i < validation ? validW : trainW).push_back(n);
  }

  dlib::set_dnn_prefer_smallest_algorithms();
  DkbNet net;
  dlib::sgd solver(static_cast<float>(options.weightDecay), static_cast<float>(options.momentum));
  dlib::dnn_trainer<DkbNet, dlib::sgd> trainer(net, solver);
  trainer.set_learning_rate(options.learningRate);
  trainer.set_min_learning_rate(options.learningRate);  // a fixed rate: the paper's 0.001
  trainer.set_learning_rate_shrink_factor(1.0);
  trainer.set_mini_batch_size(options.batchSize);

  NeuralTrainingResult result;
  result.trainingRows = trainX.size();
  result.validationRows = validX.size();
  result.validationLoss = std::numeric_limits<double>::infinity();
  DkbNet best;
  std::vector<std::size_t> batchOrder(trainX.size());
  std::iota(batchOrder.begin(), batchOrder.end(), std::size_t{0});
  std::vector<Sample> bx;
  std::vector<float> by;
  std::discrete_distribution<std::size_t> byFragments(trainW.begin(), trainW.end());
  for (std::size_t epoch = 1; epoch <= options.epochs; ++epoch) {
    if (weighted) {
      for (std::size_t& i : batchOrder) i = byFragments(rng);
    } else {
      std::shuffle(batchOrder.begin(), batchOrder.end(), rng);
    }
    for (std::size_t i = 0; i < batchOrder.size(); i += options.batchSize) {
      const std::size_t end = std::min(batchOrder.size(), i + options.batchSize);
      bx.clear();
      by.clear();
      for (std::size_t j = i; j < end; ++j) {
        bx.push_back(trainX[batchOrder[j]]);
        by.push_back(trainY[batchOrder[j]]);
      }
      trainer.train_one_step(bx, by);
    }
    trainer.get_net(dlib::force_flush_to_disk::no);  // waits for the trainer's thread
    const double trainLoss = meanSquaredError(net, trainX, trainY, trainW);
    const double validLoss = validX.empty() ? trainLoss : meanSquaredError(net, validX, validY, validW);
    // A diverged run keeps no network worth writing (it ended in a confusing dlib layer error).
    if (!std::isfinite(trainLoss) || !std::isfinite(validLoss))
      throw Error("dkb training", "the loss is not finite after epoch " + std::to_string(epoch) +
                                      " (diverged: try a smaller learning rate)");
    if (options.progress) options.progress(epoch, trainLoss, validLoss);
    if (validLoss < result.validationLoss) {
      result.validationLoss = validLoss;
      result.trainingLoss = trainLoss;
      result.bestEpoch = epoch;
      best = net;
    }
  }
  best.clean();

  NeuralImportanceModel& m = result.model;
  m.target = options.target;
  m.weights.assign(NeuralImportanceModel::floatCount(), 0.0f);
  for (int f = 0; f < kDkbFeatures; ++f) {
    m.weights[static_cast<std::size_t>(MFR_MLP_MEAN + f)] = static_cast<float>(mean[static_cast<std::size_t>(f)]);
    m.weights[static_cast<std::size_t>(MFR_MLP_STD + f)] = stddev[static_cast<std::size_t>(f)];
  }
  // layer<0> is the loss, 1 the sigmoid, 2 = fc(1), 4 = fc(64), 6 = fc(128).
  exportFc(dlib::layer<6>(best), MFR_MLP_INPUTS, MFR_MLP_HIDDEN1, MFR_MLP_W1, MFR_MLP_B1, m.weights);
  exportFc(dlib::layer<4>(best), MFR_MLP_HIDDEN1, MFR_MLP_HIDDEN2, MFR_MLP_W2, MFR_MLP_B2, m.weights);
  exportFc(dlib::layer<2>(best), MFR_MLP_HIDDEN2, 1, MFR_MLP_W3, MFR_MLP_B3, m.weights);
  nlohmann::ordered_json t;
  t["library"] = "dlib " + std::to_string(DLIB_MAJOR_VERSION) + "." + std::to_string(DLIB_MINOR_VERSION);
  t["loss"] = "mean squared error";
  t["solver"] = "sgd";
  t["learning_rate"] = options.learningRate;
  t["batch_size"] = options.batchSize;
  t["weight_decay_l2"] = options.weightDecay;
  t["l1"] = "not available in dlib's sgd solver";
  t["momentum"] = options.momentum;
  t["weighting"] = options.weighting;
  t["epochs"] = options.epochs;
  t["best_epoch"] = result.bestEpoch;
  t["training_rows"] = result.trainingRows;
  t["validation_rows"] = result.validationRows;
  t["training_mse"] = result.trainingLoss;
  t["validation_mse"] = result.validationLoss;
  t["seed"] = options.seed;
  t["dataset"] = nlohmann::ordered_json::parse(dataset.metadata.empty() ? "{}" : dataset.metadata, nullptr, false);
  m.trainingJson = jsonText(t);
  m.source = "trained";
  return result;
}

}  // namespace mfr
