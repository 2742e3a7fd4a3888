#pragma once
// Small pieces every method's C++ side uses: GL state for geometry passes, the resolve pass
// draw, storage limits.
#include <cstdint>
#include <string>
#include <vector>

#include "mfr/gl/objects.hpp"
#include "mfr/methods/method.hpp"

namespace mfr {

// Geometry pass state for capture passes with side effects only: depth test off, culling off,
// colour writes off. Colour writes must be off: llvmpipe may drop earlier fragments of a tile
// that a later primitive fully covers when the pass also writes colour (NOTES.md). Restores the
// previous state on destruction.
class GeometryPassState {
 public:
  explicit GeometryPassState(bool colorWrites = false, bool depthTest = false);
  ~GeometryPassState();
  GeometryPassState(const GeometryPassState&) = delete;
  GeometryPassState& operator=(const GeometryPassState&) = delete;

 private:
  GLboolean depthTest_, cull_, blend_;
  GLboolean colorMask_[4];
  GLboolean depthMask_;
};

// Full-screen resolve: binds the operation, draws one triangle into the bound framebuffer.
void runResolvePass(const FrameContext& ctx, const gl::Program& program, const Operation& op);

// Per-pixel capacities from an exclusive prefix sum of pixels + 1 uints starting at word
// baseWord of the buffer: offsets[p+1] − offsets[p] (variable-capacity k-buffers). Empty for no
// buffer. Waits for the GPU.
std::vector<std::uint32_t> readCapacities(const gl::Buffer& offsets, std::uint64_t pixels, std::uint64_t baseWord = 0);

// Largest element count of the given size one shader storage buffer may hold on this context.
std::uint64_t maxStorageElements(std::uint64_t elementBytes);

// An exact method's buffer of `count` elements of `elementBytes` where at most `limit` fit (the
// largest storage block, or 32-bit addresses): throws mfr::Error(what, need + " = <bytes>, more
// than the largest shader storage block of this GL context holds (<limit bytes>)" + advice) when
// it does not fit. Exact methods refuse rather than drop fragments without a word.
void requireStorageFits(const std::string& what, const std::string& need, std::uint64_t count, std::uint64_t limit,
                        std::uint64_t elementBytes, const std::string& advice);

// Runs draw() inside a GL_SAMPLES_PASSED query and returns the samples that passed (waits). The
// peeling methods count fragments and pixels with it.
template <class Draw>
std::uint64_t countSamples(Draw&& draw) {
  const gl::Query query = gl::createQuery(GL_SAMPLES_PASSED);
  glBeginQuery(GL_SAMPLES_PASSED, query.id());
  draw();
  glEndQuery(GL_SAMPLES_PASSED);
  GLuint64 samples = 0;
  glGetQueryObjectui64v(query.id(), GL_QUERY_RESULT, &samples);
  return samples;
}

// The note of a peeling method that left `ties` fragments uncomposited at exactly the depth of a
// layer it peeled (peeling's known limit; methods.md).
std::string depthTiesNote(std::uint64_t ties);

}  // namespace mfr
