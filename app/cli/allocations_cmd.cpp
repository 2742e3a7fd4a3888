// mfr allocations: per-pixel k allocations compared on the CPU, on the oracle's exact lists, at
// one slot budget F per case — where the headroom between the budget methods is and why. For each
// scene, view and budget: dkb's network (on the CPU, the same features, weights and rule as on
// the GPU), a flat importance under the same rule (water-filling), the optimum for each
// depth-complexity class's mean error curve (class-optimal: the best any allocation that tells
// pixels apart only by n(p) can expect), the same with each class split by whether the two
// farthest fragments share a colour (class-optimal+tail: what one more bit per pixel is worth),
// dkb and flat under the tail-run bound max(1, n − m) for a final run of m fragments of one RGBA
// (dkb+runs, flat+runs: what vkb and dkb do on the GPU with tail_runs, the default), and optimal-k. Printed: Σk, the
// deep hybrid OIT paper's eq. 2 error Σ_p e_p(k(p)), RMSE and mean FLIP against the oracle's exact image; then how well
// dkb picks the lists to cut: of the pixels it gives fewer than max(1, n − 1) slots, the share that
// optimal-k cuts too, against optimal-k's share among all (equal shares = chance).
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/json_text.hpp"
#include "mfr/budget/k_allocation.hpp"
#include "mfr/budget/memory_model.hpp"
#include "mfr/budget/neural_importance.hpp"
#include "mfr/budget/optimal_k.hpp"
#include "mfr/error.hpp"
#include "mfr/io_util.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/reference/oracle.hpp"

namespace mfr::cli {

void addAllocations(CLI::App& app) {
  struct Options {
    std::vector<std::string> scenes;
    std::string views = "iso", budgets = "k1,e50,e80", size = "200x150", weights, json;
    double opacity = -1.0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "allocations",
      "Compare k(p) allocations on the CPU at one budget: dkb, flat, class-optimal, optimal-k (eq. 2 error, RMSE, "
      "FLIP)");
  cmd->add_option("scenes", opt->scenes, "Scenes (model files, .mfrscene, @sample)")->required();
  cmd->add_option("--budgets", opt->budgets, "Comma-separated budgets, as for mfr evaluate (MiB, kN, fN, eN, xN)")
      ->capture_default_str();
  cmd->add_option("--views", opt->views, "Comma-separated views")->capture_default_str();
  cmd->add_option("--size,-s", opt->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--weights", opt->weights, "dkb weights file (default: the built-in weights)");
  cmd->add_option("--opacity", opt->opacity, "Override every object's opacity (0..1)")->check(finiteRange(0.0, 1.0));
  cmd->add_option("--json", opt->json, "Write all results as JSON");
  cmd->callback([opt] {
    std::vector<CommandFile> files;
    for (const std::string& path : opt->scenes) files.push_back({"scene", path, CommandFile::Role::kScene});
    files.push_back({"--weights", opt->weights});
    files.push_back({"--json", opt->json, CommandFile::Role::kOutput});
    checkCommandFiles(files);
    const auto [w, h] = parseSize("--size", opt->size);
    const std::uint64_t pixels = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
    refuseRepeatedFiles(opt->scenes, "scenes");
    const std::vector<BudgetSpec> budgets = parseBudgetSpecs(opt->budgets, pixels);
    const NeuralImportanceModel model = loadNeuralImportance(opt->weights).quantised();  // as on the GPU
    const std::vector<std::string> views = splitList(opt->views, "--views");
    refuseRepeats(views, "--views " + opt->views);
    const std::vector<Scene> scenes = loadScenesWithViews(opt->scenes, opt->opacity, views, {{w, h}});
    // Every allocation gets dkb's slots (its layout also holds the weights), so all compete at one F.
    const VariableKLayout layout = variableKLayout(pixels, NeuralImportanceModel::packedBytes());
    const std::vector<float> flat(pixels, 1.0f);
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (std::size_t s = 0; s < scenes.size(); ++s)
      for (const std::string& v : views) {
        const FragmentLists lists = castFragments(scenes[s], scenes[s].view(v), w, h);
        // Nothing to share out: the shares below were 0/0 ("-nan %") and every allocation empty,
        // exit 0 (a bug hunt), as mfr dataset refuses it.
        requireSomethingVisible(lists, opt->scenes[s] + " view " + v);
        const ImageRGBA8 exact = compositeOver(lists, scenes[s].background);
        const HybridErrorTable errors = hybridErrorTable(lists, scenes[s].background);
        const std::vector<std::uint32_t> n = lists.counts();
        // m(p): the final run of fragments of one RGBA, whose tail hybrid transparency composites
        // exactly — the shared rule's tail-run bound max(1, n − m) (vkb and dkb on the GPU, with
        // tail_runs). The depth classes split by m ≥ 2 (the two farthest fragments share a colour,
        // so a two-fragment tail is exact, the cheapest cut there is): class-optimal+tail.
        const std::vector<std::uint32_t> runs = tailRunLengths(lists);
        std::vector<std::uint32_t> lastTwoEqual(pixels, 0u);
        for (std::size_t p = 0; p < pixels; ++p) lastTwoEqual[p] = runs[p] >= 2 ? 1u : 0u;
        const HybridErrorTable classes = classMeanErrorTable(errors);
        const HybridErrorTable classesByTail = classMeanErrorTable(errors, lastTwoEqual);
        const DkbImageStats stats = dkbImageStats(lists);
        const std::uint64_t total = lists.fragments.size(), exactSlots = exactHybridSlots(lists);
        const std::uint64_t exactSlotsRuns = exactHybridSlots(lists, runs);
        const std::uint64_t nonEmpty = minimumSlots(errors);
        for (BudgetSpec b : budgets) {
          b.resolve(total, exactSlots, exactSlotsRuns, pixels);
          const std::uint64_t F = std::min<std::uint64_t>(layout.slotBudget(b.byteCount()), total);
          std::cout << scenes[s].name << ", " << v << ", " << b.label << ": F = " << F << " slots (" << std::fixed
                    << std::setprecision(1) << 100.0 * static_cast<double>(F) / static_cast<double>(total)
                    << " % of Σn, " << 100.0 * static_cast<double>(F) / static_cast<double>(exactSlots)
                    << " % of Σ max(1, n − 1), " << 100.0 * static_cast<double>(F) / static_cast<double>(exactSlotsRuns)
                    << " % of Σ max(1, n − m) = " << exactSlotsRuns << ")\n";
          if (F < nonEmpty) {
            std::cout << "  fewer slots than non-empty pixels (" << nonEmpty << "): skipped\n";
            continue;
          }
          std::vector<float> importance(pixels, 0.0f);
          for (std::size_t p = 0; p < pixels; ++p)
            if (n[p] > 0) importance[p] = neuralImportance(model, dkbFeatures(lists.pixel(p), stats, F), n[p]);
          const std::vector<std::uint32_t> kd = allocateKFromImportance(importance, n, F).k;
          const std::vector<std::uint32_t> ko = optimalKBest(errors, F).k;
          const std::vector<std::pair<std::string, std::vector<std::uint32_t>>> allocations = {
              {"dkb", kd},
              {"dkb+runs", allocateKFromImportance(importance, n, F, true, runs).k},
              {"flat", allocateKFromImportance(flat, n, F).k},
              {"flat+runs", allocateKFromImportance(flat, n, F, true, runs).k},
              {"class-optimal", optimalKBest(classes, F).k},
              {"class-optimal+tail", optimalKBest(classesByTail, F).k},
              {"optimal-k", ko}};
          nlohmann::ordered_json row;
          row["scene"] = opt->scenes[s];
          row["view"] = v;
          row["budget"] = b.label;
          row["budget_slots"] = F;
          row["fragments_total"] = total;
          row["exact_slots"] = exactSlots;
          row["exact_slots_tail_runs"] = exactSlotsRuns;
          for (const auto& [name, k] : allocations) {
            std::uint64_t sum = 0;
            for (std::uint32_t x : k) sum += x;
            const ImageRGBA8 image = compositeHybrid(lists, k, scenes[s].background);
            const double e = allocationError(errors, k), r = rmse(exact, image), f = flip(exact, image).stats.mean;
            std::cout << "  " << std::left << std::setw(19) << name << std::right << " slots " << std::setw(9) << sum
                      << "  eq. 2 error " << std::scientific << std::setprecision(4) << e << std::fixed
                      << std::setprecision(5) << "  RMSE " << r << "  FLIP " << f << "\n";
            row[name] = {{"slots", sum}, {"eq2_error", e}, {"rmse", r}, {"flip_mean", f}};
          }
          // Which lists dkb cuts below max(1, n − 1), against optimal-k's (pixels with n ≥ 3: n = 2
          // cannot be cut once every pixel holds one slot).
          std::uint64_t lists3 = 0, dkbCuts = 0, optimalCuts = 0, both = 0;
          for (std::size_t p = 0; p < pixels; ++p) {
            if (n[p] < 3) continue;
            ++lists3;
            const bool d = kd[p] < n[p] - 1, o = ko[p] < n[p] - 1;
            dkbCuts += d;
            optimalCuts += o;
            both += d && o;
          }
          auto share = [](std::uint64_t part, std::uint64_t of) {
            return of ? 100.0 * static_cast<double>(part) / static_cast<double>(of) : 0.0;
          };
          std::cout << std::setprecision(1) << "  lists with n >= 3: " << lists3 << "; optimal-k cuts " << optimalCuts
                    << " (" << share(optimalCuts, lists3) << " %) below max(1, n − 1), dkb " << dkbCuts
                    << ", of which optimal-k cuts too " << both << " (" << share(both, dkbCuts) << " %)\n";
          row["cuts"] = {{"lists", lists3}, {"optimal_k", optimalCuts}, {"dkb", dkbCuts}, {"dkb_and_optimal_k", both}};
          rows.push_back(row);
        }
      }
    if (!opt->json.empty())
      writeFileAtomically(opt->json, jsonText(nlohmann::ordered_json{{"results", rows}}, 2) + "\n");
  });
}

}  // namespace mfr::cli
