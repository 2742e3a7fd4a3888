#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mfr/json_text.hpp"
#include "mfr/error.hpp"
#include "mfr/image.hpp"
#include "mfr/io_util.hpp"
#include "mfr/reference/metrics.hpp"

namespace mfr::cli {

void addCompare(CLI::App& app) {
  struct Options {
    std::string reference, test, metrics = "rmse,flip", heatmap, json;
    double ppd = 67.0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("compare", "Compare a test image against a reference (RMSE, FLIP)");
  cmd->add_option("reference", opt->reference, "Reference PNG")->required();
  cmd->add_option("test", opt->test, "Test PNG")->required();
  cmd->add_option("--metric", opt->metrics, "Comma-separated: rmse, flip")->capture_default_str();
  cmd->add_option("--ppd", opt->ppd, "FLIP pixels per degree")->capture_default_str();
  cmd->add_option("--heatmap", opt->heatmap, "Write the error map (FLIP magma, else |difference|) as PNG");
  cmd->add_option("--json", opt->json, "Write the metrics as JSON");
  cmd->callback([opt] {
    bool wantRmse = false, wantFlip = false;
    for (const std::string& m : splitList(opt->metrics, "--metric")) {
      if (m == "rmse")
        wantRmse = true;
      else if (m == "flip")
        wantFlip = true;
      else
        throw Error("--metric " + m, "unknown metric (rmse, flip)");
    }
    if (!wantRmse && !wantFlip) throw Error("--metric " + opt->metrics, "names no metric (rmse, flip)");
    // Below 0.01 FLIP's filters are degenerate: at 1e-30 every value came out NaN.
    if (!(opt->ppd >= 0.01) || opt->ppd > 1e4) throw Error("--ppd", "must be in [0.01, 10000]");
    // Both outputs checked before the work and before either is written; neither may be an input.
    checkCommandFiles({{"reference", opt->reference},
                       {"test", opt->test},
                       {"--heatmap", opt->heatmap, CommandFile::Role::kOutput},
                       {"--json", opt->json, CommandFile::Role::kOutput}});
    if (!opt->heatmap.empty()) checkPngOutputName("--heatmap", opt->heatmap);
    const ImageRGBA8 ref = readPng(opt->reference);
    const ImageRGBA8 test = readPng(opt->test);
    if (ref.width != test.width || ref.height != test.height)
      throw Error(opt->test, "size " + std::to_string(test.width) + "x" + std::to_string(test.height) +
                                 " differs from reference " + std::to_string(ref.width) + "x" +
                                 std::to_string(ref.height));
    // Every number is computed before any is printed: a FLIP refused (memory) printed the rmse line
    // first, as if the command had half worked (a bug hunt).
    nlohmann::ordered_json j;
    std::ostringstream text;
    text << std::setprecision(6) << std::fixed;
    ImageRGBA8 heat;
    if (wantRmse) {
      const double v = rmse(ref, test);
      j["rmse"] = v;
      text << "rmse " << v << "\n";
    }
    if (wantFlip) {
      const FlipResult f = flip(ref, test, opt->ppd);
      j["flip"] = {{"mean", f.stats.mean}, {"p25", f.stats.p25}, {"median", f.stats.p50},
                   {"p75", f.stats.p75},   {"min", f.stats.min}, {"max", f.stats.max}};
      text << "flip mean " << f.stats.mean << " median " << f.stats.p50 << " max " << f.stats.max << "\n";
      if (!opt->heatmap.empty()) heat = magma(f.errorMap);
    }
    if (!opt->heatmap.empty() && heat.empty()) heat = heatmap(absoluteDifference(ref, test), 1.0f);
    std::vector<std::pair<std::filesystem::path, std::string>> outputs;
    if (!opt->heatmap.empty()) outputs.emplace_back(opt->heatmap, encodePng(opt->heatmap, heat));
    if (!opt->json.empty()) outputs.emplace_back(opt->json, jsonText(j, 2) + "\n");
    writeFilesAtomically(outputs);
    std::cout << text.str();
  });
}

}  // namespace mfr::cli
