// Classic k-buffer (Bavoil, Callahan, Lefohn, Comba, Silva, "Multi-fragment effects on the GPU
// using the k-buffer", I3D 2007): resolve pass over the pixel's sorted k entries.
#include "common/kbuffer_resolve.glsl"
