// A-buffer with per-pixel linked lists: Yang, Hensley, Grün, Thibieroz, "Real-Time Concurrent
// Linked List Construction on the GPU", Computer Graphics Forum 29(4) (EGSR 2010).
// Storage shared by the store and resolve passes: a head pointer per pixel and a global pool of
// 12-byte nodes (8-byte payload + next index).
// Nodes are three consecutive uints (colour, depth bits, next) in a flat array.
layout(std430, binding = MFR_SSBO_NODES) buffer Nodes { uint nodeWords[]; };
layout(std430, binding = MFR_SSBO_COUNTER) buffer Counter {
  uint allocated;  // nodes requested (= fragments generated this frame)
  uint dropped;    // fragments lost because the pool was full
};
