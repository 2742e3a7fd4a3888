// Method parameters as the command lines give them: Params' reading of values, and which given
// parameters would change nothing (unusedMethodParam). CPU only: the methods' descriptions need no
// GL context.
#include <gtest/gtest.h>

#include <string>

#include "mfr/error.hpp"
#include "mfr/methods/method.hpp"
#include "mfr/operation_settings.hpp"
#include "mfr/render.hpp"

namespace mfr::test {
namespace {

std::string refusal(const std::string& method, const std::string& name, const std::string& value) {
  const MethodInfo* info = findMethodInfo(method);
  if (!info) return "no method " + method;
  try {
    const Params params(info->params, {{name, value}}, method);
    return {};
  } catch (const Error& e) {
    return e.what();
  }
}

// An integer takes digits only, as the command line's whole-number options: "k=1e2" was k = 100,
// "k=8.0", "k=+8" and "k= 8" were 8, where "k=1.5" was refused (a bug hunt).
TEST(MethodParams, IntegersTakeDigitsOnly) {
  for (const std::string value : {"8", "08", "256"}) EXPECT_EQ(refusal("kplus-array", "k", value), "") << value;
  for (const std::string value : {"8.0", "1e2", "8e0", "+8", " 8", "8 ", "1.5", "0x8", "", "-"})
    EXPECT_EQ(refusal("kplus-array", "k", value).rfind("--param k=" + value + ": expected ", 0), 0u)
        << value << ": " << refusal("kplus-array", "k", value);
  EXPECT_EQ(refusal("kplus-array", "k", "1e2"), "--param k=1e2: expected an integer (digits only)");
  EXPECT_EQ(refusal("kplus-array", "k", "300"), "--param k=300: out of range [1, 256]");
  // Floats keep their spellings.
  for (const std::string value : {"1.5", "1e1", "0.25", "2"})
    EXPECT_EQ(refusal("fkb", "budget_mib", value), "") << value;
}

// A parameter acting only with another's value is named when given without it (abuffer-ll's
// pool_mib without pool=fixed was dropped without a word; a bug hunt).
TEST(MethodParams, AParameterWithoutTheValueItActsWithIsNamed) {
  RenderRequest req;
  req.method = "abuffer-ll";
  req.params = {{"pool_mib", "1"}};
  std::optional<UnusedOperationSetting> unused = unusedMethodParam(req);
  ASSERT_TRUE(unused);
  EXPECT_EQ(unused->name, "param pool_mib=1");
  EXPECT_EQ(unused->reason, "only pool=fixed uses it; this render's pool is count");
  req.method = "abuffer-sbuffer";
  req.params["pool"] = "previous";
  unused = unusedMethodParam(req);
  ASSERT_TRUE(unused);
  EXPECT_EQ(unused->reason, "only pool=fixed uses it; this render's pool is previous");
  req.params["pool"] = "fixed";
  EXPECT_FALSE(unusedMethodParam(req));
  req.params = {{"pool", "previous"}};  // pool_mib not given: nothing to refuse
  EXPECT_FALSE(unusedMethodParam(req));
  // A flag that refines another: asked for without it (dkb's tail runs without the exact tail);
  // turned off it asks for nothing.
  req.method = "dkb";
  req.params = {{"exact_tail", "off"}, {"tail_runs", "on"}};
  unused = unusedMethodParam(req);
  ASSERT_TRUE(unused);
  EXPECT_EQ(unused->name, "param tail_runs=on");
  EXPECT_EQ(unused->reason, "only exact_tail=true uses it; this render's exact_tail is false");
  req.params = {{"exact_tail", "1"}, {"tail_runs", "on"}};
  EXPECT_FALSE(unusedMethodParam(req));
  req.params = {{"exact_tail", "false"}, {"tail_runs", "false"}};
  EXPECT_FALSE(unusedMethodParam(req));
  req.method = "no-such-method";
  EXPECT_FALSE(unusedMethodParam(req));
}

// Defaults by operation: what only hybrid transparency reads is off elsewhere.
TEST(MethodParams, TailDefaultsFollowTheOperation) {
  const auto spec = [](const std::string& method, const std::string& name) {
    for (const ParamSpec& s : findMethodInfo(method)->params)
      if (s.name == name) return s;
    return ParamSpec{};
  };
  EXPECT_EQ(defaultValueFor(spec("fkb", "tail"), "hybrid"), "true");
  for (const char* op : {"oit", "zthickness", "volume", "csg"}) {
    EXPECT_EQ(defaultValueFor(spec("fkb", "tail"), op), "false") << op;
    EXPECT_EQ(defaultValueFor(spec("vkb", "exact_tail"), op), "false") << op;
    EXPECT_EQ(defaultValueFor(spec("dkb", "tail_runs"), op), "true") << op;  // inert without the exact tail
    EXPECT_EQ(defaultValueFor(spec("kplus-array", "k"), op), "8") << op;
  }
}

}  // namespace
}  // namespace mfr::test
