// adaptive.glsl — which pixel an invocation renders: the rows of FrameParams.tile (uniform passes), or
// under adaptive sampling a live tile (side listed.x: 1-8 pixels) read from the tile list (CAUSTICA_IMAGE_TILES).

layout(r32ui, binding = CAUSTICA_IMAGE_TILES) uniform restrict readonly uimage2D tileList;

// The pixel of this invocation and whether it is inside the image and the dispatch.
bool dispatchedPixel(out uvec2 pixel) {
  uint liveTiles = frame.options.y;
  if (liveTiles == 0u) {
    uvec2 local = gl_GlobalInvocationID.xy;
    pixel = local + frame.tile.xy;
    return all(lessThan(local, frame.tile.zw)) && all(lessThan(pixel, frame.frame.xy));
  }
  // Adaptive: each work group samples 64 / side^2 consecutive entries of the tile list, side^2
  // invocations per tile (side 8: one tile, the invocation's local position in it).
  uint side = frame.listed.x;
  uint perTile = side * side;
  uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;  // 2D grid past 65535 groups
  uint index = group * (uint(CAUSTICA_WORKGROUP_X * CAUSTICA_WORKGROUP_Y) / perTile) + gl_LocalInvocationIndex / perTile;
  uint within = gl_LocalInvocationIndex % perTile;
  uint entry = index < liveTiles
                    ? imageLoad(tileList, ivec2(index % CAUSTICA_TILE_LIST_WIDTH, index / CAUSTICA_TILE_LIST_WIDTH)).r
                    : 0u;
  uvec2 tile = uvec2(entry & 0xffffu, entry >> 16u);
  pixel = tile * side + uvec2(within % side, within / side);
  return index < liveTiles && all(lessThan(pixel, frame.frame.xy));
}
