// [Tsopouridis, Fudos, Vasilakis, "Deep hybrid order-independent transparency", The Visual
// Computer 2022, §4.] Sizes and float layout of the dkb network's weights (12 → 128 → 64 → 1),
// shared by budget/mlp.h (GLSL and C++) and the C++ weights file reader and trainer. Only #defines.
#ifndef MFR_MLP_LAYOUT_H
#define MFR_MLP_LAYOUT_H
#define MFR_MLP_INPUTS 12
#define MFR_MLP_HIDDEN1 128
#define MFR_MLP_HIDDEN2 64
// Float offsets of the weights layout: weights of layer l are row-major [output][input].
#define MFR_MLP_MEAN 0
#define MFR_MLP_STD (MFR_MLP_MEAN + MFR_MLP_INPUTS)
#define MFR_MLP_W1 (MFR_MLP_STD + MFR_MLP_INPUTS)
#define MFR_MLP_B1 (MFR_MLP_W1 + MFR_MLP_HIDDEN1 * MFR_MLP_INPUTS)
#define MFR_MLP_W2 (MFR_MLP_B1 + MFR_MLP_HIDDEN1)
#define MFR_MLP_B2 (MFR_MLP_W2 + MFR_MLP_HIDDEN2 * MFR_MLP_HIDDEN1)
#define MFR_MLP_W3 (MFR_MLP_B2 + MFR_MLP_HIDDEN2)
#define MFR_MLP_B3 (MFR_MLP_W3 + MFR_MLP_HIDDEN2)
#define MFR_MLP_FLOATS (MFR_MLP_B3 + 1)
// On the GPU (dkb): words 0..23 the input mean and deviation as 32-bit floats, then the weights
// and biases from MFR_MLP_W1 on as 16-bit floats, two per word (packHalf2x16: even index low).
#define MFR_MLP_PACKED_WORDS (MFR_MLP_W1 + (MFR_MLP_FLOATS - MFR_MLP_W1 + 1) / 2)

#endif
