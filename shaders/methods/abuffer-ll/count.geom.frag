// A-buffer with per-pixel linked lists (Yang et al., EGSR 2010): optional count pass that sizes
// the node pool exactly (the paper sizes it by hand; we offer count / previous-frame / fixed).
#include "common/fragment.glsl"
#include "methods/abuffer-ll/nodes.glsl"

void main() { atomicAdd(allocated, 1u); }
