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
// On the GPU (dkb), in 32-bit words: the input mean and deviation (24 floats), the biases of the
// three layers (128 + 64 + 1 floats), one scale per output row (same count), then every weight as
// a signed 8-bit integer, four per word (byte j % 4 of word j / 4), rows of W1, W2, W3 in turn:
// weight = scale[row] · q, with q ∈ [−127, 127] (symmetric per-row quantisation). dkb reads them
// as a std140 uniform block of uvec4 (uniform loads: 2.7× faster than a storage buffer on
// llvmpipe, and the constant cache on GPUs), so the word count is rounded up to a multiple of 4;
// 11,440 bytes, within GL 4.5's least GL_MAX_UNIFORM_BLOCK_SIZE of 16,384.
#define MFR_MLP_ROWS (MFR_MLP_HIDDEN1 + MFR_MLP_HIDDEN2 + 1)
#define MFR_MLP_Q_W1 0
#define MFR_MLP_Q_W2 (MFR_MLP_Q_W1 + MFR_MLP_HIDDEN1 * MFR_MLP_INPUTS)
#define MFR_MLP_Q_W3 (MFR_MLP_Q_W2 + MFR_MLP_HIDDEN2 * MFR_MLP_HIDDEN1)
#define MFR_MLP_Q_COUNT (MFR_MLP_Q_W3 + MFR_MLP_HIDDEN2)
#define MFR_MLP_GPU_BIAS (2 * MFR_MLP_INPUTS)
#define MFR_MLP_GPU_SCALE (MFR_MLP_GPU_BIAS + MFR_MLP_ROWS)
#define MFR_MLP_GPU_QUANT (MFR_MLP_GPU_SCALE + MFR_MLP_ROWS)
#define MFR_MLP_PACKED_WORDS ((MFR_MLP_GPU_QUANT + (MFR_MLP_Q_COUNT + 3) / 4 + 3) / 4 * 4)

#endif
