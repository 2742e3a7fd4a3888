#include "deep_variable_k_buffer.hpp"

#include "budget/mlp_layout.h"
#include "common/bindings.h"

// The weights are one std140 uniform block of uvec4 (shaders/methods/dkb/mlp.comp): it must fit the
// least GL_MAX_UNIFORM_BLOCK_SIZE that OpenGL 4.5 guarantees.
static_assert(MFR_MLP_PACKED_WORDS % 4 == 0 && 4 * MFR_MLP_PACKED_WORDS <= 16384);

namespace mfr {

const MethodInfo& DeepVariableKBuffer::info() const {
  static const MethodInfo i = [] {
    std::vector<ParamSpec> p = budgetParams();
    p.push_back({"weights",
                 "Network weights file",
                 ParamSpec::Type::Text,
                 "",
                 0,
                 0,
                 {},
                 "JSON weights of the 12-128-64-1 network (mfr train); empty: the built-in "
                 "resources/dkb/weights.json"});
    return MethodInfo{"dkb",
                      "Deep variable k-buffer: a neural network predicts k(p) under a memory budget",
                      "Tsopouridis, Fudos, Vasilakis: Deep hybrid order-independent transparency. The Visual "
                      "Computer 2022",
                      false,
                      p,
                      "hybrid"};
  }();
  return i;
}

void DeepVariableKBuffer::configureMember(const Params& params) {
  const std::string& path = params.text("weights");
  if (path != weightsPath_ || !weights_) {
    // 8-bit weights on the GPU; model_ holds exactly the values it runs (tests compare).
    NeuralImportanceModel model = loadNeuralImportance(path).quantised();  // throws before anything changes
    model_ = std::move(model);
    weightsPath_ = path;
    const std::vector<std::uint32_t> words = model_.packedWords();
    weights_ = gl::createBuffer(words.size() * sizeof(std::uint32_t), words.data());
  }
  if (!count_.id()) {
    count_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/dkb/count.geom.frag"}});
    nearest_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/dkb/nearest.geom.frag"}});
    mlp_ = gl::Program({{GL_COMPUTE_SHADER, "methods/dkb/mlp.comp"}});
  }
}

std::uint64_t DeepVariableKBuffer::memberFixedBytes() const {
  return NeuralImportanceModel::packedBytes();
}

void DeepVariableKBuffer::clearFeatures() {
  clearArena(layout_.tailBase, layout_.stride, 0x7F800000u);             // T(0): nearest depth, +inf
  clearArena(layout_.tailBase + layout_.stride, 4 * layout_.stride, 0);  // T(1..4): farthest depth, colour sums
  clearArena(layout_.kBase, pixels() + 1, 0);                            // K: nearest colour
}

std::uint32_t DeepVariableKBuffer::drawFeatures(const FrameContext& ctx) {
  setArenaUniforms(count_);
  ctx.timer.begin("features");
  ctx.scene.draw(count_, ctx.frame);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  setArenaUniforms(nearest_);
  ctx.scene.draw(nearest_, ctx.frame);
  ctx.timer.end();
  return 2;
}

void DeepVariableKBuffer::computeImportance(const FrameContext&) {
  glBindBufferBase(GL_UNIFORM_BUFFER, MFR_UBO_DKB_WEIGHTS, weights_.id());
  setArenaUniforms(mlp_);
  mlp_.set("uTarget", model_.predictsFractionOfList() ? 0u : 1u);
  dispatchPixels(mlp_, 64);
}

std::string DeepVariableKBuffer::describeImportance() const {
  return "MLP 12-128-64-1, 8-bit weights (" + model_.source + ", predicts " + model_.target + ")";
}

}  // namespace mfr
