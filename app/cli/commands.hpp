#pragma once
// Subcommands of mfr; each adds itself to the app and runs from its callback.
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "mfr/render.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::cli {

void addRender(CLI::App& app);
void addCompare(CLI::App& app);
void addInfo(CLI::App& app);
void addBench(CLI::App& app);
void addDataset(CLI::App& app);
void addTrain(CLI::App& app);
void addEvaluate(CLI::App& app);

// "WxH" → (w, h); throws mfr::Error naming the option.
std::pair<int, int> parseSize(const std::string& option, const std::string& text);
// Comma-separated list.
std::vector<std::string> splitList(const std::string& text);
// loadScene, then every object's opacity set to `opacity` unless it is negative (--opacity).
Scene loadSceneWithOpacity(const std::string& path, double opacity);
// Every scene loaded (with --opacity) and every view checked before any work, so that a bad file
// or view fails at once; throws mfr::Error for an empty view list.
std::vector<Scene> loadScenesWithViews(const std::vector<std::string>& paths, double opacity,
                                       const std::vector<std::string>& views);
// The whole text as a finite number, or nothing ("1.5" yes; "1.5x", "", "nan", "inf" no).
std::optional<double> parseNumber(const std::string& text);
// "name" or "name:key=value:key=value" → request of w×h (a method run with several settings);
// op=… sets the operation (default "auto"). Throws mfr::Error naming --methods.
RenderRequest parseMethodSpec(const std::string& spec, int w, int h);
// Median of the values (0 for none).
double median(std::vector<double> values);

}  // namespace mfr::cli
