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
#include <span>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/json_text.hpp"
#include "mfr/budget/neural_importance.hpp"
#include "mfr/budget/memory_model.hpp"
#include "mfr/error.hpp"
#include "mfr/operation_settings.hpp"
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

// Mean k(p) of the pixels whose depth complexity n(p) lies in [lo, hi): where a method puts its
// slots (--k-by-depth). Buckets grow by about ×1.5 so that deep pixels are not averaged away.
struct DepthBucket {
  std::uint32_t lo = 0, hi = 0;  // hi = 0: no upper end
  std::uint64_t pixels = 0;
  double sumN = 0.0, sumK = 0.0;
};

std::vector<DepthBucket> kByDepth(std::span<const std::uint32_t> n, std::span<const std::uint32_t> k) {
  static constexpr std::uint32_t kEdges[] = {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256};
  std::vector<DepthBucket> buckets;
  for (std::size_t i = 0; i < std::size(kEdges); ++i)
    buckets.push_back({kEdges[i], i + 1 < std::size(kEdges) ? kEdges[i + 1] : 0u});
  if (n.size() != k.size()) throw Error("--k-by-depth", "the k map and the depth complexity differ in size");
  for (std::size_t p = 0; p < n.size(); ++p) {
    if (n[p] == 0) continue;
    const auto b = std::upper_bound(std::begin(kEdges), std::end(kEdges), n[p]) - std::begin(kEdges) - 1;
    DepthBucket& bucket = buckets[static_cast<std::size_t>(b)];
    bucket.pixels += 1;
    bucket.sumN += n[p];
    bucket.sumK += k[p];
  }
  return buckets;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

// The non-empty classes of one method as JSON rows (k_by_depth).
nlohmann::ordered_json depthTableJson(const std::vector<DepthBucket>& buckets) {
  nlohmann::ordered_json t = nlohmann::ordered_json::array();
  for (const DepthBucket& d : buckets) {
    if (d.pixels == 0) continue;
    nlohmann::ordered_json entry;
    entry["n_min"] = d.lo;
    entry["n_below"] = d.hi ? nlohmann::ordered_json(d.hi) : nlohmann::ordered_json();
    entry["pixels"] = d.pixels;
    entry["mean_n"] = d.sumN / static_cast<double>(d.pixels);
    entry["mean_k"] = d.sumK / static_cast<double>(d.pixels);
    t.push_back(entry);
  }
  return t;
}

// One line per class that any method has pixels in: each method's mean k and pixel count.
void printDepthTables(const std::vector<std::pair<std::string, std::vector<DepthBucket>>>& tables) {
  std::cout << "  mean k by depth complexity n (pixels with that n in each method's own lists):\n";
  for (std::size_t i = 0; i < tables.front().second.size(); ++i) {
    const bool any = std::any_of(tables.begin(), tables.end(), [i](const auto& t) { return t.second[i].pixels > 0; });
    if (!any) continue;
    const DepthBucket& ref = tables.front().second[i];
    std::cout << "    n " << std::left << std::setw(10)
              << ("[" + std::to_string(ref.lo) + ", " + (ref.hi ? std::to_string(ref.hi) : "inf") + ")") << std::right;
    for (const auto& [m, t] : tables)
      std::cout << "  " << m << " " << (t[i].pixels ? fixed(t[i].sumK / static_cast<double>(t[i].pixels), 2) : "-")
                << " (" << t[i].pixels << ")";
    std::cout << "\n";
  }
}

}  // namespace

void addEvaluate(CLI::App& app) {
  struct Options {
    std::vector<std::string> scenes;
    std::string views = "iso", budgets = "f30,f50,f70", size = "200x150", methods = "fkb,vkb,dkb,optimal-k", weights,
                json;
    int repeat = 3;
    double opacity = -1.0;
    bool kByDepth = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Compare fkb, vkb, dkb and optimal-k under memory budgets: k range, fragments captured, RMSE, FLIP, time");
  cmd->add_option("scenes", opt->scenes, "Scenes (model files, .mfrscene, @sample)")->required();
  cmd->add_option("--budgets", opt->budgets,
                  "Comma-separated budgets: MiB; kN = the memory of a uniform k = N k+-buffer with the tail; fN = the "
                  "memory with which the variable-k layout holds N % of each frame's fragments; eN = N % of its "
                  "sum of max(1, n - 1), the slots with which hybrid is exact; xN = N % of its sum of max(1, n - m), m "
                  "the final run of fragments of one colour (the exact threshold with tail_runs)")
      ->capture_default_str();
  cmd->add_option("--views", opt->views, "Comma-separated views")->capture_default_str();
  cmd->add_option("--size,-s", opt->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--methods,-m", opt->methods,
                  "Methods to compare, each name or name:key=value:… (e.g. vkb:exact_tail=false)")
      ->capture_default_str();
  cmd->add_option("--weights", opt->weights, "dkb weights file (default: the built-in weights)");
  cmd->add_option("--repeat,-r", opt->repeat, "Timed frames per GPU method")
      ->capture_default_str()
      ->check(wholeNumber())
      ->check(CLI::Range(1, 100));
  cmd->add_option("--opacity", opt->opacity, "Override every object's opacity (0..1)")->check(finiteRange(0.0, 1.0));
  cmd->add_option("--json", opt->json, "Write all results as JSON");
  cmd->add_flag("--k-by-depth", opt->kByDepth,
                "Also print (and write to the JSON) each method's mean k per depth-complexity class n(p)");
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
    const std::vector<std::string> methods = splitList(opt->methods, "--methods");
    if (methods.empty()) throw Error("--methods", "names no method");
    refuseRepeats(methods, "--methods " + opt->methods);  // "vkb,vkb" printed a row twice and "tie vkb=vkb"
    std::map<std::string, RenderRequest> specs;           // each method spec's request, without size and budget
    std::vector<std::string> interlockRows;               // specs asking for sync=interlock: checked on the context
    std::size_t methodWidth = 11;
    // A weights file that cannot be read is the user's mistake, not one row's failure: refused
    // before anything runs (it was only a row's error, and exit 0).
    if (!opt->weights.empty()) (void)loadNeuralImportance(opt->weights);
    for (const std::string& m : methods) {
      const RenderRequest spec = parseMethodSpec(m, w, h);
      // The registry's methods and optimal-k have a description; the oracle (no budget) has none.
      const MethodInfo* methodInfo = findMethodInfo(spec.method);
      if (!methodInfo) throw Error("--methods " + m, "not a method (see mfr info --methods)");
      if (const auto weights = spec.params.find("weights"); weights != spec.params.end()) {
        std::vector<CommandFile> read{{"--methods " + m, weights->second}};
        read.push_back({"--json", opt->json, CommandFile::Role::kOutput});
        checkCommandFiles(read);  // the JSON must not replace the weights it reads
        (void)loadNeuralImportance(weights->second);
      }
      // The rest of the spec too, before anything renders: a bad parameter or operation is the
      // user's mistake, which every row would only repeat (with exit 0).
      const auto has = [&](const char* name) {
        return std::any_of(methodInfo->params.begin(), methodInfo->params.end(),
                           [&](const ParamSpec& p) { return p.name == name; });
      };
      if (!has("budget_mib"))
        throw Error("--methods " + m, "has no memory budget (budget_mib): evaluate compares methods under --budgets");
      if (spec.params.contains("budget_mib"))
        throw Error("--methods " + m, "budget_mib is set by --budgets, not in the method spec");
      std::map<std::string, std::string> values = spec.params;
      values["budget_mib"] = "1";
      const Params params(methodInfo->params, values, spec.method);
      if (spec.operation != "auto") validateOperation(spec.operation);
      // Hybrid (auto here) composites the k-buffer's tail; without one every row was the renderer's
      // "--op hybrid: needs --param tail=true", naming options the user never gave (a bug hunt).
      if ((spec.operation == "auto" || spec.operation == "hybrid") && has("tail") && !params.flag("tail"))
        throw Error("--methods " + m, spec.params.contains("tail")
                                          ? "operation hybrid (evaluate's default) composites the tail this spec turns "
                                            "off (drop tail=false, or add op=oit)"
                                          : "operation hybrid (evaluate's default) composites a tail, which " +
                                                spec.method + " keeps only with tail=true (add it, or op=oit)");
      if (has("sync") && params.text("sync") == "interlock") interlockRows.push_back(m);
      // Every row is measured against the exact "over" image: an operation that draws another
      // image (a volume, a CSG result, merged z-thickness slabs) would only be a row of errors
      // or of meaningless numbers for every scene, view and budget.
      if (spec.operation != "auto" && spec.operation != "hybrid" && spec.operation != "oit")
        throw Error("--methods " + m, "evaluate measures against the exact 'over' image; operation " + spec.operation +
                                          " draws another image (use hybrid, the default, or oit)");
      // optimal-k's rows were each the renderer's "--op oit: …", exit 0 (a bug hunt).
      if (spec.method == "optimal-k" && spec.operation == "oit")
        throw Error("--methods " + m, "optimal-k is a hybrid-transparency reference: drop op=oit (it runs hybrid)");
      // Nor do hybrid and oit use a thickness, a step or shading, which would change nothing.
      RenderRequest asRun = spec;  // auto is hybrid here, whatever the method's own (see below)
      if (asRun.operation == "auto") asRun.operation = "hybrid";
      if (const auto unused = unusedOperationSetting(asRun, false))
        throw Error("--methods " + m, unused->name + ": " + unused->reason);
      specs[m] = spec;
      methodWidth = std::max(methodWidth, m.size() + 2);
    }
    const std::vector<std::string> views = splitList(opt->views, "--views");
    refuseRepeats(views, "--views " + opt->views);
    const std::vector<Scene> scenes = loadScenesWithViews(opt->scenes, opt->opacity, views, {{w, h}});
    GpuRenderer& gpu = headlessRenderer();
    const gl::ContextInfo info = gl::queryContextInfo();
    for (const std::string& m : interlockRows)  // each row was this error, with exit 0
      if (!info.fragmentShaderInterlock)
        throw Error("--methods " + m, "sync=interlock: this OpenGL driver (" + info.renderer +
                                          ") has no fragment shader interlock (use sync=spinlock, the default)");
    // The budget column holds "label MiB" (up to 65536.00): a long label ran into the method column.
    int budgetWidth = 14;
    for (const BudgetSpec& b : budgets) budgetWidth = std::max(budgetWidth, static_cast<int>(b.label.size()) + 11);
    nlohmann::ordered_json out;
    out["renderer"] = info.renderer;
    out["size"] = opt->size;
    out["repeat"] = opt->repeat;
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    std::cout << "renderer: " << info.renderer << ", " << opt->size << ", median of " << opt->repeat << " frames\n";
    std::cout << std::left << std::setw(22) << "scene" << std::setw(12) << "view" << std::setw(budgetWidth) << "budget"
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
        // A view that sees nothing has no budget to share: every row was "below what k = 1 needs",
        // exit 0 (a bug hunt), as mfr dataset refuses it.
        requireSomethingVisible(lists, opt->scenes[s] + " view " + v);
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
        ImageRGBA8 gpuExact;
        std::uint64_t referenceOverflowPixels = 0;
        try {
          RenderOutput reference = gpu.render(camera, exactRequest);
          gpuExact = std::move(reference.image);
          referenceOverflowPixels = reference.stats.overflow ? reference.stats.overflowPixels : 0;
        } catch (const Error& e) {
          // Its refusal (a frame beyond the storage block) named "--method abuffer-ll", which the
          // user never gave: it is evaluate's own reference.
          std::string reason = e.what();
          if (const std::string given = "--method abuffer-ll: "; reason.starts_with(given))
            reason.erase(0, given.size());
          throw Error("scene '" + scenes[s].name + "', view " + v + ": the exact reference (abuffer-ll)", reason);
        }
        const std::uint64_t total = lists.fragments.size();
        // The reference lost fragments (a list longer than abuffer-ll's pool or resolve holds): the
        // rows are measured against an incomplete image, which was not said (a bug hunt).
        if (referenceOverflowPixels > 0)
          std::cerr << "note: " << opt->scenes[s] << " view " << v
                    << ": the exact reference (abuffer-ll) lost fragments on " << referenceOverflowPixels
                    << " pixels; the GPU rows' RMSE and FLIP are against that image\n";
        const std::uint64_t exactSlots = exactHybridSlots(lists),
                            exactSlotsRuns = exactHybridSlots(lists, tailRunLengths(lists));
        // --k-by-depth: n(p) of each method's own lists (the GPU's rasterisation, the oracle's rays).
        std::vector<std::uint32_t> gpuDepth, oracleDepth;
        if (opt->kByDepth) {
          gpuDepth = gpu.depthComplexity(camera, w, h);
          oracleDepth = lists.counts();
        }
        for (BudgetSpec b : budgets) {
          b.resolve(total, exactSlots, exactSlotsRuns, pixels);
          std::vector<std::pair<std::string, double>> flips, rmses;
          std::vector<std::pair<std::string, std::vector<DepthBucket>>> depthTables;
          for (const std::string& m : methods) {
            RenderRequest req = specs.at(m);
            if (req.operation == "auto") req.operation = "hybrid";
            req.params["budget_mib"] = b.paramText();
            // --weights for the dkb rows that name none of their own (dkb:weights=FILE wins).
            if (req.method == "dkb" && !opt->weights.empty() && !req.params.contains("weights"))
              req.params["weights"] = opt->weights;
            const bool cpu = req.method == "optimal-k";
            nlohmann::ordered_json row;
            row["scene"] = opt->scenes[s];
            row["view"] = v;
            row["budget"] = b.label;
            row["budget_mib"] = b.mib;
            row["budget_bytes"] = b.byteCount();
            row["exact_slots"] = exactSlots;
            row["exact_slots_tail_runs"] = exactSlotsRuns;
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
                        << v.substr(0, 11) << std::setw(budgetWidth) << b.label
                        << std::setw(static_cast<int>(methodWidth)) << m << "  " << e.what() << "\n";
              continue;
            }
            const ImageRGBA8& reference = cpu ? exact : gpuExact;
            const double e = rmse(reference, r.image);
            const double f = flip(reference, r.image).stats.mean;
            // A share of the fragments of the method's own rasterisation (a GPU row's count of every
            // fragment; the oracle's for optimal-k): against the oracle's total a GPU row could
            // capture 100.1 % (a bug hunt).
            const std::uint64_t all = cpu ? total : r.stats.fragmentsGenerated;
            const double captured =
                all ? 100.0 * static_cast<double>(r.stats.fragmentsStored) / static_cast<double>(all) : 0.0;
            row["k_min"] = r.stats.kMin;
            row["k_max"] = r.stats.kMax;
            row["fragments_captured"] = r.stats.fragmentsStored;
            row["fragments_total"] = all;
            row["captured_percent"] = captured;
            row["bytes_allocated"] = r.stats.bytesAllocated;
            // Fragments the method lost to a full structure or a cut resolve, as bench and render
            // report them (evaluate's numbers looked as if nothing was lost; a bug hunt).
            row["overflow"] = r.stats.overflow;
            row["overflow_pixels"] = r.stats.overflowPixels;
            row["reference_overflow_pixels"] = cpu ? 0 : referenceOverflowPixels;
            row["reference"] = cpu ? "oracle (exact lists, over)" : "abuffer-ll (every rasterised fragment, over)";
            row["rmse"] = e;
            row["flip_mean"] = f;
            row["rmse_vs_oracle"] = rmse(exact, r.image);
            // optimal-k is not timed: null, not a time of 0 (as bench writes it).
            row["median_total_ms"] = times.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(median(times));
            nlohmann::ordered_json p = nlohmann::ordered_json::object();
            for (const auto& [pass, ms] : passes) p[pass] = median(ms);
            row["median_pass_ms"] = p;
            if (opt->kByDepth) {
              const std::vector<std::uint32_t> k = cpu ? r.kMap : gpu.kMap();
              if (!k.empty()) {
                depthTables.emplace_back(m, kByDepth(cpu ? oracleDepth : gpuDepth, k));
                row["k_by_depth"] = depthTableJson(depthTables.back().second);
              }
            }
            rows.push_back(row);
            std::cout << std::left << std::setw(22) << scenes[s].name.substr(0, 21) << std::setw(12) << v.substr(0, 11)
                      << std::setw(budgetWidth) << (b.label + " " + fixed(b.mib, 2))
                      << std::setw(static_cast<int>(methodWidth)) << m << std::right << std::setw(9)
                      << (std::to_string(r.stats.kMin) + "-" + std::to_string(r.stats.kMax)) << std::setw(10)
                      << r.stats.fragmentsStored << std::setw(8) << fixed(captured, 1) << std::setw(9) << fixed(e, 5)
                      << std::setw(9) << fixed(f, 5) << std::setw(10)
                      << (times.empty() ? std::string("cpu") : fixed(median(times), 1))
                      << (r.stats.overflow ? "  OVERFLOW" : "") << "\n";
            if (cpu) continue;  // the bound, not a competitor: wins count among the others
            flips.emplace_back(m, f);
            rmses.emplace_back(m, e);
          }
          countWin(flipWins, flips);
          countWin(rmseWins, rmses);
          if (!depthTables.empty()) printDepthTables(depthTables);
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
    if (!opt->json.empty()) writeFileAtomically(opt->json, jsonText(out, 2) + "\n");
  });
}

}  // namespace mfr::cli
