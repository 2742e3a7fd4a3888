#pragma once
// Subcommands of mfr; each adds itself to the app and runs from its callback.
#include <CLI/CLI.hpp>

#include <string>

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

}  // namespace mfr::cli
