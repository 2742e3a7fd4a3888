// Variable k-buffer using importance maps (Vasilakis, Vardis, Papaioannou, Moustakas, EG 2017
// Short Papers): resolve over each pixel's k(p) contiguous slots (MFR_KB_VARIABLE: offsets from
// the allocation's prefix sum), sorted by the shared driver; with --op hybrid the tail sums
// complete the pixel (Tsopouridis, Fudos, Vasilakis, The Visual Computer 2022, §3.3).
#include "common/kbuffer_resolve.glsl"
