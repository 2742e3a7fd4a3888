// mfr dataset: training data for dkb — per scene × view × budget, the oracle's exact lists, the
// optimal k(p) under the budget and the 12 features of a random sample of the non-empty pixels
// (format: mfr/budget/dataset.hpp, docs/methods.md).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <random>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/json_text.hpp"
#include "mfr/budget/dataset.hpp"
#include "mfr/error.hpp"
#include "mfr/io/load.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr::cli {

namespace {

// "1.5" → 1.5 slots per non-empty pixel; "all" → every fragment (encoded as −1).
std::vector<double> parseBudgetLevels(const std::string& text) {
  std::vector<double> out;
  for (const std::string& item : splitList(text, "--budgets")) {
    if (item == "all") {
      out.push_back(-1.0);
      continue;
    }
    const std::optional<double> v = parseNumber(item);
    if (!v || *v < 1.0) throw Error("--budgets " + item, "expected slots per non-empty pixel (a number >= 1) or 'all'");
    // "1,1" wrote each frame twice (a repeated 'all' was written once).
    if (std::find(out.begin(), out.end(), *v) != out.end())
      throw Error("--budgets " + text, "'" + item + "' is given twice");
    out.push_back(*v);
  }
  if (out.empty()) throw Error("--budgets", "no budget given");
  return out;
}

}  // namespace

void addDataset(CLI::App& app) {
  struct Options {
    std::vector<std::string> scenes, sizes{"200x150"};
    std::string views = "iso", budgets = "1,1.25,1.5,2,2.5,3,4,6,all", output, sampleBy = "pixels", labels = "optimal";
    double sample = 0.2, opacity = -1.0;
    std::uint64_t seed = 1;
    bool skipExact = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "dataset", "Write dkb training data: features and optimal-k labels of sampled pixels per scene, view and budget");
  cmd->add_option("scenes", opt->scenes, "Training scenes (model files, .mfrscene, @sample)")->required();
  cmd->add_option("-o,--output", opt->output, "Output dataset file")->required();
  cmd->add_option("--views", opt->views, "Comma-separated views (names or orbit:AZ:EL)")->capture_default_str();
  cmd->add_option("--size,-s", opt->sizes, "Image size WxH (repeatable)")->capture_default_str();
  cmd->add_option("--budgets", opt->budgets,
                  "Slot budgets per frame, in slots per non-empty pixel (>= 1) or 'all' (every fragment)")
      ->capture_default_str();
  cmd->add_option("--sample", opt->sample, "Fraction of the non-empty pixels written per frame")
      ->capture_default_str()
      ->check(finiteRange(0.0, 1.0));
  cmd->add_option("--sample-by", opt->sampleBy,
                  "pixels: each non-empty pixel with probability --sample; deep: pixels deeper than the frame's "
                  "mean n(p) more often, in proportion to n(p)")
      ->capture_default_str()
      ->check(CLI::IsMember({"pixels", "deep"}));
  cmd->add_option("--seed", opt->seed, "Random seed of the pixel sampling")
      ->capture_default_str()
      ->check(wholeNumber());
  cmd->add_option("--labels", opt->labels,
                  "optimal: each pixel's k of optimal-k; class-optimal: optimal-k on the curves averaged over the "
                  "pixels of equal n(p), the best a network that cannot see which lists have cheap tails can do")
      ->capture_default_str()
      ->check(CLI::IsMember({"optimal", "class-optimal"}));
  cmd->add_flag("--skip-exact-budgets", opt->skipExact,
                "Leave out a frame's budgets of at least sum max(1, n - 1) slots: there the exact-tail bound makes "
                "every allocation exact, so their labels teach the network nothing");
  cmd->add_option("--opacity", opt->opacity, "Override every object's opacity (0..1)")->check(finiteRange(0.0, 1.0));
  cmd->callback([opt] {
    std::vector<CommandFile> files;
    for (const std::string& path : opt->scenes) files.push_back({"scene", path, CommandFile::Role::kScene});
    files.push_back({"-o", opt->output, CommandFile::Role::kRequiredOutput});
    checkCommandFiles(files);
    const std::vector<double> levels = parseBudgetLevels(opt->budgets);
    refuseRepeatedFiles(opt->scenes, "scenes");
    const std::vector<std::string> views = splitList(opt->views, "--views");
    refuseRepeats(views, "--views " + opt->views);
    refuseRepeats(opt->sizes, "--size");
    std::vector<std::pair<int, int>> sizes;
    for (const std::string& s : opt->sizes) {
      sizes.push_back(parseSize("--size", s));
      // 080x060 and 80x60 wrote each frame twice (a bug hunt).
      if (const auto first = std::find(sizes.begin(), sizes.end() - 1, sizes.back()); first != sizes.end() - 1)
        throw Error("--size", "'" + s + "' is '" + opt->sizes[static_cast<std::size_t>(first - sizes.begin())] +
                                  "' again (one size given twice)");
    }
    if (!(opt->sample > 0.0)) throw Error("--sample", "must be in (0, 1]: 0 writes no rows");
    const std::vector<Scene> scenes = loadScenesWithViews(opt->scenes, opt->opacity, views, sizes);
    const DatasetSampling sampling = opt->sampleBy == "deep" ? DatasetSampling::DeepPixels : DatasetSampling::Pixels;
    DkbDataset dataset;
    std::mt19937_64 rng(opt->seed);
    nlohmann::ordered_json meta;
    meta["scenes"] = opt->scenes;
    meta["views"] = views;
    meta["sizes"] = opt->sizes;
    meta["budgets"] = opt->budgets;
    meta["sample"] = opt->sample;
    meta["sample_by"] = opt->sampleBy;
    meta["seed"] = opt->seed;
    meta["skip_exact_budgets"] = opt->skipExact;
    meta["labels"] = opt->labels;
    nlohmann::ordered_json frames = nlohmann::ordered_json::array();
    std::cout << std::left << std::setw(28) << "scene" << std::setw(16) << "view" << std::setw(9) << "size"
              << std::right << std::setw(10) << "F" << std::setw(10) << "Σn" << std::setw(9) << "rows" << std::setw(12)
              << "error"
              << "  solver\n";
    for (std::size_t s = 0; s < scenes.size(); ++s)
      for (const std::string& v : views)
        for (const auto& [w, h] : sizes) {
          const FragmentLists lists = castFragments(scenes[s], scenes[s].view(v), w, h);
          requireSomethingVisible(lists, opt->scenes[s] + " view " + v);
          HybridErrorTable errors = hybridErrorTable(lists, scenes[s].background);
          if (opt->labels == "class-optimal") errors = classMeanErrorTable(errors);
          const std::uint64_t nonEmpty = minimumSlots(errors);
          bool allDone = false;             // levels at or above Σn all mean "every fragment": one frame of those
          std::set<std::uint64_t> written;  // budgets in slots: 1 and 1.0001 can round to one F
          const std::uint64_t exactSlots = exactHybridSlots(lists);
          for (double level : levels) {
            const std::uint64_t F =
                level < 0 ? lists.fragments.size()
                          : std::min<std::uint64_t>(
                                lists.fragments.size(),
                                static_cast<std::uint64_t>(std::llround(level * static_cast<double>(nonEmpty))));
            if (opt->skipExact && F >= exactSlots) continue;
            if (!written.insert(F).second) continue;
            if (F >= lists.fragments.size()) {
              if (allDone) continue;
              allDone = true;
            }
            const DatasetFrame f = appendDatasetFrame(dataset, lists, errors, F, opt->sample, rng, sampling);
            std::cout << std::left << std::setw(28) << scenes[s].name.substr(0, 27) << std::setw(16) << v.substr(0, 15)
                      << std::setw(9) << (std::to_string(w) + "x" + std::to_string(h)) << std::right << std::setw(10)
                      << F << std::setw(10) << f.totalFragments << std::setw(9) << f.sampled << std::setw(12)
                      << std::setprecision(4) << f.optimalError << "  " << f.solver << "\n";
            frames.push_back({{"scene", opt->scenes[s]},
                              {"view", v},
                              {"width", w},
                              {"height", h},
                              {"budget_slots", F},
                              {"total_fragments", f.totalFragments},
                              {"rows", f.sampled},
                              {"solver", f.solver}});
          }
        }
    // An empty file was written with exit 0 (train then refused it): say why instead.
    if (dataset.size() == 0)
      throw Error(
          "-o " + opt->output,
          std::string("no rows to write: ") +
              (opt->skipExact && frames.empty()
                   ? "--skip-exact-budgets left out every frame's budget (each holds the exact tails)"
                   : "the sample drew no pixel (--sample " + (std::ostringstream() << opt->sample).str() + ")"));
    meta["frames"] = frames;
    dataset.metadata = jsonText(meta);
    writeDataset(opt->output, dataset);
    std::cout << opt->output << ": " << dataset.size() << " rows\n";
  });
}

}  // namespace mfr::cli
