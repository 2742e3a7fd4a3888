// Deep hybrid order-independent transparency (Tsopouridis, Fudos, Vasilakis, The Visual Computer
// 2022): resolve over each pixel's predicted k(p) contiguous slots (MFR_KB_VARIABLE), sorted by
// the shared driver; --op hybrid adds the tail sums (§3.3).
#include "common/kbuffer_resolve.glsl"
