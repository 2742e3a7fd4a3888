#include "prefix_sum.hpp"

#include <algorithm>

#include "common/bindings.h"
#include "mfr/error.hpp"

namespace mfr {
namespace {
std::uint64_t blocksOf(std::uint64_t n) {
  return (n + PrefixSum::kBlock - 1) / PrefixSum::kBlock;
}
}  // namespace

std::uint64_t PrefixSum::scratchElements(std::uint64_t n) {
  // Level l scans `count` elements in blocksOf(count) blocks and writes that many totals; the
  // totals are the next level's input until one block remains (its total is the grand total).
  std::uint64_t total = 0;
  std::uint64_t count = n;
  do {
    const std::uint64_t blocks = std::max<std::uint64_t>(blocksOf(count), 1);
    total += blocks;
    count = blocks;
  } while (count > 1);
  return total;
}

void PrefixSum::dispatch(const gl::Program& program, std::uint32_t count, std::uint32_t blocks, std::uint32_t inBase,
                         std::uint32_t outBase, std::uint32_t sumsBase) const {
  program.use();
  program.set("uCount", count);
  program.set("uBlocks", blocks);
  program.set("uInBase", inBase);
  program.set("uOutBase", outBase);
  program.set("uSumsBase", sumsBase);
  // 2D grid: one dimension holds at most 65535 work groups (the GL minimum).
  const std::uint32_t x = std::min<std::uint32_t>(blocks, 65535u);
  const std::uint32_t y = (blocks + x - 1) / x;
  glDispatchCompute(x, y, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void PrefixSum::scan(GLuint input, GLuint output, std::uint32_t n) {
  scan(input, 0, output, 0, n);
}

void PrefixSum::scan(GLuint input, std::uint32_t inBase, GLuint output, std::uint32_t outBase, std::uint32_t n) {
  if (!blockScan_.id()) {
    blockScan_ = gl::Program({{GL_COMPUTE_SHADER, "common/prefix_sum.comp"}});
    addOffsets_ = gl::Program({{GL_COMPUTE_SHADER, "common/prefix_sum.comp"}}, {{"MFR_SCAN_ADD", "1"}});
  }
  const std::uint64_t need = scratchElements(n);
  if (!scratch_ || need != scratchSize_) {
    scratch_ = gl::createBuffer(need * 4);
    scratchSize_ = need;
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  if (n == 0) {
    const GLuint zero = 0;
    glClearNamedBufferSubData(scratch_.id(), GL_R32UI, totalOffset(), 4, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    return;
  }

  // Level plan: (elements, blocks, base of this level's block totals in the scratch).
  struct Level {
    std::uint32_t count, blocks, sumsBase;
  };
  std::vector<Level> levels;
  std::uint32_t count = n, sumsBase = 0;
  for (;;) {
    const auto blocks = static_cast<std::uint32_t>(blocksOf(count));
    levels.push_back({count, blocks, sumsBase});
    if (blocks == 1) break;
    count = blocks;
    sumsBase += blocks;
  }

  // Up: level 0 scans input → output; level l > 0 scans level l-1's block totals in place.
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_SCAN, scratch_.id());
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const Level& L = levels[l];
    if (l == 0) {
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, input);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, output);
      dispatch(blockScan_, L.count, L.blocks, inBase, outBase, L.sumsBase);
    } else {
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_AUX, scratch_.id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, scratch_.id());
      const std::uint32_t base = levels[l - 1].sumsBase;
      dispatch(blockScan_, L.count, L.blocks, base, base, L.sumsBase);
    }
  }
  // Down: every level below the top adds its blocks' scanned offsets (the top has one block).
  for (std::size_t l = levels.size() - 1; l-- > 0;) {
    const Level& L = levels[l];
    if (l == 0) {
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, output);
      dispatch(addOffsets_, L.count, L.blocks, outBase, outBase, L.sumsBase);
    } else {
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, MFR_SSBO_OFFSETS, scratch_.id());
      const std::uint32_t base = levels[l - 1].sumsBase;
      dispatch(addOffsets_, L.count, L.blocks, base, base, L.sumsBase);
    }
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
}

std::uint32_t PrefixSum::readTotal() const {
  if (!scratch_) throw Error("prefix sum", "no scan has run");
  std::uint32_t total = 0;
  glGetNamedBufferSubData(scratch_.id(), totalOffset(), 4, &total);
  return total;
}

}  // namespace mfr
