// [Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §4: the per-pixel network 12 → 128 → 64 → 1, ReLU, ReLU, sigmoid.] Forward pass
// shared verbatim by the GPU inference pass (shaders/methods/dkb/mlp.comp) and the C++ reference
// (mfrcore/src/budget/neural_importance.cpp), same accumulation order. The including code defines
// how values are fetched (budget/mlp_layout.h): MFR_MLP_STAT(i), input statistic i;
// MFR_MLP_BIAS(f, b), bias b of all layers (float index f of the layout); MFR_MLP_ROW_WEIGHT(f, q,
// r), the weight at float index f, 8-bit index q, output row r (of all layers). C++ reads f from a
// vector of already dequantised floats, GLSL dequantises q with row r's scale. The features are standardised first, (x − mean) / std, with the training set's statistics
// stored in the weights file (an input normalisation layer of the model).
// Valid GLSL 4.50 and C++ with GLM.
#ifndef MFR_MLP_H
#define MFR_MLP_H

#include "budget/mlp_layout.h"

float mfrMlpForward(vec4 a, vec4 b, vec4 c) {
  float x[MFR_MLP_INPUTS];
  x[0] = a.x; x[1] = a.y; x[2] = a.z; x[3] = a.w;
  x[4] = b.x; x[5] = b.y; x[6] = b.z; x[7] = b.w;
  x[8] = c.x; x[9] = c.y; x[10] = c.z; x[11] = c.w;
  for (int i = 0; i < MFR_MLP_INPUTS; ++i)
    x[i] = (x[i] - MFR_MLP_STAT(MFR_MLP_MEAN + i)) / MFR_MLP_STAT(MFR_MLP_STD + i);
  float h1[MFR_MLP_HIDDEN1];
  for (int j = 0; j < MFR_MLP_HIDDEN1; ++j) {
    float s = MFR_MLP_BIAS(MFR_MLP_B1 + j, j);
    for (int i = 0; i < MFR_MLP_INPUTS; ++i)
      s += MFR_MLP_ROW_WEIGHT(MFR_MLP_W1 + j * MFR_MLP_INPUTS + i, MFR_MLP_Q_W1 + j * MFR_MLP_INPUTS + i, j) * x[i];
    h1[j] = max(s, 0.0f);
  }
  float out_ = MFR_MLP_BIAS(MFR_MLP_B3, MFR_MLP_HIDDEN1 + MFR_MLP_HIDDEN2);
  for (int j = 0; j < MFR_MLP_HIDDEN2; ++j) {
    float s = MFR_MLP_BIAS(MFR_MLP_B2 + j, MFR_MLP_HIDDEN1 + j);
    for (int i = 0; i < MFR_MLP_HIDDEN1; ++i)
      s += MFR_MLP_ROW_WEIGHT(MFR_MLP_W2 + j * MFR_MLP_HIDDEN1 + i, MFR_MLP_Q_W2 + j * MFR_MLP_HIDDEN1 + i,
                              MFR_MLP_HIDDEN1 + j) * h1[i];
    out_ += MFR_MLP_ROW_WEIGHT(MFR_MLP_W3 + j, MFR_MLP_Q_W3 + j, MFR_MLP_HIDDEN1 + MFR_MLP_HIDDEN2) * max(s, 0.0f);
  }
  return 1.0f / (1.0f + exp(-out_));
}

// The importance dkb allocates by, from the network's output y (before sanitising): y·n + ½ when
// it predicts k/n, so that the allocation rule's floor rounds the predicted k instead of
// truncating it; y when it predicts k/F.
float mfrDkbImportance(float y, uint n, bool predictsFractionOfList) {
  return predictsFractionOfList ? y * float(n) + 0.5f : y;
}

#endif
