// k+-buffer max-heap (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient, Memory-Friendly and
// Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015): the pixel's k entries form a binary
// max-heap (children of slot i at 2i+1, 2i+2), maximum at slot 0. A fragment nearer than the root
// evicts it and sifts down from the root in O(log k) steps. Empty slots hold +inf, so a heap of
// +infs is valid and the first k fragments need no special case. The sift moves the hole, not the
// fragment: slot 0 is written once, with the new maximum (the larger child or the fragment), so a
// racy reader (culling outside the lock) never sees a value below the true maximum.
// Used inside the critical section; include after common/kbuffer_store.glsl.
void kbMaxHeapInsert() {
  uvec2 top = kbEntries[kbSlot(0u)];
  if (!(gDepth < kbDepth(top))) {
    kbNotKept(gPixel, gFrag);
    return;
  }
  if (top.y != KB_EMPTY) kbNotKept(gPixel, top);  // evicted
  uint hole = 0u;
  for (uint level = 0u; level < 32u; ++level) {  // log2(k) + 1 levels at most
    uint child = 2u * hole + 1u;
    if (child >= gK) break;
    uvec2 c = kbEntries[kbSlot(child)];
    if (child + 1u < gK) {
      uvec2 r = kbEntries[kbSlot(child + 1u)];
      if (kbDepth(r) > kbDepth(c)) {
        c = r;
        ++child;
      }
    }
    if (!(kbDepth(c) > gDepth)) break;
    kbEntries[kbSlot(hole)] = c;  // the larger child moves up into the hole
    hole = child;
  }
  kbEntries[kbSlot(hole)] = gFrag;
}
