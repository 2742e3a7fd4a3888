// [Multifragment rendering infrastructure — Vasilakis, Vardis, Papaioannou, "A Survey of Multifragment
// Rendering", Computer Graphics Forum 39(2), 2020.] Binding points, image units and constants shared by C++ (mfrcore) and GLSL. Valid in both:
// only #define lines. A method adds its own bindings here so that no two passes collide.
#ifndef MFR_BINDINGS_H
#define MFR_BINDINGS_H

// Vertex attributes of scene meshes
#define MFR_ATTR_POSITION 0
#define MFR_ATTR_NORMAL 1
#define MFR_ATTR_COLOR 2
#define MFR_ATTR_SCALAR 3  // Mesh::scalars: the field a surface is coloured by (0 without one)

// Uniform block with the per-frame camera
#define MFR_UBO_FRAME 0
// Uniform block with the dkb network's weights (budget/mlp_layout.h)
#define MFR_UBO_DKB_WEIGHTS 1

// Shader storage buffers
#define MFR_SSBO_NODES 0      // fragment storage (linked-list nodes, arrays, …)
#define MFR_SSBO_OFFSETS 1    // per-pixel offsets / heads
#define MFR_SSBO_COUNTER 2    // global counters (allocation, overflow, statistics)
#define MFR_SSBO_AUX 3        // method-specific extra storage
#define MFR_SSBO_SCAN 4       // prefix-sum scratch
#define MFR_SSBO_TAIL 5       // tail accumulation (hybrid transparency)
#define MFR_SSBO_DUMP 6       // debug operation: per-pixel sorted fragments (tests)
#define MFR_SSBO_DUMP_COUNT 7 // debug operation: per-pixel fragment counts (tests)
#define MFR_SSBO_LOCKS 8      // per-pixel spin-lock words kept in a buffer (variable-k buffers)
#define MFR_SSBO_ARENA 9      // per-pixel arena of the variable-k buffers (features, k(p), …)
#define MFR_SSBO_BUDGET 10    // per-frame budget state: image sums, allocation search, F(M)
#define MFR_SSBO_CSG 11       // operation "csg": per-pixel visible surface (object id, depth)
#define MFR_SSBO_RESOLVE_CUT 12  // the resolve's count of pixels whose list came out short (common/resolve.glsl)

// Image units
#define MFR_IMAGE_HEADS 0
#define MFR_IMAGE_COUNTS 1
#define MFR_IMAGE_LOCKS 2
#define MFR_IMAGE_AUX 3

// Texture units
#define MFR_TEX_DEPTH 0
#define MFR_TEX_AUX0 1
#define MFR_TEX_AUX1 2
#define MFR_TEX_AUX2 3
// Operation "volume": volume i's scalar grid (R32F, texelFetch) on unit MFR_TEX_VOLUME + i and its
// transfer-function table (RGBA32F, 1D) on MFR_TEX_VOLUME_TF + i, i < MFR_MAX_VOLUMES.
#define MFR_TEX_VOLUME 4
#define MFR_TEX_VOLUME_TF 8
// Surfaces coloured by a field (common/color_map.glsl): every colour map's table, one row per map
// (RGBA32F 2D, texelFetch), MFR_COLOR_MAP_SIZE entries evenly over the map's [0, 1] and then the
// colour of NaN at x = MFR_COLOR_MAP_SIZE.
#define MFR_TEX_COLOR_MAPS 12
#define MFR_COLOR_MAP_SIZE 256
// A surface coloured by a volume ("@NAME"): that volume's grid (R32F, texelFetch), sampled at each
// fragment (common/fragment.glsl).
#define MFR_TEX_FIELD_GRID 13
// Before interpolation each vertex's value is clamped to the range widened by this many spans on
// either side: infinities (and values so large that their differences overflow) would otherwise
// interpolate into NaN on the GPU. Beyond the range the map saturates, so colours barely change.
#define MFR_COLOR_MAP_BAND 1000.0

// Invalid index / end of a linked list
#define MFR_NIL 0xFFFFFFFFu

// Longest per-pixel list any resolve walks. A hard bound keeps every GPU loop finite. It is kept
// well below 65535 because llvmpipe (Mesa 22.3.6) miscomputed list walks whose loop bound (a
// uniform) was large — measured: wrong fragments along a screen diagonal with a bound of 65535,
// and fragments missing from l+-depth-sorting rounds (pixels with > MFR_RESOLVE_LOCAL fragments)
// with 60000 and with 16384; correct with 4096 and below (tests: DeepPixelsUseLPlusDepthSorting).
// A pixel with more fragments than this is cut off at resolve.
#define MFR_MAX_LIST_WALK 4096u

// Local array size used by the resolve pass to gather one pixel's fragments before sorting;
// longer lists are sorted in l+-depth-sorting rounds (k+-buffer paper, §4.4).
#define MFR_RESOLVE_LOCAL 64

// Image-space CSG (operation "csg"): the tree is a postfix program over a bit stack; a word holds
// the opcode in its low byte and, for a primitive, the primitive's bit (0..31) in the next byte.
#define MFR_CSG_PRIMITIVE 0u
#define MFR_CSG_UNION 1u
#define MFR_CSG_INTERSECTION 2u
#define MFR_CSG_DIFFERENCE 3u
#define MFR_CSG_MAX_PRIMITIVES 32  // inside states fit one uint
#define MFR_CSG_MAX_PROGRAM 64     // postfix words; the stack depth is at most 32 as well
// Capture payload "object": the colour word of a stored fragment holds objectId·2 + frontFacing
// (the CSG operation's classification needs them, not the colour; 8 bytes per fragment still).
#define MFR_PAYLOAD_COLOR 0
#define MFR_PAYLOAD_OBJECT 1

// Z-thickness blending (operation "zthickness"): a pixel's slabs still open at one depth are kept in
// a window of this many entries (a newer slab beyond it is merged into the newest entry, so the
// loop stays bounded); opacities are clamped below 1 so that every slab has a finite extinction
// (an opaque surface reaches 1 - 1/1024 over its thickness).
#define MFR_ZTHICK_WINDOW 16
#define MFR_ZTHICK_MAX_ALPHA (1.0 - 1.0 / 1024.0)
// Operation "volume" (shaders/ops/volume.glsl, mfr/scene/volume.hpp): the transfer function is a
// table of this many (rgb, extinction) entries; a pixel's ray takes at most MFR_VOLUME_MAX_STEPS
// steps through the volume (a longer chord gets a longer step), and marching stops once the
// transmittance is below MFR_VOLUME_MIN_TRANSMITTANCE (what is left changes no 8-bit value).
#define MFR_VOLUME_TF_SIZE 256
// At most this many volumes are drawn at once; where they overlap, their media mix (extinctions
// add, emission weighted by extinction: Kainz et al. 2009's multiple volumes).
#define MFR_MAX_VOLUMES 4
#define MFR_VOLUME_MAX_STEPS 4096
#define MFR_VOLUME_MIN_TRANSMITTANCE (1.0 / 4096.0)
#define MFR_VOLUME_MAX_ALPHA (1.0 - 1.0 / 1024.0)
// Shaded volumes (Volume::shading; Levoy, "Display of Surfaces from Volume Data", IEEE CG&A 8(3)
// 1988): a sample's emission is scaled by mix(1, AMBIENT + DIFFUSE·|n·v|, w), n the normalised
// world gradient (central differences one grid unit apart), v the ray, w = g/(g + EDGE·range) with
// g the gradient's length per grid unit and range the transfer function's [low, high]: homogeneous
// regions, whose normals are noise, stay unshaded.
#define MFR_VOLUME_AMBIENT 0.3
#define MFR_VOLUME_DIFFUSE 0.7
#define MFR_VOLUME_SHADE_EDGE 0.02
// kbuffer-zmerge: the largest k (its store pass compares all pairs of k + 1 segments).
#define MFR_ZMERGE_MAX_K 32

#endif
