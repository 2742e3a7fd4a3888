// k+-buffer max-array (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015): resolve pass;
// the unsorted k entries are sorted by the shared driver.
#include "common/kbuffer_resolve.glsl"
