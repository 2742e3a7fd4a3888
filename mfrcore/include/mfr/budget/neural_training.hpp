#pragma once
// Training the dkb network (Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent
// transparency", The Visual Computer 2022, §4) with dlib's DNN toolkit: the paper's 12-128-64-1
// network (ReLU, ReLU, sigmoid), mean squared error, SGD with learning rate 0.001 and mini-batches
// of 512. dlib's sgd solver offers L2 weight decay and momentum but no L1 term, so the paper's
// L1/L2 regularisation is L2 only (weight_decay); momentum is dlib's (0.9 by default). Inputs are
// standardised with the training rows' mean and standard deviation, stored in the model.
#include <cstdint>
#include <functional>
#include <string>

#include "mfr/budget/dataset.hpp"
#include "mfr/budget/neural_importance.hpp"

namespace mfr {

struct NeuralTrainingOptions {
  std::string target = "k_over_n";  // what the sigmoid predicts: k/n or k/F ("k_over_budget")
  std::size_t epochs = 40;
  double learningRate = 0.001;
  std::size_t batchSize = 512;
  double weightDecay = 0.0005;  // L2
  double momentum = 0.9;
  double validationFraction = 0.1;  // rows held out to pick the best epoch
  // "none": every row as often as the next; "fragments": rows drawn (with replacement) with
  // probability ∝ n(p) each epoch, and the losses weighted by n(p) — a pixel's k error costs slots
  // in proportion to its depth, so deep pixels should be fitted better (still mean squared error).
  std::string weighting = "none";
  std::uint64_t seed = 1;
  // Called after each epoch: (epoch, training MSE, validation MSE).
  std::function<void(std::size_t, double, double)> progress;
};

struct NeuralTrainingResult {
  NeuralImportanceModel model;  // weights of the epoch with the least validation error
  std::size_t bestEpoch = 0;
  double trainingLoss = 0.0, validationLoss = 0.0;
  std::size_t trainingRows = 0, validationRows = 0;
};

// Throws mfr::Error for an empty dataset or bad options.
NeuralTrainingResult trainNeuralImportance(const DkbDataset& dataset, const NeuralTrainingOptions& options);

}  // namespace mfr
