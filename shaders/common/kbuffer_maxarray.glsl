// k+-buffer max-array (Vasilakis, Papaioannou, Fudos, "k+-buffer: An Efficient, Memory-Friendly
// and Dynamic k-buffer Framework", IEEE TVCG 21(6) 2015; I3D 2014): the pixel's k
// entries are kept unsorted with the farthest one in slot 0. A fragment nearer than slot 0 evicts
// it; the new maximum among slots 1..k-1 and the fragment then moves into slot 0 (one scan of
// k-1 slots). Slot 0 is written once, with its final value, before the slot it came from, so a
// racy reader (culling outside the lock) only ever sees +inf or a real maximum, which never
// increases during the frame: its culling test stays conservative.
// Used inside the critical section; include after common/kbuffer_store.glsl.
void kbMaxArrayInsert() {
  uvec2 top = kbEntries[kbSlot(0u)];
  if (!(gDepth < kbDepth(top))) {
    kbNotKept(gPixel, gFrag);  // not among the k nearest
    return;
  }
  if (top.y != KB_EMPTY) kbNotKept(gPixel, top);  // evicted
  uint far = 0u;
  uvec2 farEntry = gFrag;
  for (uint i = 1u; i < gK; ++i) {
    uvec2 e = kbEntries[kbSlot(i)];
    if (kbDepth(e) > kbDepth(farEntry)) {
      far = i;
      farEntry = e;
    }
  }
  kbEntries[kbSlot(0u)] = farEntry;
  if (far != 0u) kbEntries[kbSlot(far)] = gFrag;
}
