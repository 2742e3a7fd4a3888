// [Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §4.] The 12 per-pixel features of the deep variable k-buffer (dkb), shared
// verbatim by the GPU pass (shaders/methods/dkb/mlp.comp) and the CPU dataset writer
// (mfrcore/src/budget/neural_importance.cpp), so training and inference see the same numbers:
//   a = (n/Σn, F(M)/Σn, nearest depth, farthest depth)          of the pixel
//   b = (nearest depth, farthest depth of the image, nearest colour r, g)
//   c = (nearest colour b, mean colour r, g, b)
// Depths are window depths in [0, 1]; colours the stored 8-bit shaded values / 255; the mean is
// over all of the pixel's fragments. Only non-empty pixels have features (k = 0 elsewhere).
// Valid GLSL 4.50 and C++ with GLM; MFR_OUT(T) is "out T" in GLSL and "T&" in C++.
#ifndef MFR_FEATURES_H
#define MFR_FEATURES_H

#define MFR_DKB_FEATURES 12

void mfrDkbFeatures(uint n, float totalFragments, float budgetSlots, float nearDepth, float farDepth,
                    float imageNear, float imageFar, uint nearestColor, vec3 colorSum, MFR_OUT(vec4) a,
                    MFR_OUT(vec4) b, MFR_OUT(vec4) c) {
  float total = max(totalFragments, 1.0f);
  vec3 nearest = vec3(float(nearestColor & 255u), float((nearestColor >> 8u) & 255u),
                      float((nearestColor >> 16u) & 255u)) / 255.0f;
  vec3 mean = colorSum / (255.0f * max(float(n), 1.0f));
  a = vec4(float(n) / total, budgetSlots / total, nearDepth, farDepth);
  b = vec4(imageNear, imageFar, nearest.x, nearest.y);
  c = vec4(nearest.z, mean.x, mean.y, mean.z);
}

#endif
