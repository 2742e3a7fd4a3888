#pragma once
// Numbers in notes and messages: the shortest text that reads back as the same double
// (std::to_string printed a step of 1e-9 as "0.000000" and 1e30 with 31 digits).
#include <charconv>
#include <string>

namespace mfr {

inline std::string numberText(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
}

}  // namespace mfr
