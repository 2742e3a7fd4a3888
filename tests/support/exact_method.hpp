#pragma once
// Parameterised test of an exact method against the oracle (tests/gl/test_exact_methods.cpp
// defines the tests; each method's test file instantiates them with its parameter sets).
#include <gtest/gtest.h>

#include <cctype>
#include <map>
#include <string>

namespace mfr::test {

struct ExactCase {
  std::string method;
  std::map<std::string, std::string> params;
  std::string label;  // test name suffix, e.g. "pool_previous"
  // Parameters added for the 100-layers-per-pixel test, for cases whose capacity (slots, passes)
  // is deliberately smaller than that.
  std::map<std::string, std::string> deepParams = {};
};

class ExactMethod : public ::testing::TestWithParam<ExactCase> {};

inline std::string exactCaseName(const ::testing::TestParamInfo<ExactCase>& p) {
  std::string n = p.param.method + (p.param.label.empty() ? "" : "_" + p.param.label);
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

}  // namespace mfr::test
