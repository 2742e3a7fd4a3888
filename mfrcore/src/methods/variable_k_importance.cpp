#include "variable_k_importance.hpp"

#include <sstream>

#include "common/bindings.h"

namespace mfr {

const MethodInfo& VariableKBufferImportance::info() const {
  static const MethodInfo i = [] {
    std::vector<ParamSpec> p = budgetParams();
    p.push_back({"poi_x",
                 "Point of interest x",
                 ParamSpec::Type::Float,
                 "0.5",
                 0,
                 1,
                 {},
                 "periphery criterion: where the viewer looks, as a fraction of the image width"});
    p.push_back({"poi_y",
                 "Point of interest y",
                 ParamSpec::Type::Float,
                 "0.5",
                 0,
                 1,
                 {},
                 "… as a fraction of the image height, from the top"});
    p.push_back({"falloff",
                 "Periphery falloff d",
                 ParamSpec::Type::Float,
                 "0.35",
                 0.01,
                 10,
                 {},
                 "importance exp(-(r/d)^2), r the distance from the point of interest in image diagonals"});
    p.push_back({"n_limit",
                 "Depth complexity limit N",
                 ParamSpec::Type::Float,
                 "32",
                 1,
                 4096,
                 {},
                 "depth criterion (min(n, N)/N)^alpha saturates at N fragments"});
    p.push_back(
        {"alpha", "Depth complexity exponent", ParamSpec::Type::Float, "1", 0, 8, {}, "alpha of the depth criterion"});
    p.push_back({"w_periphery", "Weight: periphery", ParamSpec::Type::Float, "1", 0, 100, {}, ""});
    p.push_back({"w_depth", "Weight: depth complexity", ParamSpec::Type::Float, "1", 0, 100, {}, ""});
    p.push_back({"w_fresnel",
                 "Weight: Fresnel",
                 ParamSpec::Type::Float,
                 "1",
                 0,
                 100,
                 {},
                 "Schlick's Fresnel term of the nearest fragment (silhouettes matter more)"});
    p.push_back({"noise",
                 "Noise lambda",
                 ParamSpec::Type::Float,
                 "0",
                 0,
                 1,
                 {},
                 "blend of a per-pixel hash into the importance"});
    return MethodInfo{"vkb",
                      "Variable k-buffer with importance maps, under a memory budget",
                      "Vasilakis, Vardis, Papaioannou, Moustakas: Variable k-buffer using Importance Maps. "
                      "Eurographics 2017 Short Papers (with the tail of hybrid transparency)",
                      false,
                      p,
                      "hybrid"};
  }();
  return i;
}

void VariableKBufferImportance::configureMember(const Params& params) {
  pointOfInterest_ = {static_cast<float>(params.real("poi_x")), static_cast<float>(params.real("poi_y"))};
  falloff_ = static_cast<float>(params.real("falloff"));
  depthLimit_ = static_cast<float>(params.real("n_limit"));
  depthAlpha_ = static_cast<float>(params.real("alpha"));
  weights_ = {static_cast<float>(params.real("w_periphery")), static_cast<float>(params.real("w_depth")),
              static_cast<float>(params.real("w_fresnel"))};
  noise_ = static_cast<float>(params.real("noise"));
  if (!count_.id()) {
    count_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/vkb/count.geom.frag"}});
    nearest_ =
        gl::Program({{GL_VERTEX_SHADER, "common/scene.vert"}, {GL_FRAGMENT_SHADER, "methods/vkb/nearest.geom.frag"}});
    importance_ = gl::Program({{GL_COMPUTE_SHADER, "methods/vkb/importance.comp"}});
  }
}

void VariableKBufferImportance::clearFeatures() {
  clearArena(layout_.tailBase, layout_.stride, 0x7F800000u);             // T(0): nearest depth, +inf
  clearArena(layout_.tailBase + layout_.stride, 2 * layout_.stride, 0);  // T(1), T(2): Fresnel, farthest depth
}

std::uint32_t VariableKBufferImportance::drawFeatures(const FrameContext& ctx) {
  setArenaUniforms(count_);
  ctx.timer.begin("count");
  ctx.scene.draw(count_, ctx.frame);
  ctx.timer.end();
  if (weights_.z <= 0.0f) return 1;  // no Fresnel criterion: no nearest pass
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  setArenaUniforms(nearest_);
  ctx.timer.begin("nearest");
  ctx.scene.draw(nearest_, ctx.frame);
  ctx.timer.end();
  return 2;
}

void VariableKBufferImportance::computeImportance(const FrameContext&) {
  setArenaUniforms(importance_);
  importance_.set("uImageSize", glm::vec2(static_cast<float>(width_), static_cast<float>(height_)));
  importance_.set("uPointOfInterest", pointOfInterest_);
  importance_.set("uFalloff", falloff_);
  importance_.set("uDepthLimit", depthLimit_);
  importance_.set("uDepthAlpha", depthAlpha_);
  importance_.set("uWeights", weights_);
  importance_.set("uNoise", noise_);
  dispatchPixels(importance_, 256);
}

std::string VariableKBufferImportance::describeImportance() const {
  std::ostringstream s;
  s << "periphery×" << weights_.x << " (poi " << pointOfInterest_.x << "," << pointOfInterest_.y << ", d " << falloff_
    << ") + depth×" << weights_.y << " (N " << depthLimit_ << ", alpha " << depthAlpha_ << ") + Fresnel×" << weights_.z
    << ", noise " << noise_;
  return s.str();
}

}  // namespace mfr
