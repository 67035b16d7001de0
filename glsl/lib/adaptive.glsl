// adaptive.glsl — which pixel an invocation renders: the rows of FrameParams.tile (uniform passes), or
// under adaptive sampling one 8x8 work group per live tile read from the tile list (CAUSTICA_IMAGE_TILES).

layout(r32ui, binding = CAUSTICA_IMAGE_TILES) uniform restrict readonly uimage2D tileList;

// The pixel of this invocation and whether it is inside the image and the dispatch.
bool dispatchedPixel(out uvec2 pixel) {
  uint liveTiles = frame.options.y;
  if (liveTiles == 0u) {
    uvec2 local = gl_GlobalInvocationID.xy;
    pixel = local + frame.tile.xy;
    return all(lessThan(local, frame.tile.zw)) && all(lessThan(pixel, frame.frame.xy));
  }
  uint index = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;  // 2D grid past 65535 groups
  uint entry = index < liveTiles
                    ? imageLoad(tileList, ivec2(index % CAUSTICA_TILE_LIST_WIDTH, index / CAUSTICA_TILE_LIST_WIDTH)).r
                    : 0u;
  uvec2 tile = uvec2(entry & 0xffffu, entry >> 16u);
  pixel = tile * uvec2(CAUSTICA_WORKGROUP_X, CAUSTICA_WORKGROUP_Y) + gl_LocalInvocationID.xy;
  return index < liveTiles && all(lessThan(pixel, frame.frame.xy));
}
