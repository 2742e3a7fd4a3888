// Fixed k-buffer under a memory budget (fkb; Tsopouridis, Fudos, Vasilakis, "Deep hybrid
// order-independent transparency", The Visual Computer 2022, its baseline): a k+-buffer max-array
// (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015) with the largest uniform k that fits M;
// resolve over the pixel's k slots, sorted by the shared driver.
#include "common/kbuffer_resolve.glsl"
