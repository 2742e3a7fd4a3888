#pragma once
// Comma-separated numbers as the command lines give them (--clip, --section, budgets, sizes):
// shared by mfr's options and mfrcore's parsers, so both read the same text the same way.
#include <cmath>
#include <cstddef>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mfr::text {

// The items of `text` between separators, empty ones included ("a,,b" has three, "a," two), so
// that a parser can refuse a doubled or stray separator instead of reading past it; "" has none.
inline std::vector<std::string> splitList(const std::string& text, char separator = ',') {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, separator)) out.push_back(item);
  if (!text.empty() && text.back() == separator) out.emplace_back();
  return out;
}

// The whole of `text` (after leading blanks) as one finite decimal number, or none (std::stod
// alone would also take hexadecimal, "0x10").
inline std::optional<double> parseNumber(const std::string& text) {
  if (text.find_first_not_of("0123456789+-.eE \t\n\r\v\f") != std::string::npos) return std::nullopt;
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

// Six numbers a,b,c,d,e,f as two vectors (a,b,c) and (d,e,f), or none.
template <class Vec3>
std::optional<std::pair<Vec3, Vec3>> parseTwoVectors(const std::string& text) {
  const std::vector<std::string> items = splitList(text);
  if (items.size() != 6) return std::nullopt;
  std::pair<Vec3, Vec3> out;
  for (std::size_t i = 0; i < 6; ++i) {
    const std::optional<double> v = parseNumber(items[i]);
    if (!v) return std::nullopt;
    (i < 3 ? out.first : out.second)[static_cast<int>(i % 3)] = *v;
  }
  return out;
}

}  // namespace mfr::text
