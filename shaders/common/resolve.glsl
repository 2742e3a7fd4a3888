// Resolve driver (k+-buffer paper: Vasilakis, Papaioannou, Fudos, IEEE TVCG 21(6) 2015, §4.4) shared by
// every method that stores per-pixel lists: gather, sort, operate.
// Sorting: insertion sort for short lists, Shell sort for longer ones, and l+-depth-sorting
// (Vasilakis & Fudos, "k+-buffer: fragment synchronized k-buffer", I3D 2014, §4.4 of the TVCG 2015
// k+-buffer paper) when a pixel holds more than MFR_RESOLVE_LOCAL fragments: rounds that each
// select the next MFR_RESOLVE_LOCAL nearest fragments after the last one emitted, so no pixel
// drops fragments for lack of local memory.
//
// The including method defines, before this file:
//   uint mfrCursorBegin(ivec2 pixel);                      cursor of the first stored fragment
//   bool mfrNext(inout uint cursor, out MfrFragment f);   next fragment in storage order
// and the operation file (MFR_OP_FILE) defines OpState, opBegin, opFragment, opEnd.
// Keys are (depth, storage index), so equal depths still sort the same way on every run.
#include "common/bindings.h"
#include "common/payload.glsl"
#include MFR_OP_FILE

uniform uint uMaxListLength;  // bound on any pixel's list walk (pool or array capacity)

// Pixels whose list was not walked or composited whole. llvmpipe (Mesa) ends every loop of a shader
// invocation once its loops have taken 65,535 steps in all: pixels of ~700 fragments and more came
// out short, with exit 0 and nothing in the stats (a bug hunt). The renderer reads this count into
// the stats (overflow_pixels and a note); where it is 0, every list was resolved whole.
layout(std430, binding = MFR_SSBO_RESOLVE_CUT) buffer ResolveCut { uint mfrResolveCutPixels; };

layout(location = 0) out vec4 outColor;

MfrFragment gLocal[MFR_RESOLVE_LOCAL];
uint gIndex[MFR_RESOLVE_LOCAL];

bool keyLess(float da, uint ia, float db, uint ib) { return da < db || (da == db && ia < ib); }

void sortLocal(uint n) {
  if (n <= 16u) {
    for (uint i = 1u; i < n; ++i) {
      MfrFragment f = gLocal[i];
      uint fi = gIndex[i];
      int j = int(i) - 1;
      while (j >= 0 && keyLess(f.depth, fi, gLocal[j].depth, gIndex[j])) {
        gLocal[j + 1] = gLocal[j];
        gIndex[j + 1] = gIndex[j];
        --j;
      }
      gLocal[j + 1] = f;
      gIndex[j + 1] = fi;
    }
    return;
  }
  // Shell sort with Ciura's gaps: far fewer moves than insertion sort on 17–64 elements.
  const uint gaps[4] = uint[4](23u, 10u, 4u, 1u);
  for (int g = 0; g < 4; ++g) {
    uint gap = gaps[g];
    for (uint i = gap; i < n; ++i) {
      MfrFragment f = gLocal[i];
      uint fi = gIndex[i];
      uint j = i;
      while (j >= gap && keyLess(f.depth, fi, gLocal[j - gap].depth, gIndex[j - gap])) {
        gLocal[j] = gLocal[j - gap];
        gIndex[j] = gIndex[j - gap];
        j -= gap;
      }
      gLocal[j] = f;
      gIndex[j] = fi;
    }
  }
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  OpState s;
  opBegin(s, p);
  uint n = 0u;
  uint cursor = mfrCursorBegin(p);
  MfrFragment f;
  uint walk = min(uMaxListLength, MFR_MAX_LIST_WALK);
  // mfrNext advances the cursor: it is called once per step, in the body, never in a loop condition.
  for (uint it = 0u; it < walk; ++it) {
    if (!mfrNext(cursor, f)) break;
    if (n < uint(MFR_RESOLVE_LOCAL)) {
      gLocal[n] = f;
      gIndex[n] = n;
    }
    ++n;
  }
  // A walk that stopped before the list's end was cut short: by the loop limit, or by
  // MFR_MAX_LIST_WALK (no loop here: a loop would not run once the limit is reached).
  MfrFragment beyond;
  bool walkCut = mfrNext(cursor, beyond);
  uint emitted = 0u;
  if (n <= uint(MFR_RESOLVE_LOCAL)) {
    sortLocal(n);
    for (uint i = 0u; i < n; ++i) {
      opFragment(s, gLocal[i], i);
      ++emitted;
    }
  } else {
    // l+-depth-sorting rounds.
    float lastDepth = -1.0;
    uint lastIndex = 0u;
    bool first = true;
    uint rounds = (n + uint(MFR_RESOLVE_LOCAL) - 1u) / uint(MFR_RESOLVE_LOCAL);
    for (uint r = 0u; r < rounds; ++r) {
      uint m = 0u;  // gLocal[0..m) sorted ascending, the m nearest after the last key
      cursor = mfrCursorBegin(p);
      for (uint i = 0u; i < n; ++i) {
        if (!mfrNext(cursor, f)) break;
        if (!first && !keyLess(lastDepth, lastIndex, f.depth, i)) continue;
        if (m == uint(MFR_RESOLVE_LOCAL) &&
            !keyLess(f.depth, i, gLocal[m - 1u].depth, gIndex[m - 1u]))
          continue;
        // Insert into the sorted array, dropping its largest element when full.
        int j = int(min(m, uint(MFR_RESOLVE_LOCAL) - 1u)) - 1;
        if (m < uint(MFR_RESOLVE_LOCAL)) ++m;
        while (j >= 0 && keyLess(f.depth, i, gLocal[j].depth, gIndex[j])) {
          gLocal[j + 1] = gLocal[j];
          gIndex[j + 1] = gIndex[j];
          --j;
        }
        gLocal[j + 1] = f;
        gIndex[j + 1] = i;
      }
      for (uint i = 0u; i < m; ++i) {
        opFragment(s, gLocal[i], emitted);
        ++emitted;  // per fragment: an emission loop cut short shows
      }
      if (m == 0u) break;
      lastDepth = gLocal[m - 1u].depth;
      lastIndex = gIndex[m - 1u];
      first = false;
    }
  }
  // Not caught: a limit reached inside a round's shifts that leaves the counts whole and the order
  // wrong. A probe loop after the work would catch it, but llvmpipe runs pixels in lockstep with
  // one limit per group, so it also flagged shallow pixels beside deep ones (186 of 144 pixels).
  if (walkCut || emitted < n) atomicAdd(mfrResolveCutPixels, 1u);
  outColor = opEnd(s, p, n);
}
