// gpu_layout.h — every struct and binding index shared by the host (C++) and the shaders (GLSL).
// Compiled as C++ (with static_asserts on sizes) and included by GLSL, so layouts cannot drift.
// All SSBO structs use std430 rules; every member is a vec4/uvec4 or a 4-byte scalar in a 16-byte group.
#ifndef CAUSTICA_GPU_LAYOUT_H
#define CAUSTICA_GPU_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace caustica::gpu {
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using uint = std::uint32_t;
#define CAUSTICA_CONST static constexpr
#else
#define CAUSTICA_CONST const
#endif

// ---- binding indices (macros: GLSL 4.30 layout qualifiers take only literals) -------------------
#define CAUSTICA_BINDING_NODES 0      // buffer of BvhNode[]; the shaders read it through CAUSTICA_TEXUNIT_BVH_NODES, not as an SSBO
#define CAUSTICA_BINDING_TRIGEOM 1    // buffer of TriGeom[] (BVH leaf order); read through CAUSTICA_TEXUNIT_TRI_GEOM, not as an SSBO
#define CAUSTICA_BINDING_TRISHADE 2   // uint[] shading words per triangle (same order as TriGeom; kTriShadeWords): read through
                                      // CAUSTICA_TEXUNIT_TRI_SHADE, or as SSBOs when split over several blocks
#define CAUSTICA_BINDING_MATERIALS 3  // buffer of Material[]; read through CAUSTICA_TEXUNIT_MATERIALS, not as an SSBO
#define CAUSTICA_BINDING_EMITTERS 4   // buffer of LightNode[] (light tree over emissive triangles); read through CAUSTICA_TEXUNIT_LIGHT_NODES
#define CAUSTICA_BINDING_TEXELS 5     // buffer of uint[]: TexInfo records (kTexInfoWords each), then RGBA8 texels, sRGB-encoded;
                                      // read through CAUSTICA_TEXUNIT_TEXELS and CAUSTICA_TEXUNIT_TEX_INFO
#define CAUSTICA_BINDING_COUNTERS 6   // SSBO: Counters (atomic statistics)
#define CAUSTICA_SSBO_COUNT 7         // buffers the path tracer binds (bindings 0-6; 0 and 1 are read as textures)
#define CAUSTICA_BINDING_SPLIT_FIRST 7  // first binding of the extra parts of split arrays (split_buffers.glsl)
#define CAUSTICA_MAX_SPLIT_PARTS 4    // storage blocks the TriShade words may be split into
#define CAUSTICA_BINDING_FRAME 0      // UBO: FrameParams
#define CAUSTICA_BINDING_CASTERS 1    // UBO: CasterParams (a UBO: GL 4.3 guarantees only 8 SSBOs per shader)
#define CAUSTICA_BINDING_ENVIRONMENT 3  // UBO: EnvironmentParams (environment map size, rotation, background)
#define CAUSTICA_TEXUNIT_ENV_MAP 0      // texture unit: rgba32f environment map (rgb radiance, a conditional CDF)
#define CAUSTICA_TEXUNIT_ENV_MARGINAL 1 // texture unit: rgba32f height x 1 (r: marginal CDF over rows)
#define CAUSTICA_TEXUNIT_BVH_NODES 2   // texture unit: buffer texture (rgba32ui) over the nodes SSBO's buffer, 4 texels per BvhNode
#define CAUSTICA_TEXUNIT_TRI_GEOM 3    // texture unit: buffer texture (rgba32ui) over the TriGeom buffer, 3 texels per triangle
#define CAUSTICA_TEXUNIT_BVH_WIDE 6    // texture unit: buffer texture (rgba32ui) over the BvhWideNode buffer, 7 texels per node
// The shading reads go through buffer textures too (app/gpu/shading_textures.*): on llvmpipe a texelFetch
// is a vector gather, an SSBO load a loop over the SIMD lanes (docs/architecture.md, "Writing shaders for llvmpipe").
#define CAUSTICA_TEXUNIT_MATERIALS 4   // texture unit: buffer texture (rgba32ui) over the materials buffer, 12 texels per Material
#define CAUSTICA_TEXUNIT_LIGHT_NODES 5 // texture unit: buffer texture (rgba32ui) over the light-tree buffer, 4 texels per LightNode
#define CAUSTICA_TEXUNIT_TEXELS 7      // texture unit: buffer texture (r32ui) over the texel buffer, one word per texel
#define CAUSTICA_TEXUNIT_TEX_INFO 8    // texture unit: buffer texture (rgba32ui) over the same buffer, 3 texels per TexInfo
#define CAUSTICA_TEXUNIT_TRI_SHADE 9   // texture unit: buffer texture (rgb32ui) over the TriShade buffer (unless split), 3 words per texel
#define CAUSTICA_MAX_CASTERS 8        // caustic casters the shader can aim at (CasterParams.sphere[])
#define CAUSTICA_TEXUNIT_CELL_KEYS 10   // texture unit: buffer texture (rgba32ui) over the caustic cell table's keys (manifold NEE)
#define CAUSTICA_TEXUNIT_CELLS 11       // texture unit: buffer texture (rgba32ui) over its CausticCell slots
#define CAUSTICA_TEXUNIT_GUIDE_KEYS 12  // texture unit: buffer texture (rgba32ui) over the caster guide table's keys (guiding)
#define CAUSTICA_TEXUNIT_GUIDE_CELLS 13 // texture unit: buffer texture (rgba32ui) over its CausticCell slots
#define CAUSTICA_BINDING_CELL_KEYS 0    // caustic_photons.comp only: SSBO of the cell table's keys (atomic compare-and-swap)
#define CAUSTICA_BINDING_CELLS 1        // caustic_photons.comp only: SSBO of CausticCell words (atomic adds)
#define CAUSTICA_BINDING_CELL_DROPS 2   // caustic_photons.comp only: SSBO: photons whose cell found no free slot
#define CAUSTICA_BINDING_PHOTON_EMITTERS 3  // caustic_photons.comp only: SSBO of uvec2 per caster and emitter (photonEmitterTable)
#define CAUSTICA_BINDING_LIGHT_SPLATS 0  // light_trace.comp only: SSBO of the light tracer's splats (kLightSplatWords, below)
#define CAUSTICA_TEXUNIT_LIGHT_SPLATS 14 // texture unit: buffer texture (rgb32ui) over the same buffer, read by pathtrace.comp
#define CAUSTICA_BINDING_POINT_LIGHTS 2  // UBO: PointLights (raster and Whitted modes, docs/render-modes.md)
#define CAUSTICA_MAX_POINT_LIGHTS 8   // emitter groups the raster and Whitted modes light with
#define CAUSTICA_BINDING_PUNCTUAL 4   // UBO: PunctualParams (KHR_lights_punctual; a UBO, not a ninth SSBO)
#define CAUSTICA_MAX_PUNCTUAL 128     // punctual lights a scene may have (PunctualParams.light[], 8 KiB)
#define CAUSTICA_IMAGE_ACCUM 0        // image unit: rgba32f running sum of radiance
#define CAUSTICA_IMAGE_COMP 1         // image unit: rgba32f Kahan compensation of the sum
#define CAUSTICA_IMAGE_DISPLAY 2      // image unit: rgba8 tone-mapped display image
#define CAUSTICA_IMAGE_HALF 3         // image unit: rgba32f sum (rgb) and count (a) of each pixel's odd-numbered samples (error estimate)
#define CAUSTICA_IMAGE_TILES 4        // image unit: r32ui list of live tiles (adaptive sampling), x | y << 16 in tiles
#define CAUSTICA_IMAGE_COVERAGE 5     // image unit: r32f samples whose camera ray hit the scene (--background transparent)
#define CAUSTICA_IMAGE_ALBEDO 6       // image unit: rgba32f feature sums (CAUSTICA_AOV): albedo (rgb), luminance^2 (a)
#define CAUSTICA_IMAGE_NORMAL 7       // image unit: rgba32f feature sums (CAUSTICA_AOV): shading normal (xyz), distance (w)
// The denoiser's image units (denoise.comp, its own program; docs/denoising.md).
#define CAUSTICA_DENOISE_IMAGE_ACCUM 0   // rgba32f accumulation sums (read)
#define CAUSTICA_DENOISE_IMAGE_ALBEDO 1  // rgba32f feature sums: albedo, luminance^2 (read by the prepare stage)
#define CAUSTICA_DENOISE_IMAGE_FILTERED 1  // rgba32f the filter passes' last output (read by the residual passes)
#define CAUSTICA_DENOISE_IMAGE_NORMAL 2  // rgba32f feature sums: normal, distance (read by the prepare stage)
#define CAUSTICA_DENOISE_IMAGE_MOMENTS 2 // rgba32f feature sums: albedo, luminance^2 (read by the last residual pass)
#define CAUSTICA_DENOISE_IMAGE_PING 3    // rgba32f demodulated illumination (rgb) and variance of the mean (a), or
                                         // the residual (rgb), read by a pass
#define CAUSTICA_DENOISE_IMAGE_PONG 4    // the same, written by a pass (and by prepare)
#define CAUSTICA_DENOISE_IMAGE_GUIDE 5   // rgba32f unit mean normal (xyz; 0: none) and mean distance (w; -1: no samples)
#define CAUSTICA_DENOISE_IMAGE_CENTRE 6  // rgba32f albedo (rgb, floored) and distance gradient (a)
#define CAUSTICA_DENOISE_IMAGE_OUTPUT 7  // rgba32f denoised sums (rgb = mean x count, a = count), or the residual
                                         // the last filter pass writes
#define CAUSTICA_TILE_LIST_WIDTH 1024 // texels per row of the live-tile list image
#define CAUSTICA_WORKGROUP_X 8        // compute work-group size in pixels
#define CAUSTICA_WORKGROUP_Y 8
#define CAUSTICA_BVH_STACK 64         // traversal stack entries; the builder guarantees depth < this
#define CAUSTICA_BVH_WIDE_STACK 192   // 4-wide traversal stack entries: <= 3 pushes per binary level, checked by packBvhWideNodes

CAUSTICA_CONST uint kInvalidIndex = 0xffffffffu;

// Material flags (Material.flags)
CAUSTICA_CONST uint kMatDoubleSided = 1u;
CAUSTICA_CONST uint kMatHasVolume = 2u;      // Beer–Lambert absorption inside (KHR_materials_volume)
CAUSTICA_CONST uint kMatDispersive = 4u;     // KHR_materials_dispersion with dispersion > 0
// A --light-radius sphere made from a spot light: emission is weighted by spotFalloff of the direction
// it leaves in; absorption.xyz holds the spot axis, absorption.w cos(outer cone), emission.w cos(inner).
CAUSTICA_CONST uint kMatSpotEmitter = 256u;

// PunctualLight.position.w: the light's type
CAUSTICA_CONST uint kPunctualPoint = 0u;
CAUSTICA_CONST uint kPunctualSpot = 1u;
CAUSTICA_CONST uint kPunctualDirectional = 2u;
CAUSTICA_CONST uint kMatAlphaTexture = 8u;   // alphaMode BLEND or MASK: the base-colour texture's alpha multiplies baseColor.a
CAUSTICA_CONST uint kMatAlphaMask = 16u;     // alphaMode MASK with a texture or vertex alpha: opaque where alpha >= cutoff (tex2.w), else absent
CAUSTICA_CONST uint kMatVertexAlpha = 32u;   // alphaMode BLEND or MASK in a scene with vertex colours: COLOR_0's alpha multiplies baseColor.a

// EnvironmentParams.size.z: what camera rays that leave the scene see
CAUSTICA_CONST uint kBackgroundEnvironment = 0u;  // the environment (black if there is none)
CAUSTICA_CONST uint kBackgroundColor = 1u;        // EnvironmentParams.background.rgb
CAUSTICA_CONST uint kBackgroundTransparent = 2u;  // nothing: radiance 0 and alpha 0

// ---- SSBO structs ----------------------------------------------------------------------------
// 64-byte BVH node (Aila & Laine 2009 style): the boxes of BOTH children live in the parent, so one
// node fetch (4 RGBA32UI texels of the texture buffer CAUSTICA_TEXUNIT_BVH_NODES) decides which
// children a ray enters. nodes[0] is the root. A child reference (left, right) is either an inner
// node's index (bit 31 clear) or a leaf packed as kBvhLeafBit | count << kBvhCountShift | first
// triangle (count 1..kBvhMaxLeafSize triangles triGeom[first .. first + count - 1]); an empty slot
// (empty scene; the second child of a one-leaf tree) is a leaf of count 0, kBvhEmptyRef.
struct BvhNode {
  vec3 lmin;      // left child's world-space AABB minimum
  uint left;      // left child reference
  vec3 lmax;      // left child's AABB maximum
  uint reserved0; // 0
  vec3 rmin;      // right child's AABB minimum
  uint right;     // right child reference
  vec3 rmax;      // right child's AABB maximum
  uint reserved1; // 0
};
CAUSTICA_CONST uint kBvhLeafBit = 0x80000000u;
CAUSTICA_CONST uint kBvhCountShift = 27u;
CAUSTICA_CONST uint kBvhFirstMask = 0x07ffffffu;  // first triangle of a leaf: < 2^27
CAUSTICA_CONST uint kBvhMaxLeafSize = 15u;         // 4 bits of count
CAUSTICA_CONST uint kBvhEmptyRef = 0x80000000u;    // a leaf of no triangles

// 112-byte 4-wide BVH node (7 RGBA32 texels of the buffer texture CAUSTICA_TEXUNIT_BVH_WIDE), made by
// collapsing the binary SAH tree (app/accel/bvh_wide.*): the boxes of up to four children, stored
// structure-of-arrays (component k of each vector is child k) so one node fetch tests all four slabs
// with vec4 arithmetic. child[k] is a ref as in BvhNode (inner node index, or a packed leaf); an
// unused slot is kBvhEmptyRef with the box (+inf, +inf) on every axis, which no ray enters.
// Children are packed in no particular order; the traversal sorts them by entry distance.
struct BvhWideNode {
  vec4 minX;    // children's world-space AABB minimum x
  vec4 maxX;    // maximum x
  vec4 minY;
  vec4 maxY;
  vec4 minZ;
  vec4 maxZ;
  uvec4 child;  // child refs (kBvhLeafBit: leaf; kBvhEmptyRef: unused slot)
};

// Instancing (docs/instancing.md): one record per instance, in
// top-level leaf order, 64 bytes = 4 RGBA32 texels, meant to follow the BVH nodes in their buffer
// texture. The top-level BVH's leaves are single instances (count 1, first = record index); a
// bottom-level BVH's nodes and triangles are rebased into the shared node and TriGeom arrays.
struct InstanceRecord {
  vec4 row0;      // world-to-object affine map, row 0: dot(row0.xyz, p) + row0.w
  vec4 row1;      // row 1
  vec4 row2;      // row 2 (normals back to world space: transpose of this 3x3, then normalize)
  uint root;      // the mesh's bottom-level root node (index into the shared node array)
  uint mesh;      // Scene::meshes index
  uint sceneInstance;  // Scene::instances index
  uint flags;     // 0 (reserved)
};

// Shading data of one instance (64 bytes = 4 texels), indexed by Scene::instances index: in the node
// buffer texture at node index CAUSTICA_INSTANCE_RECORD_BASE + CAUSTICA_INSTANCE_COUNT + instance,
// after the InstanceRecords (glsl/lib/instances.glsl). Then, from texel CAUSTICA_LIGHT_LEAF_TABLE on,
// the light-leaf table: one uint per (instance, emissive triangle of its mesh), 4 per texel, the
// light-tree leaf node of that emitter (kInvalidIndex: not in the tree, zero power).
struct InstanceShade {
  vec4 row0;           // object-to-world affine map (rebased on Scene::origin), row 0: dot(row0.xyz, p) + row0.w
  vec4 row1;           // row 1
  vec4 row2;           // row 2
  uint lightLeafBase;  // the instance's first entry in the light-leaf table (emissive meshes; else 0)
  uint flags;          // kInstanceMirrored: negative determinant (corners 1 and 2 swap, as flattenInstances)
  uint reserved0;      // 0
  uint reserved1;      // 0
};
CAUSTICA_CONST uint kInstanceMirrored = 1u;

// Triangle positions for intersection (48 bytes). A zero-area triangle is stored as one point, v0.xyz
// three times (packedTrianglePositions, app/accel/bvh.h): the GLSL test rejects it by det == 0.
struct TriGeom {
  vec4 v0;  // xyz: vertex 0 (world space); w: material index (stored as float bits of a uint)
  vec4 v1;  // xyz: vertex 1; w: emissive triangles: light-tree leaf index + 1 (uint bits), else 0;
            // instanced scenes (object-space vertices): index among its mesh's emissive triangles + 1
  vec4 v2;  // xyz: vertex 2; w unused
};

// Triangle shading attributes, fetched only for the closest hit (glsl/lib/tri_shade.glsl): the TriShade
// SSBO is a uint[] in TriGeom order, per triangle the normals and then only the blocks the scene needs
// (TriShadeLayout in app/accel/gpu_scene.h; the defines CAUSTICA_TRISHADE_TEXCOORDS, _COLORS, _TANGENTS):
//   3 words, always: vertex normals 0..2 (world space, unit), octahedral, packSnorm2x16 (octEncode);
//               kOctZeroNormal: no normal (the geometric normal is used)
//   6 words, textured scenes: texcoords u0, v0, u1, v1, u2, v2 (float bits)
//   6 words, scenes with vertex colours (COLOR_0): corner k's packHalf2x16(r, g), packHalf2x16(b, a)
//   3 words, scenes with TANGENTs on normal-mapped meshes: corner k's unit tangent (world space),
//               octahedral, with bit 0 set where the bitangent sign w is negative; kOctZeroNormal: none
// Every block a multiple of 3 words (one RGB32UI texel). 12 bytes per triangle without textures, 36 with.
CAUSTICA_CONST uint kTriShadeWords = 3u;
CAUSTICA_CONST uint kTriShadeWordsTextured = 9u;
CAUSTICA_CONST uint kTriShadeTexcoordWords = 6u;
CAUSTICA_CONST uint kTriShadeColorWords = 6u;
CAUSTICA_CONST uint kTriShadeTangentWords = 3u;
CAUSTICA_CONST uint kOctZeroNormal = 0x80008000u;  // snorm -32768 twice: never produced by octEncode

// Material after the glTF material contract (docs/materials.md), 192 bytes: the first seven texels are
// read at every hit; the last five only by shaders with a layer (clear coat, sheen) or the specular and
// transmission textures (materialAt, bindings.glsl).
struct Material {
  vec4 baseColor;     // rgb: linear base colour factor; a: opacity (1 = opaque)
  vec4 emission;      // rgb: emitted radiance (linear, W sr^-1 m^-2 relative units); w: unused
  vec4 params;        // x: metallic (metal weight), y: roughness (GGX alpha = y^2), z: transmission, w: ior at 587.6 nm
  vec4 absorption;    // rgb: absorption coefficient sigma_a per scene unit (Beer–Lambert); w: abbe number V (0 = none)
  uvec4 tex;          // x: base-colour texture index, y: emissive texture index (kInvalidIndex = none), z: flags, w unused
  vec4 specular;      // rgb: F0 of the dielectric specular layer over the diffuse base; w: its F90 (0 = Lambertian base)
  uvec4 tex2;         // x: metallicRoughness texture, y: normal texture (kInvalidIndex = none); z: normal scale,
                      // w: alpha cutoff (both float bits)
  vec4 coat;          // KHR_materials_clearcoat: x: weight (0 = none), y: roughness (GGX alpha = y^2), z: its normal
                      // map's scale, w: unused
  vec4 sheen;         // KHR_materials_sheen: rgb: sheen colour (linear; 0 = none), w: sheen roughness
  uvec4 tex3;         // textures: x: clearcoat (R), y: clearcoat roughness (G), z: clearcoat normal map,
                      // w: sheen colour (RGB, sRGB)
  uvec4 tex4;         // textures: x: sheen roughness (A), y: specular (A), z: specular colour (RGB, sRGB),
                      // w: transmission (R)
  vec4 specularBase;  // with a specular texture: rgb: ((ior - 1) / (ior + 1))^2 x specularColorFactor (unclamped),
                      // w: specularFactor: F0 = min(rgb x colour texture, 1) x w x texture A, F90 = w x texture A
};
CAUSTICA_CONST uint kMaterialTexels = 12u;  // RGBA32 texels per Material in its buffer texture

// A texture inside the texel SSBO (48 bytes, stored as kTexInfoWords uints at the head of that SSBO).
// Several may share texels (KHR_texture_transform).
struct TexInfo {
  uint offset;   // first texel in the texel SSBO (GpuScene::texels; the SSBO adds the records in front)
  uint width;    // texels
  uint height;   // texels
  uint flags;    // bit 0: repeat S (else clamp), bit 1: repeat T, bit 2: mirrored S, bit 3: mirrored T, bit 4: nearest filter
  vec4 uvRow0;   // xyz: u' = dot(xyz, (u, v, 1)) (KHR_texture_transform; identity (1, 0, 0)); w unused
  vec4 uvRow1;   // xyz: v' = dot(xyz, (u, v, 1)) (identity (0, 1, 0)); w unused
};

CAUSTICA_CONST uint kTexInfoWords = 12u;

// Statistics the shader writes atomically.
struct Counters {
  uint nonFinite;      // samples rejected because they were NaN or Inf
  uint primaryRays;    // eye rays traced
  uint secondaryRays;  // bounce rays traced
  uint shadowRays;     // next-event-estimation visibility rays traced
};

// One node of the light tree over the emissive triangles (64 bytes; app/accel/light_tree.h,
// glsl/lib/light_tree.glsl): a binary BVH whose nodes bound the position, power and emission
// directions of their triangles (Conty Estevez & Kulla 2018). Node 0 is the root; one triangle per leaf.
struct LightNode {
  vec4 boundsMin;  // xyz: world-space AABB minimum; w: power (sum of luminance(emission) * area * sides)
  vec4 boundsMax;  // xyz: world-space AABB maximum; w: cos(theta_o), the normal cone's half angle
  vec4 axis;       // xyz: unit axis of the normal cone; w: cos(theta_e), emission spread beyond the normals (0: cosine)
  uvec4 link;      // x: inner: left child (right = x + 1); leaf: triangle (TriGeom order); y: kLightNode* flags;
                   // z: leaf: bit trail from the root (bit d set: right child at depth d); w: leaf: depth
};
CAUSTICA_CONST uint kLightNodeLeaf = 1u;       // LightNode.link.y: a leaf (one triangle)
CAUSTICA_CONST uint kLightNodeTwoSided = 2u;   // LightNode.link.y: some triangle below emits from both faces
CAUSTICA_CONST uint kLightNodeInstanceShift = 2u;  // instanced scenes: a leaf's link.y >> this = its Scene::instances index
#define CAUSTICA_LIGHT_TREE_DEPTH 32           // bits of the trail: the builder keeps every leaf's depth <= this

// ---- UBO ---------------------------------------------------------------------------------------
// Per-dispatch parameters (std140: vec4/uvec4 only).
struct FrameParams {
  vec4 camPos;      // xyz: eye position (world space)
  vec4 camRight;    // xyz: right axis scaled by tan(yfov/2) * aspect (orthographic: half the image width)
  vec4 camUp;       // xyz: up axis scaled by tan(yfov/2) (orthographic: half the image height, scene units)
  vec4 camForward;  // xyz: unit viewing direction; w: 1 for an orthographic camera, else 0
  uvec4 frame;      // x: width, y: height, z: index of the first sample of this dispatch, w: seed
  uvec4 options;    // x: max depth, y: live tiles in the tile list (0: the dispatch covers `tile`; else one
                    //    8x8 work group per 64 / side^2 listed tiles, adaptive sampling), z: emitter count, w: samples per pixel
                    //    of this dispatch (pathtrace.comp; indices z .. z + w - 1; the integrator and dispersion
                    //    mode are shader variants, not flags)
  uvec4 tile;       // x, y: pixel offset of this dispatch's tile; z, w: tile size
  uvec4 listed;     // x: side of the listed tiles in pixels (1, 2, 4 or 8; adaptive.glsl), yzw unused
  // (A vec4 `lights`, the total emitter weight, was uploaded here and read by no shader since the light
  // tree: removed.)
};

// The light tracer's splats (light_trace.comp writes them, pathtrace.comp reads them): for each sample
// index of a dispatch (slot s) and pixel (x, y), kLightSplatWords words from word kLightSplatWords *
// ((s * height + y) * width + x): the low 32 bits of the r, g, b sums, then their high 32 bits. Each sum
// is a 64-bit fixed-point count of steps of CasterParams.params.w (radiance).
CAUSTICA_CONST uint kLightSplatWords = 6u;

// Caustic casters: bounding spheres of the scene's specular objects (glass, mirrors), aimed at from
// diffuse surfaces by the mis integrator so that caustic paths are found more often (std140).
// A refractive caster is aimed at only from points that see it overlap the lights (within a margin):
// the shadow side, where its caustic falls. Mirrors reflect light anywhere and are always aimed at.
struct CasterParams {
  uvec4 count;                            // x: spheres in use (0..CAUSTICA_MAX_CASTERS); y: bit i set = sphere i refracts;
                                          // z: buckets of the caustic cell table - 1 (a power of 2 minus 1; manifold NEE,
                                          // caustic_cells.glsl), 0: no table; w: bit i set = the photon pass sends
                                          // photons to sphere i (manifoldCasterMask; caustic_photons.comp only)
  uvec4 guide;                            // x: buckets of the caster guide table - 1 (caster guiding, caustic_cells.glsl),
                                          // 0: no table; y: bit i set = the guide photon pass sends photons to
                                          // sphere i (guideCasterMask; caustic_photons.comp only); z: bit i set = a
                                          // diffuse bounce may aim at sphere i's cone (aimCasterMask); w unused
  vec4 params;                            // x: probability of aiming at a caster at a diffuse vertex; y: margin (radians);
                                          // z: probability that an aimed bounce follows a caster's guide lobe; w: radiance
                                          // of one step of the light tracer's fixed-point splats (light_trace.glsl)
  vec4 lights;                            // xyz: centre, w: radius of a sphere around every emitter (world space)
  vec4 sphere[CAUSTICA_MAX_CASTERS];      // xyz: centre (world space), w: radius (scene units)
};

// The caustic cell tables (glsl/lib/caustic_cells.glsl, app/gpu/caustic_cells.h), manifold NEE's and caster
// guiding's (the same layout; guiding's photons follow any chain of smooth events and count for the
// caster of their last one, CasterParams.guide): a hash
// table of receiver cells, each caster's cubes of kCellPerRadius times its radius, keyed by caster and
// cell. Buckets of 4 keys (one uvec4 each; key 0: empty); each slot's CausticCell holds what the
// caster's photons brought there (uint words, written with atomics by caustic_photons.comp): their
// count and the sum of their directions back towards the caster's last vertex, each a unit vector
// times kCellDirScale rounded (int bits).
struct CausticCell {
  uint count;
  uint dirX, dirY, dirZ;
};
CAUSTICA_CONST float kCellDirScale = 1024.0;
CAUSTICA_CONST float kCellPerRadius = 0.125;  // a cell's side over its caster's bounding radius

// The environment light (scene/environment.h; glsl/lib/environment.glsl), std140. Its texels and
// CDFs live in two textures (CAUSTICA_TEXUNIT_ENV_*): no ninth SSBO.
struct EnvironmentParams {
  uvec4 size;        // x, y: map width and height in texels (0 = no environment); z: kBackground*; w unused
  vec4 rotation;     // x, y: cos and sin of the map's rotation about +Y; zw unused
  vec4 background;   // rgb: linear radiance camera rays see for kBackgroundColor; a unused
};

// The raster and Whitted modes light the scene with point lights: the emissive triangles grouped
// into at most CAUSTICA_MAX_POINT_LIGHTS lights at their power-weighted centres (app/scene/light_groups.h).
// Radiant intensity towards unit direction w (from the light): intensity.rgb * (max(0, dot(axis.xyz, w)) + position.w),
// so a flat one-sided emitter keeps its cosine lobe and a closed one shines evenly; a spot light
// (cone.z = 1) gives intensity.rgb * spotFalloff(dot(axis.xyz, w), cone.x, cone.y) instead (std140).
// KHR_lights_punctual lights join the groups: point (axis 0, position.w 1), spot, and directional
// (a point far away, docs/render-modes.md).
struct PointLight {
  vec4 position;   // xyz: world-space position; w: isotropic part of the lobe (0 flat .. 1/4 closed)
  vec4 intensity;  // rgb: sum of emitted radiance * area (* 2 if double-sided); w: shadow far distance (scene units)
  vec4 axis;       // xyz: mean emitter normal, length = the flat part of the lobe (0..1); spot: unit cone axis; w: unused
  vec4 cone;       // spot only: x: cos(outer cone), y: cos(inner cone), z: 1 (else 0); w: unused
};
struct PointLights {
  uvec4 count;                                  // x: lights in use (0..CAUSTICA_MAX_POINT_LIGHTS); yzw unused
  PointLight light[CAUSTICA_MAX_POINT_LIGHTS];
};

// One KHR_lights_punctual light (std140, 64 bytes); units in app/scene/punctual_lights.h.
struct PunctualLight {
  vec4 position;   // xyz: world-space position (point, spot); w: type (kPunctual*, as a float)
  vec4 direction;  // xyz: unit world-space direction the light shines toward (spot, directional); w: cos(outer cone)
  vec4 intensity;  // rgb: colour x intensity (cd as radiance x area; directional: lux as irradiance); w: cos(inner cone)
  vec4 select;     // x: probability of choosing this light (power / total); y: cumulative probability up to and including it; zw unused
};

// Every punctual light of the scene, chosen by power at each non-delta vertex (std140).
struct PunctualParams {
  uvec4 count;                                   // x: lights in use (0..CAUSTICA_MAX_PUNCTUAL); yzw unused
  PunctualLight light[CAUSTICA_MAX_PUNCTUAL];
};

#ifdef __cplusplus
static_assert(sizeof(EnvironmentParams) == 48, "EnvironmentParams must be 48 bytes (std140)");
static_assert(sizeof(PointLight) == 64, "PointLight must be 64 bytes (std140)");
static_assert(sizeof(PointLights) == 16 + 64 * CAUSTICA_MAX_POINT_LIGHTS, "PointLights must match std140");
static_assert(sizeof(PunctualLight) == 64, "PunctualLight must be 64 bytes (std140)");
static_assert(sizeof(PunctualParams) == 16 + 64 * CAUSTICA_MAX_PUNCTUAL, "PunctualParams must match std140");
static_assert(sizeof(BvhNode) == 64, "BvhNode must be 64 bytes (4 texels)");
static_assert(sizeof(BvhWideNode) == 112, "BvhWideNode must be 112 bytes (7 texels)");
static_assert(sizeof(InstanceRecord) == 64, "InstanceRecord must be 64 bytes (4 texels)");
static_assert(sizeof(InstanceShade) == 64, "InstanceShade must be 64 bytes (4 texels)");
static_assert(sizeof(TriGeom) == 48, "TriGeom must be 48 bytes (std430)");
static_assert(sizeof(Material) == 16 * kMaterialTexels, "Material must be 192 bytes (std430)");
static_assert(sizeof(TexInfo) == 48, "TexInfo must be 48 bytes (std430)");
static_assert(sizeof(Counters) == 16, "Counters must be 16 bytes (std430)");
static_assert(sizeof(FrameParams) == 128, "FrameParams must be 128 bytes (std140)");
static_assert(sizeof(CasterParams) == 64 + 16 * CAUSTICA_MAX_CASTERS, "CasterParams must match std140");
static_assert(sizeof(CausticCell) == 16, "CausticCell must be 16 bytes (one rgba32ui texel)");
static_assert(sizeof(LightNode) == 64, "LightNode must be 64 bytes (std430)");
}  // namespace caustica::gpu
#endif
#undef CAUSTICA_CONST
#endif
