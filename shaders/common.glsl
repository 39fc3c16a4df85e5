// Shared by the feature kernels: pixel groups, packed pixels, border rules and orientation
// bins. The C++ twins live in src/match/border.hpp and src/match/*_reference.cpp.
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_samplerless_texture_functions : require
#include "gpu/kernel_interface.h"

// The constants and push constants these kernels share with their hosts: kernel_interface.h.
//
// Sliding-window kernels take kPixelGroup neighbouring outputs per invocation: neighbours share
// most of their inputs. On llvmpipe a load from a storage buffer at a per-invocation
// offset, and a store, is a loop over the lanes (a texel fetch is a gather), so the feature
// kernels read their inputs as texel buffers and take several pixels per load and store:
// colour as packed BGRX words, labels 4 to a word. The loops over a group carry [[unroll]]:
// their small arrays must be indexed by constants, an indexed local array being a loop
// over the lanes too.

// Invocation i's group of kPixelGroup neighbouring pixels of one row of a width x height image:
// row y, first column x0. False past the last group (the dispatch rounds up).
bool rowGroup(int i, int width, int height, out int y, out int x0) {
  int per_row = (width + kPixelGroup - 1) / kPixelGroup;
  y = i / per_row;
  x0 = (i - y * per_row) * kPixelGroup;
  return i < per_row * height;
}

// Invocation i's group of kPixelGroup neighbouring rows of one column of a width x height image
// (width counts elements: 3 per pixel for a colour image): first row y0, column x. False past
// the last group.
bool columnGroup(int i, int width, int height, out int y0, out int x) {
  y0 = i / width * kPixelGroup;
  x = i - i / width * width;
  return i < (height + kPixelGroup - 1) / kPixelGroup * width;
}

// Colour pixels are packed BGRX words (byte 0 blue, 1 green, 2 red, 3 unused). Sums of them
// under weights that total at most 256 fit 16-bit lanes, so the filters split a word into
// its even bytes (blue, red) and odd bytes (green, unused) and sum all channels at once.
uint evenLanes(uint bgrx) { return bgrx & 0x00FF00FFu; }
uint oddLanes(uint bgrx) { return (bgrx >> 8u) & 0x00FF00FFu; }
// Back to a packed word from lane sums, each shifted right by `shift`.
uint fromLanes(uint even, uint odd, uint shift) {
  return ((even >> shift) & 0x00FF00FFu) | (((odd >> shift) & 0x00FF00FFu) << 8u);
}

// Label images (orientation bins, labels, spread labels) are packed 4 pixels per word, rows
// of wordsPerRow(width) words, byte x % 4 of word x / 4 holding pixel x; the bytes past the
// width are 0. Kernels on them take a word (4 neighbouring pixels) per invocation: one fetch
// and one store instead of four.
int wordsPerRow(int width) { return (width + 3) / 4; }

// Invocation i's word of a label image: row y, first pixel x0 (a multiple of 4). False past
// the last word.
bool rowWord(int i, int width, int height, out int y, out int x0) {
  int per_row = wordsPerRow(width);
  y = i / per_row;
  x0 = (i - y * per_row) * 4;
  return i < per_row * height;
}

uint byteOf(uint word, int b) { return (word >> (8u * uint(b))) & 0xFFu; }

// The bytes of the word at x0 that lie inside a row of `width` pixels.
uint insideBytes(int x0, int width) { return width - x0 >= 4 ? 0xFFFFFFFFu : (1u << (8u * uint(width - x0))) - 1u; }

// The words at pixels x0 - 4, x0 and x0 + 4 of row `row` (its first word) of a packed label
// image of `per_row` words a row, indices clamped to the row: what clampedByte reads.
uvec3 wordsAround(utextureBuffer image, int row, int x0, int per_row) {
  int xw = x0 / 4;
  return uvec3(texelFetch(image, row + max(xw - 1, 0)).x, texelFetch(image, row + xw).x,
               texelFetch(image, row + min(xw + 1, per_row - 1)).x);
}

// Pixel clamp(x, 0, width - 1) of a packed row, given its words around x0 (wordsAround;
// x0 a multiple of 4; x within x0 - 4 .. x0 + 7): BORDER_REPLICATE for windows of radius up
// to 4 around the word at x0.
uint clampedByte(uvec3 words, int x, int x0, int width) {
  int t = clamp(x, 0, width - 1) - x0;
  return byteOf(t < 0 ? words.x : t < 4 ? words.y : words.z, t & 3);
}

// BORDER_REPLICATE
int clampIndex(int i, int n) { return clamp(i, 0, n - 1); }

// BORDER_REFLECT_101
int reflect101Index(int i, int n) {
  if (n == 1) return 0;
  while (i < 0 || i >= n) i = i < 0 ? -i : 2 * n - 2 - i;
  return i;
}

// Gradient orientation bin, sign ignored, bins centred on k * 22.5 degrees: exact integer
// comparisons with tan(edge) * 2^19 (see gradientOrientationBin in C++).
int gradientOrientationBin(int gx, int gy) {
  if (gy == 0) return 0;
  if (gy < 0 || (gy == 0 && gx < 0)) {
    gx = -gx;
    gy = -gy;
  }
  uint ax = uint(abs(gx));
  uint sy = uint(gy) << 19;
  int b = (sy >= ax * 104287u ? 1 : 0) + (sy >= ax * 350318u ? 1 : 0) + (sy >= ax * 784652u ? 1 : 0) +
          (sy >= ax * 2635774u ? 1 : 0);
  return gx >= 0 ? b : (8 - b) & 7;
}

// Depth normal bin, 45-degree sectors centred on k * 45 degrees (see normalOrientationBin).
int normalOrientationBin(int ddx, int ddy) {
  if (ddx == 0 && ddy == 0) return 0;
  precise float ax = float(abs(ddx));
  precise float ay = float(abs(ddy));
  precise float e1 = ax * 0.41421356;
  precise float e2 = ax * 2.41421356;
  int b = (ay >= e1 ? 1 : 0) + (ay >= e2 ? 1 : 0);
  if (ddx >= 0) return ddy >= 0 ? b : (8 - b) & 7;
  return ddy >= 0 ? 4 - b : 4 + b;
}

// Index of this invocation in a one-dimensional kernel dispatched as rows of
// gl_NumWorkGroups.x workgroups (gpu::Batch::dispatchLinear): a 12-Mpixel image needs more
// workgroups than one dimension of a dispatch may have (65535 on lavapipe). A macro, so that
// gl_WorkGroupSize is read after the shader has declared its local size.
#define LINEAR_INVOCATION \
  int(gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x)
