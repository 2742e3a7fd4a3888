// k+-buffer max-heap (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015): resolve pass;
// the heap-ordered k entries are sorted by the shared driver.
#include "common/kbuffer_resolve.glsl"
