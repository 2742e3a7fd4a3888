// k+-buffer on S-buffer storage, K+B-AB_SB (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015,
// Alg. 3): resolve pass over the pixel's min(n(p), k) contiguous slots (MFR_KB_VARIABLE: offsets
// from the prefix sum), sorted by the shared driver.
#include "common/kbuffer_resolve.glsl"
