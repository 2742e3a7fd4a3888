#pragma once
// Numbers in notes and messages: the shortest text that reads back as the same double
// (std::to_string printed a step of 1e-9 as "0.000000" and 1e30 with 31 digits).
#include <charconv>
#include <cstdio>
#include <string>

namespace mfr {

inline std::string numberText(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
}

// Six significant digits (printf's %g): values a user typed or a float held, shown as read
// ("0.3", not 0.29999999999999999; 1e33 as a float is 9.999999944957273e+32).
inline std::string shortNumberText(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace mfr
