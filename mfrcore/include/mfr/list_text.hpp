#pragma once
// Comma-separated numbers as the command lines give them (--clip, --section, budgets, sizes):
// shared by mfr's options and mfrcore's parsers, so both read the same text the same way.
#include <cmath>
#include <cstddef>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace mfr::text {

// The non-empty items of `text` between separators.
inline std::vector<std::string> splitList(const std::string& text, char separator = ',') {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, separator))
    if (!item.empty()) out.push_back(item);
  return out;
}

// The whole of `text` as one finite number, or none.
inline std::optional<double> parseNumber(const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace mfr::text
