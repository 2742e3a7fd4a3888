// Dynamic k+-buffer (Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015): resolve pass over
// the pixel's k slots (k chosen this frame), sorted by the shared driver.
#include "common/kbuffer_resolve.glsl"
