// [Vasilakis, Vardis, Papaioannou, Moustakas, "Variable k-buffer using Importance Maps",
// Eurographics 2017 Short Papers.] The importance map of the variable k-buffer (vkb), shared by
// the GPU pass (shaders/methods/vkb/importance.comp) and C++ tests. Our reading of the paper's
// criteria (its text was not reachable when this was written; docs/methods.md states the rule):
//   periphery   P = exp(−(r / d)²), r = distance of the pixel centre from the point of interest
//               in units of the image diagonal, d the falloff;
//   depth       D = (min(n, N_limit) / N_limit)^α, n the pixel's fragment count;
//   Fresnel     F = F0 + (1 − F0)(1 − |cos θ|)^5 (Schlick, F0 = 0.04) of the nearest fragment;
//   I = (w_P·P + w_D·D + w_F·F) / (w_P + w_D + w_F), then I ← (1 − λ)·I + λ·ξ with ξ ∈ [0, 1) a
//   per-pixel hash (noise λ breaks up the banding of equal importances).
// Valid GLSL 4.50 and C++ with GLM (no swizzles, f-suffixed literals).
#ifndef MFR_IMPORTANCE_H
#define MFR_IMPORTANCE_H

const float MFR_FRESNEL_F0 = 0.04f;

float mfrFresnelSchlick(float cosTheta) {
  float m = 1.0f - min(abs(cosTheta), 1.0f);
  return MFR_FRESNEL_F0 + (1.0f - MFR_FRESNEL_F0) * (m * m * m * m * m);
}

float mfrPeriphery(vec2 pixelCentre, vec2 imageSize, vec2 pointOfInterest, float falloff) {
  vec2 delta = pixelCentre - pointOfInterest * imageSize;
  float r = length(delta) / length(imageSize);
  float x = r / max(falloff, 1.0e-6f);
  return exp(-x * x);
}

float mfrDepthImportance(uint n, float nLimit, float alpha) {
  float ratio = min(float(n), nLimit) / max(nLimit, 1.0f);
  return pow(ratio, alpha);
}

// Integer hash of the pixel (Wang-style mixing) → [0, 1).
float mfrPixelNoise(uint x, uint y) {
  uint h = x * 1973u + y * 9277u + 26699u;
  h = (h ^ 61u) ^ (h >> 16u);
  h = h * 9u;
  h = h ^ (h >> 4u);
  h = h * 0x27d4eb2du;
  h = h ^ (h >> 15u);
  return float(h >> 8u) / 16777216.0f;
}

float mfrCombineImportance(float periphery, float depth, float fresnel, vec3 weights, float noiseAmount, float noise) {
  float wsum = weights.x + weights.y + weights.z;
  float i = wsum > 0.0f ? (weights.x * periphery + weights.y * depth + weights.z * fresnel) / wsum : 1.0f;
  return (1.0f - noiseAmount) * i + noiseAmount * noise;
}

#endif
