// mfr evaluate: the budget methods side by side against the exact image — for each scene, view
// and memory budget: fkb, vkb, dkb (GPU) and optimal-k (CPU reference): k range, fragments
// captured (count and % of all, the deep hybrid OIT paper's Table 2), RMSE and mean FLIP against
// the exact "over" image (of the same rasterisation for the GPU methods, the oracle's for
// optimal-k), and per-pass time (median of --repeat frames).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/budget/memory_model.hpp"
#include "mfr/error.hpp"
#include "mfr/gl/context.hpp"
#include "mfr/gpu_renderer.hpp"
#include "mfr/io/load.hpp"
#include "mfr/io_util.hpp"
#include "mfr/reference/composite.hpp"
#include "mfr/reference/hybrid.hpp"
#include "mfr/reference/metrics.hpp"
#include "mfr/reference/oracle.hpp"
#include "mfr/render.hpp"

namespace mfr::cli {

namespace {

struct Budget {
  std::string label;
  double mib = 0.0;
  double fragmentPercent = 0.0;  // fN budgets
  bool ofExactSlots = false;     // eN budgets: the percentage is of Σ max(1, n − 1)
};

// "3.5" MiB; "kN": the bytes of a uniform-k k+-buffer with the tail (fkb's layout) at k = N;
// "fN": the bytes with which the variable-k layout holds N % of the frame's fragments; "eN": N % of
// Σ max(1, n − 1), the slots after which hybrid transparency is exact everywhere (both resolved
// per frame, mib stays 0 here).
Budget parseBudget(const std::string& item, std::uint64_t pixels) {
  Budget b;
  b.label = item;
  if (!item.empty() && (item[0] == 'f' || item[0] == 'e')) {
    const std::optional<double> percent = parseNumber(item.substr(1));
    if (!percent || !(*percent > 0.0) || *percent > 100.0)
      throw Error("--budgets " + item, item[0] == 'f'
                                           ? "expected fN with 0 < N <= 100 (% of the frame's fragments)"
                                           : "expected eN with 0 < N <= 100 (% of the frame's Σ max(1, n − 1))");
    b.fragmentPercent = *percent;
    b.ofExactSlots = item[0] == 'e';
    return b;
  }
  if (!item.empty() && item[0] == 'k') {
    const std::optional<double> k = parseNumber(item.substr(1));
    if (!k || !(*k >= 1.0) || *k > 256.0)
      throw Error("--budgets " + item, "expected kN with 1 <= N <= 256 (N may be fractional)");
    // bytes(k) = P·(8k + y) + z of fkb's layout, also for fractional k (between two uniform k).
    const KBufferMemoryModel m = kplusArrayMemoryModel(pixels);
    b.mib = (static_cast<double>(m.pixels) * (8.0 * *k + static_cast<double>(m.bytesPerPixel)) +
             static_cast<double>(m.fixedBytes)) /
            (1024.0 * 1024.0);
    return b;
  }
  const std::optional<double> mib = parseNumber(item);
  if (!mib || *mib <= 0.0) throw Error("--budgets " + item, "expected MiB (a positive number) or kN");
  b.mib = *mib;
  return b;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

}  // namespace

void addEvaluate(CLI::App& app) {
  struct Options {
    std::vector<std::string> scenes;
    std::string views = "iso", budgets = "f30,f50,f70", size = "200x150", methods = "fkb,vkb,dkb,optimal-k", weights,
                json;
    int repeat = 3;
    double opacity = -1.0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Compare fkb, vkb, dkb and optimal-k under memory budgets: k range, fragments captured, RMSE, FLIP, time");
  cmd->add_option("scenes", opt->scenes, "Scenes (model files, .mfrscene, @sample)")->required();
  cmd->add_option("--budgets", opt->budgets,
                  "Comma-separated budgets: MiB; kN = the memory of a uniform k = N k+-buffer with the tail; fN = the "
                  "memory with which the variable-k layout holds N % of each frame's fragments; eN = N % of its "
                  "sum of max(1, n - 1), the slots with which hybrid is exact")
      ->capture_default_str();
  cmd->add_option("--views", opt->views, "Comma-separated views")->capture_default_str();
  cmd->add_option("--size,-s", opt->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--methods,-m", opt->methods,
                  "Methods to compare, each name or name:key=value:… (e.g. vkb:exact_tail=false)")
      ->capture_default_str();
  cmd->add_option("--weights", opt->weights, "dkb weights file (default: the built-in weights)");
  cmd->add_option("--repeat,-r", opt->repeat, "Timed frames per GPU method")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  cmd->add_option("--opacity", opt->opacity, "Override every object's opacity (0..1)")->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--json", opt->json, "Write all results as JSON");
  cmd->callback([opt] {
    const auto [w, h] = parseSize("--size", opt->size);
    const std::uint64_t pixels = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
    std::vector<Budget> budgets;
    for (const std::string& b : splitList(opt->budgets)) budgets.push_back(parseBudget(b, pixels));
    if (budgets.empty()) throw Error("--budgets", "no budget given");
    const std::vector<std::string> methods = splitList(opt->methods);
    const std::vector<std::string> known = availableMethods();
    std::map<std::string, RenderRequest> specs;  // each method spec's request, without size and budget
    std::size_t methodWidth = 11;
    for (const std::string& m : methods) {
      const RenderRequest spec = parseMethodSpec(m, w, h);
      if (std::find(known.begin(), known.end(), spec.method) == known.end() || spec.method == "oracle")
        throw Error("--methods " + m, "not a method (see mfr info --methods)");
      specs[m] = spec;
      methodWidth = std::max(methodWidth, m.size() + 2);
    }
    const std::vector<std::string> views = splitList(opt->views);
    const std::vector<Scene> scenes = loadScenesWithViews(opt->scenes, opt->opacity, views);
    GpuRenderer& gpu = headlessRenderer();
    const gl::ContextInfo info = gl::queryContextInfo();
    nlohmann::ordered_json out;
    out["renderer"] = info.renderer;
    out["size"] = opt->size;
    out["repeat"] = opt->repeat;
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    std::cout << "renderer: " << info.renderer << ", " << opt->size << ", median of " << opt->repeat << " frames\n";
    std::cout << std::left << std::setw(22) << "scene" << std::setw(12) << "view" << std::setw(14) << "budget"
              << std::setw(static_cast<int>(methodWidth)) << "method" << std::right << std::setw(9) << "k range"
              << std::setw(10) << "captured" << std::setw(8) << "%" << std::setw(9) << "RMSE" << std::setw(9) << "FLIP"
              << std::setw(10) << "ms\n";
    // Wins per (scene, view, budget): the method with the lowest FLIP and the lowest RMSE, compared
    // at the 5 decimals printed; equal lowest values count as a tie of those methods.
    std::map<std::string, int> flipWins, rmseWins;
    auto countWin = [](std::map<std::string, int>& wins, const std::vector<std::pair<std::string, double>>& values) {
      if (values.empty()) return;
      auto printed = [](double v) { return std::llround(v * 1e5); };
      long long best = printed(values.front().second);
      for (const auto& [m, v] : values) best = std::min(best, printed(v));
      std::string key;
      int count = 0;
      for (const auto& [m, v] : values)
        if (printed(v) == best) {
          key += (count++ ? "=" : "") + m;
        }
      ++wins[count > 1 ? "tie " + key : key];
    };
    for (std::size_t s = 0; s < scenes.size(); ++s) {
      gpu.setScene(scenes[s]);
      for (const std::string& v : views) {
        const Camera camera = scenes[s].view(v);
        const FragmentLists lists = castFragments(scenes[s], camera, w, h);
        const ImageRGBA8 exact = compositeOver(lists, scenes[s].background);
        // The GPU methods are measured against the exact image of the same rasterisation — every
        // fragment, composited with "over" (the linked-list A-buffer, exact on every
        // non-ambiguous pixel: tests/gl/test_exact_methods.cpp) — so that the ray caster's and the
        // rasteriser's different verdicts on edge pixels do not add one error floor to all of them;
        // optimal-k, which works on the oracle's lists, against the oracle's exact image.
        RenderRequest exactRequest;
        exactRequest.method = "abuffer-ll";
        exactRequest.width = w;
        exactRequest.height = h;
        const ImageRGBA8 gpuExact = gpu.render(camera, exactRequest).image;
        const std::uint64_t total = lists.fragments.size();
        const std::uint64_t exactSlots = exactHybridSlots(lists);
        for (Budget b : budgets) {
          if (b.fragmentPercent > 0.0) {
            const double of = static_cast<double>(b.ofExactSlots ? exactSlots : total);
            const auto slots = static_cast<std::uint64_t>(std::ceil(b.fragmentPercent / 100.0 * of));
            b.mib = static_cast<double>(variableKLayout(pixels).bytes(slots)) / (1024.0 * 1024.0);
          }
          std::vector<std::pair<std::string, double>> flips, rmses;
          for (const std::string& m : methods) {
            RenderRequest req = specs.at(m);
            if (req.operation == "auto") req.operation = "hybrid";
            req.params["budget_mib"] = fixed(b.mib, 6);
            if (req.method == "dkb" && !opt->weights.empty()) req.params["weights"] = opt->weights;
            const bool cpu = req.method == "optimal-k";
            nlohmann::ordered_json row;
            row["scene"] = opt->scenes[s];
            row["view"] = v;
            row["budget"] = b.label;
            row["budget_mib"] = b.mib;
            row["exact_slots"] = exactSlots;
            row["method"] = m;
            RenderOutput r;
            std::vector<double> times;
            std::map<std::string, std::vector<double>> passes;
            try {
              if (cpu) {
                r = render(scenes[s], camera, req);
              } else {
                for (int i = 0; i < opt->repeat; ++i) {
                  r = gpu.render(camera, req);
                  times.push_back(r.stats.totalTimeMs());
                  for (const auto& [pass, ms] : r.stats.passTimesMs) passes[pass].push_back(ms);
                }
              }
            } catch (const Error& e) {
              row["error"] = e.what();
              rows.push_back(row);
              std::cout << std::left << std::setw(22) << scenes[s].name.substr(0, 21) << std::setw(12)
                        << v.substr(0, 11) << std::setw(14) << b.label << std::setw(static_cast<int>(methodWidth)) << m
                        << "  " << e.what() << "\n";
              continue;
            }
            const ImageRGBA8& reference = cpu ? exact : gpuExact;
            const double e = rmse(reference, r.image);
            const double f = flip(reference, r.image).stats.mean;
            const double captured =
                total ? 100.0 * static_cast<double>(r.stats.fragmentsStored) / static_cast<double>(total) : 0.0;
            row["k_min"] = r.stats.kMin;
            row["k_max"] = r.stats.kMax;
            row["fragments_captured"] = r.stats.fragmentsStored;
            row["fragments_total"] = total;
            row["captured_percent"] = captured;
            row["bytes_allocated"] = r.stats.bytesAllocated;
            row["reference"] = cpu ? "oracle (exact lists, over)" : "abuffer-ll (every rasterised fragment, over)";
            row["rmse"] = e;
            row["flip_mean"] = f;
            row["rmse_vs_oracle"] = rmse(exact, r.image);
            row["median_total_ms"] = median(times);
            nlohmann::ordered_json p = nlohmann::ordered_json::object();
            for (const auto& [pass, ms] : passes) p[pass] = median(ms);
            row["median_pass_ms"] = p;
            rows.push_back(row);
            std::cout << std::left << std::setw(22) << scenes[s].name.substr(0, 21) << std::setw(12) << v.substr(0, 11)
                      << std::setw(14) << (b.label + " " + fixed(b.mib, 2)) << std::setw(static_cast<int>(methodWidth))
                      << m << std::right << std::setw(9)
                      << (std::to_string(r.stats.kMin) + "-" + std::to_string(r.stats.kMax)) << std::setw(10)
                      << r.stats.fragmentsStored << std::setw(8) << fixed(captured, 1) << std::setw(9) << fixed(e, 5)
                      << std::setw(9) << fixed(f, 5) << std::setw(10)
                      << (times.empty() ? std::string("cpu") : fixed(median(times), 1)) << "\n";
            if (cpu) continue;  // the bound, not a competitor: wins count among the others
            flips.emplace_back(m, f);
            rmses.emplace_back(m, e);
          }
          countWin(flipWins, flips);
          countWin(rmseWins, rmses);
        }
      }
    }
    auto printWins = [](const char* metric, const std::map<std::string, int>& wins) {
      std::cout << "lowest " << metric << " per scene, view and budget:";
      const char* separator = " ";
      for (const auto& [m, n] : wins) {
        std::cout << separator << m << " " << n;
        separator = ", ";
      }
      std::cout << "\n";
    };
    printWins("FLIP", flipWins);
    printWins("RMSE", rmseWins);
    out["results"] = rows;
    if (!opt->json.empty()) writeFileAtomically(opt->json, out.dump(2) + "\n");
  });
}

}  // namespace mfr::cli
