// [Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §4: the per-pixel network 12 → 128 → 64 → 1, ReLU, ReLU, sigmoid.] Forward pass
// shared verbatim by the GPU inference pass (shaders/methods/dkb/mlp.comp) and the C++ reference
// (mfrcore/src/budget/neural_importance.cpp), same accumulation order. The including code defines
// how values are fetched (budget/mlp_layout.h): MFR_MLP_STAT(i), input statistic i;
// MFR_MLP_BIAS(r) and MFR_MLP_SCALE(r), the bias and weight scale of output row r (rows of all
// layers in turn); MFR_MLP_QUAD(q), the four weights at 8-bit indices q … q + 3 (one row's, q a
// multiple of 4) as a vec4 of the integers −127 … 127. A row's output is bias + scale·Σ q·x: the
// scale is applied once per row, not once per weight, and the weights are read four at a time —
// the inner loops are dot products (4.4× faster on llvmpipe than a scaled weight per product).
// The features are standardised first, (x − mean) / std, with the training set's statistics
// stored in the weights file (an input normalisation layer of the model).
// Valid GLSL 4.50 and C++ with GLM.
#ifndef MFR_MLP_H
#define MFR_MLP_H

#include "budget/mlp_layout.h"

float mfrMlpForward(vec4 a, vec4 b, vec4 c) {
  vec4 x[MFR_MLP_INPUTS / 4];
  x[0] = a;
  x[1] = b;
  x[2] = c;
  for (int i = 0; i < MFR_MLP_INPUTS / 4; ++i)
    for (int e = 0; e < 4; ++e)
      x[i][e] = (x[i][e] - MFR_MLP_STAT(MFR_MLP_MEAN + 4 * i + e)) / MFR_MLP_STAT(MFR_MLP_STD + 4 * i + e);
  vec4 h1[MFR_MLP_HIDDEN1 / 4];
  for (int j = 0; j < MFR_MLP_HIDDEN1; ++j) {
    float s = 0.0f;
    for (int i = 0; i < MFR_MLP_INPUTS / 4; ++i) s += dot(MFR_MLP_QUAD(MFR_MLP_Q_W1 + j * MFR_MLP_INPUTS + 4 * i), x[i]);
    h1[j / 4][j % 4] = max(MFR_MLP_BIAS(j) + MFR_MLP_SCALE(j) * s, 0.0f);
  }
  vec4 h2[MFR_MLP_HIDDEN2 / 4];
  for (int j = 0; j < MFR_MLP_HIDDEN2; ++j) {
    float s = 0.0f;
    for (int i = 0; i < MFR_MLP_HIDDEN1 / 4; ++i)
      s += dot(MFR_MLP_QUAD(MFR_MLP_Q_W2 + j * MFR_MLP_HIDDEN1 + 4 * i), h1[i]);
    h2[j / 4][j % 4] = max(MFR_MLP_BIAS(MFR_MLP_HIDDEN1 + j) + MFR_MLP_SCALE(MFR_MLP_HIDDEN1 + j) * s, 0.0f);
  }
  float s = 0.0f;
  for (int i = 0; i < MFR_MLP_HIDDEN2 / 4; ++i) s += dot(MFR_MLP_QUAD(MFR_MLP_Q_W3 + 4 * i), h2[i]);
  const int last = MFR_MLP_HIDDEN1 + MFR_MLP_HIDDEN2;  // the output row
  return 1.0f / (1.0f + exp(-(MFR_MLP_BIAS(last) + MFR_MLP_SCALE(last) * s)));
}

// The importance dkb allocates by, from the network's output y (before sanitising): y·n + ½ when
// it predicts k/n, so that the allocation rule's floor rounds the predicted k instead of
// truncating it; y when it predicts k/F.
float mfrDkbImportance(float y, uint n, bool predictsFractionOfList) {
  return predictsFractionOfList ? y * float(n) + 0.5f : y;
}

#endif
