// mfr train: trains the dkb network on an mfr dataset with dlib (mfr/budget/neural_training.hpp)
// and writes the weights file dkb reads (--param weights=FILE; the shipped one is
// resources/dkb/weights.json, its command and scenes in resources/dkb/README.md).
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "mfr/budget/dataset.hpp"
#include "mfr/budget/neural_training.hpp"
#include "mfr/error.hpp"
#include "mfr/io_util.hpp"

namespace mfr::cli {

void addTrain(CLI::App& app) {
  struct Options {
    std::vector<std::string> datasets;
    std::string output;
    NeuralTrainingOptions training;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("train", "Train the dkb network (12-128-64-1, dlib) on mfr dataset files");
  cmd->add_option("datasets", opt->datasets, "Dataset files written by mfr dataset")->required();
  cmd->add_option("-o,--output", opt->output, "Output weights file (JSON)")->required();
  cmd->add_option("--target", opt->training.target, "What the network predicts: k_over_n or k_over_budget")
      ->capture_default_str();
  cmd->add_option("--epochs", opt->training.epochs, "Epochs")
      ->capture_default_str()
      ->check(wholeNumber())
      ->check(CLI::Range(1, 100000));
  // dlib asserts on a rate of 0 and trains to NaN on NaN decay or momentum: checked here.
  cmd->add_option("--learning-rate", opt->training.learningRate, "SGD learning rate")
      ->capture_default_str()
      ->check(finiteRange(1e-12, 10.0));
  cmd->add_option("--batch", opt->training.batchSize, "Mini-batch size")
      ->capture_default_str()
      ->check(wholeNumber())
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--weight-decay", opt->training.weightDecay, "L2 weight decay")
      ->capture_default_str()
      ->check(finiteRange(0.0, 1.0));
  cmd->add_option("--momentum", opt->training.momentum, "SGD momentum")
      ->capture_default_str()
      ->check(finiteRange(0.0, 0.999));
  cmd->add_option("--validation", opt->training.validationFraction, "Fraction of rows held out")
      ->capture_default_str()
      ->check(finiteRange(0.0, 0.9));
  cmd->add_option("--seed", opt->training.seed, "Random seed (split, batches)")
      ->capture_default_str()
      ->check(wholeNumber());
  cmd->add_option("--weighting", opt->training.weighting,
                  "none, or fragments: rows drawn with probability proportional to n(p), losses weighted by n(p)")
      ->capture_default_str();
  cmd->callback([opt] {
    std::vector<CommandFile> files;
    refuseRepeatedFiles(opt->datasets, "datasets");  // every row twice: validation rows were training rows too
    for (const std::string& path : opt->datasets) files.push_back({"dataset", path});
    files.push_back({"-o", opt->output, CommandFile::Role::kRequiredOutput});
    checkCommandFiles(files);
    DkbDataset all;
    std::string meta = "[";
    for (const std::string& path : opt->datasets) {
      DkbDataset d = readDataset(path);
      all.rows.insert(all.rows.end(), d.rows.begin(), d.rows.end());
      meta += (meta.size() > 1 ? "," : "") + (d.metadata.empty() ? std::string("{}") : d.metadata);
    }
    all.metadata = meta + "]";
    if (all.size() < 2) {
      std::string names;
      for (const std::string& path : opt->datasets) names += (names.empty() ? "" : ", ") + path;
      throw Error(names, (opt->datasets.size() == 1 ? "holds " : "hold ") + std::to_string(all.size()) +
                             (all.size() == 1 ? " row" : " rows") + "; training needs at least 2");
    }
    NeuralTrainingOptions training = opt->training;
    training.progress = [](std::size_t epoch, double train, double valid) {
      std::cout << "epoch " << std::setw(4) << epoch << "  train MSE " << std::scientific << std::setprecision(4)
                << train << "  validation MSE " << valid << std::defaultfloat << std::endl;
    };
    const NeuralTrainingResult r = trainNeuralImportance(all, training);
    writeFileAtomically(opt->output, neuralImportanceJson(r.model));
    // Too few rows leave none for validation: the best epoch is then chosen on the training rows.
    std::cout << opt->output << ": best epoch " << r.bestEpoch
              << (r.validationRows > 0 ? ", validation MSE " : ", training MSE ") << r.validationLoss << " ("
              << r.trainingRows << " training rows, "
              << (r.validationRows > 0 ? std::to_string(r.validationRows) : std::string("no")) << " validation rows)\n";
  });
}

}  // namespace mfr::cli
