// The GPU exclusive scan (mfrcore/src/methods/prefix_sum.*, shaders/common/prefix_sum.comp)
// against std::exclusive_scan: sizes around the block size (1024) and the level boundaries, in
// and out of place, values that wrap 32 bits, output elements past n untouched.
#include <gtest/gtest.h>

#include <numeric>
#include <random>
#include <vector>

#include "../../mfrcore/src/methods/prefix_sum.hpp"
#include "gl_fixture.hpp"
#include "mfr/gl/objects.hpp"

namespace mfr::test {
namespace {

constexpr std::uint32_t kSentinel = 0xDEADBEEFu;
constexpr std::uint32_t kTail = 16;  // extra output elements that must stay untouched

std::vector<std::uint32_t> randomValues(std::size_t n, std::uint32_t maxValue, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::uint32_t> dist(0, maxValue);
  std::vector<std::uint32_t> v(n);
  for (auto& x : v) x = dist(rng);
  return v;
}

void checkScan(std::uint32_t n, std::uint32_t maxValue, bool inPlace, unsigned seed) {
  SCOPED_TRACE("n = " + std::to_string(n) + (inPlace ? ", in place" : ", out of place"));
  context();
  const std::vector<std::uint32_t> input = randomValues(n, maxValue, seed);
  std::vector<std::uint32_t> expected(n);
  std::exclusive_scan(input.begin(), input.end(), expected.begin(), 0u);  // wraps mod 2^32 like the GPU
  const std::uint32_t expectedTotal = std::accumulate(input.begin(), input.end(), 0u);

  std::vector<std::uint32_t> initial(input);
  initial.resize(n + kTail, kSentinel);
  gl::Buffer in = gl::createBuffer(initial.size() * 4, initial.data());
  gl::Buffer separate;
  if (!inPlace) {
    const std::vector<std::uint32_t> filler(n + kTail, kSentinel);
    separate = gl::createBuffer(filler.size() * 4, filler.data());
  }
  const GLuint out = inPlace ? in.id() : separate.id();

  PrefixSum scan;
  scan.scan(in.id(), out, n);
  std::vector<std::uint32_t> result(n + kTail);
  glGetNamedBufferSubData(out, 0, static_cast<GLsizeiptr>(result.size() * 4), result.data());
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  std::size_t wrong = 0, first = n;
  for (std::uint32_t i = 0; i < n; ++i)
    if (result[i] != expected[i]) {
      ++wrong;
      first = std::min<std::size_t>(first, i);
    }
  EXPECT_EQ(wrong, 0u) << "first wrong element " << first << ": " << (first < n ? result[first] : 0) << " vs "
                       << (first < n ? expected[first] : 0);
  for (std::uint32_t i = n; i < n + kTail; ++i) EXPECT_EQ(result[i], kSentinel) << "element " << i << " past n written";
  EXPECT_EQ(scan.readTotal(), expectedTotal);
  EXPECT_EQ(scan.bytesAllocated(), 4 * PrefixSum::scratchElements(n));
  if (!inPlace) {
    std::vector<std::uint32_t> after(n);
    glGetNamedBufferSubData(in.id(), 0, static_cast<GLsizeiptr>(n * 4), after.data());
    EXPECT_EQ(after, input) << "input modified by an out-of-place scan";
  }
}

TEST(PrefixSum, ScratchHoldsEveryLevelsBlockTotals) {
  EXPECT_EQ(PrefixSum::kBlock, 1024u);
  EXPECT_EQ(PrefixSum::scratchElements(0), 1u);
  EXPECT_EQ(PrefixSum::scratchElements(1), 1u);
  EXPECT_EQ(PrefixSum::scratchElements(1024), 1u);
  EXPECT_EQ(PrefixSum::scratchElements(1025), 2u + 1u);
  EXPECT_EQ(PrefixSum::scratchElements(100000), 98u + 1u);
  EXPECT_EQ(PrefixSum::scratchElements(1u << 20), 1024u + 1u);
  EXPECT_EQ(PrefixSum::scratchElements((1u << 20) + 1), 1025u + 2u + 1u);
}

TEST(PrefixSum, MatchesCpuOnAwkwardSizes) {
  unsigned seed = 1;
  for (std::uint32_t n : {1u, 2u, 255u, 256u, 257u, 1023u, 1024u, 1025u, 4097u, 100000u, 1u << 20})
    checkScan(n, 1000, false, seed++);
}

TEST(PrefixSum, InPlace) {
  unsigned seed = 100;
  for (std::uint32_t n : {1u, 257u, 1025u, 100000u}) checkScan(n, 1000, true, seed++);
}

// More than 1024² elements: three levels of block totals.
TEST(PrefixSum, ThreeLevels) {
  checkScan((1u << 20) + 1000, 7, false, 7);
}

TEST(PrefixSum, WrapsModulo2To32LikeUnsignedArithmetic) {
  checkScan(3000, 0xFFFFFFFFu, false, 11);
}

TEST(PrefixSum, EmptyInputHasTotalZero) {
  context();
  gl::Buffer b = gl::createBuffer(4);
  PrefixSum scan;
  scan.scan(b.id(), b.id(), 0);
  EXPECT_EQ(scan.readTotal(), 0u);
}

// One object, scans of changing sizes: the scratch follows the size, results stay right.
TEST(PrefixSum, ReusedForDifferentSizes) {
  context();
  PrefixSum scan;
  unsigned seed = 50;
  for (std::uint32_t n : {5000u, 3u, 70000u}) {
    const std::vector<std::uint32_t> input = randomValues(n, 50, seed++);
    std::vector<std::uint32_t> expected(n);
    std::exclusive_scan(input.begin(), input.end(), expected.begin(), 0u);
    gl::Buffer in = gl::createBuffer(n * 4, input.data());
    gl::Buffer out = gl::createBuffer(n * 4);
    scan.scan(in.id(), out.id(), n);
    std::vector<std::uint32_t> result(n);
    glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(n * 4), result.data());
    EXPECT_EQ(result, expected) << "n = " << n;
    EXPECT_EQ(scan.readTotal(), std::accumulate(input.begin(), input.end(), 0u));
  }
}

}  // namespace
}  // namespace mfr::test
