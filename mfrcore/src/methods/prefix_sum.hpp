#pragma once
// GPU exclusive prefix sum (scan) of a buffer of uints: Blelloch 1990 / Harris et al., GPU Gems 3
// ch. 39 (shaders/common/prefix_sum.comp). Multi-level and work-efficient: block scans in shared
// memory → the same scan over the block totals, recursively → add the scanned totals back. Used by
// variable-length per-pixel arrays (S-buffer, k-buffer variants) to turn per-pixel counts into
// offsets without a CPU round trip; the grand total stays on the GPU (totalBuffer/totalOffset)
// unless the caller reads it back.
#include <cstdint>
#include <vector>

#include "mfr/gl/objects.hpp"
#include "mfr/gl/program.hpp"

namespace mfr {

class PrefixSum {
 public:
  // Elements one work group scans (256 threads × 4); must match SCAN_BLOCK in prefix_sum.comp.
  static constexpr std::uint32_t kBlock = 1024;

  // Scratch elements (uints) a scan of n elements needs: the block totals of every level, the
  // last level's single total being the grand total (n ≤ kBlock: just that one).
  static std::uint64_t scratchElements(std::uint64_t n);

  // Exclusive scan of n uints: output[i] = input[0] + … + input[i-1] for i < n, and the total
  // input[0] + … + input[n-1] (mod 2^32) into totalBuffer() at totalOffset(). input and output
  // may be the same buffer; output elements ≥ n are not touched. Issues the memory barrier that
  // makes the input's shader writes visible, and one after, so the results can be read by shaders,
  // buffer copies or glGetBufferSubData. Needs a current GL 4.5 context. Clobbers the SSBO bindings
  // MFR_SSBO_AUX, MFR_SSBO_OFFSETS and MFR_SSBO_SCAN and the current program.
  void scan(GLuint input, GLuint output, std::uint32_t n);
  // The same over elements [inBase, inBase + n) of input into [outBase, outBase + n) of output
  // (word offsets: scans of regions inside one larger buffer).
  void scan(GLuint input, std::uint32_t inBase, GLuint output, std::uint32_t outBase, std::uint32_t n);

  [[nodiscard]] GLuint totalBuffer() const { return scratch_.id(); }
  [[nodiscard]] GLintptr totalOffset() const { return static_cast<GLintptr>(4 * (scratchSize_ - 1)); }
  // Reads the last scan's total back to the CPU (waits for the GPU).
  [[nodiscard]] std::uint32_t readTotal() const;
  // Bytes of GPU memory this object owns (its scratch buffer).
  [[nodiscard]] std::uint64_t bytesAllocated() const { return scratch_ ? 4 * scratchSize_ : 0; }

 private:
  void dispatch(const gl::Program& program, std::uint32_t count, std::uint32_t blocks, std::uint32_t inBase,
                std::uint32_t outBase, std::uint32_t sumsBase) const;

  gl::Program blockScan_, addOffsets_;
  gl::Buffer scratch_;
  std::uint64_t scratchSize_ = 0;  // elements
};

}  // namespace mfr
