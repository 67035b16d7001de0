// light_tree.glsl — chooses an emissive triangle by its importance to a shading point, descending the
// light tree (LightNode[] in gpu_layout.h, built by app/accel/light_tree.cpp), and gives the
// probability of any triangle's choice for MIS. C++ twins of the same names in app/accel/light_tree.h.
// Reads the nodes through their buffer texture (CAUSTICA_TEXUNIT_LIGHT_NODES; a vector gather on llvmpipe,
// where an SSBO load is a loop over the SIMD lanes). Needs gpu_layout.h.

layout(binding = CAUSTICA_TEXUNIT_LIGHT_NODES) uniform usamplerBuffer lightNodeTexels;  // 4 texels per LightNode

uvec4 lightNodeLink(uint i) { return texelFetch(lightNodeTexels, int(4u * i + 3u)); }
LightNode lightNodeAt(uint i) {
  int b = int(4u * i);
  LightNode node;
  node.boundsMin = uintBitsToFloat(texelFetch(lightNodeTexels, b));
  node.boundsMax = uintBitsToFloat(texelFetch(lightNodeTexels, b + 1));
  node.axis = uintBitsToFloat(texelFetch(lightNodeTexels, b + 2));
  node.link = texelFetch(lightNodeTexels, b + 3);
  return node;
}

float ltCosSubClamped(float sinA, float cosA, float sinB, float cosB) {  // cos(max(0, a - b))
  if (cosA > cosB) return 1.0;
  return cosA * cosB + sinA * sinB;
}
float ltSinSubClamped(float sinA, float cosA, float sinB, float cosB) {  // sin(max(0, a - b))
  if (cosA > cosB) return 0.0;
  return sinA * cosB - cosA * sinB;
}
float ltSafeSqrt(float x) { return sqrt(max(x, 0.0)); }

// An upper bound, up to a constant, of the light the node's triangles can send to p (world space) on a
// surface with unit normal n (either side; n = 0: none): power x bounded emission cosine x bounded
// receiver cosine / clamped squared distance; 0 where no triangle below can light p.
float lightImportance(LightNode node, vec3 p, vec3 n) {
  float power = node.boundsMin.w;
  if (!(power > 0.0)) return 0.0;
  vec3 lo = node.boundsMin.xyz, hi = node.boundsMax.xyz;
  vec3 centre = 0.5 * (lo + hi);
  vec3 d = p - centre;  // from the node's centre to p
  float d2 = dot(d, d);
  vec3 diag = hi - lo;
  float r2 = 0.25 * dot(diag, diag);  // squared radius of the sphere around the box
  float invD = d2 > 0.0 ? 1.0 / sqrt(d2) : 0.0;
  float cosW = dot(node.axis.xyz, d) * invD;
  if ((node.link.y & kLightNodeTwoSided) != 0u) cosW = abs(cosW);
  float sinW = ltSafeSqrt(1.0 - cosW * cosW);
  float cosB = d2 > r2 ? ltSafeSqrt(1.0 - r2 / d2) : -1.0;  // -1: p inside the sphere, every direction
  float sinB = ltSafeSqrt(1.0 - cosB * cosB);
  float cosO = node.boundsMax.w;
  float sinO = ltSafeSqrt(1.0 - cosO * cosO);
  float cosX = ltCosSubClamped(sinW, cosW, sinO, cosO);
  float sinX = ltSinSubClamped(sinW, cosW, sinO, cosO);
  float cosP = ltCosSubClamped(sinX, cosX, sinB, cosB);
  if (cosP <= node.axis.w) return 0.0;
  float importance = power * cosP / max(d2, r2);
  if (dot(n, n) > 0.0) {  // the receiver's cosine, bounded the same way (either side of the surface)
    float cosI = d2 > 0.0 ? abs(dot(d, n)) * invD : 1.0;
    float sinI = ltSafeSqrt(1.0 - cosI * cosI);
    importance *= ltCosSubClamped(sinI, cosI, sinB, cosB);
  }
  return max(importance, 0.0);
}

#ifdef CAUSTICA_INSTANCED
uint gLightInstance = 0u;  // instanced scenes: the Scene::instances index of the leaf sampleLightTree chose
#endif

// Descends from the root choosing each child in proportion to its importance, u in [0, 1) rescaled at
// every level. False where no triangle can light p; else tri (TriGeom order) and pmf, its probability.
// The descent is a bottom-tested loop, one body per level: llvmpipe runs a loop's whole body (masked)
// in the iteration whose test at the top ends it, so the top-tested loop this was cost one level more
// per call (on a one-level tree twice the work), plus a separate test of a leaf root. A leaf root runs
// the body once with the root in both children's places (il + ir > 0 exactly when the root's
// importance is > 0). The child's link comes from its node record (the same texel lightNodeLink reads).
// Same arithmetic in the same order as the C++ twin (app/accel/light_tree.cpp), so the same choices.
bool sampleLightTree(vec3 p, vec3 n, float u, out uint tri, out float pmf) {
  pmf = 0.0;
  tri = 0u;
  float prob = 1.0;
  uvec4 link = lightNodeLink(0u);
  bool leaf = (link.y & kLightNodeLeaf) != 0u;
  int level = 0;  // of the node `link` belongs to
  do {
    LightNode nl = lightNodeAt(leaf ? 0u : link.x);
    LightNode nr = lightNodeAt(leaf ? 0u : link.x + 1u);
    float il = lightImportance(nl, p, n);
    float ir = lightImportance(nr, p, n);
    if (!(il + ir > 0.0)) return false;
    if (leaf) break;  // the root is a leaf and can light p
    float pl = il / (il + ir);
    if (u < pl) {
      u = min(u / pl, 0.99999994);
      prob *= pl;
      link = nl.link;
    } else {
      u = min((u - pl) / (1.0 - pl), 0.99999994);
      prob *= 1.0 - pl;
      link = nr.link;
    }
    leaf = (link.y & kLightNodeLeaf) != 0u;
    ++level;
  } while (!leaf && level <= CAUSTICA_LIGHT_TREE_DEPTH);
  if (!leaf || level > CAUSTICA_LIGHT_TREE_DEPTH) return false;
  tri = link.x;
#ifdef CAUSTICA_INSTANCED
  gLightInstance = link.y >> kLightNodeInstanceShift;
#endif
  pmf = prob;
  return true;
}

// The probability that sampleLightTree(p, n) chooses the triangle of leaf node `leaf`: the same choices
// repeated along the leaf's bit trail. A bottom-tested loop as above (one body per level; a leaf root,
// depth 0, runs it once with the root in both places: 1 where its importance is > 0, else 0).
float lightTreePdf(vec3 p, vec3 n, uint leaf) {
  uvec4 leafLink = lightNodeLink(leaf);
  uint trail = leafLink.z, depth = leafLink.w;
  uint left = depth == 0u ? 0u : lightNodeLink(0u).x;
  float prob = 1.0;
  uint k = 0u;
  do {
    LightNode nl = lightNodeAt(left);
    LightNode nr = lightNodeAt(depth == 0u ? 0u : left + 1u);
    float il = lightImportance(nl, p, n);
    float ir = lightImportance(nr, p, n);
    if (!(il + ir > 0.0)) return 0.0;
    if (depth == 0u) return 1.0;
    float pl = il / (il + ir);
    if (((trail >> k) & 1u) != 0u) {
      prob *= 1.0 - pl;
      left = nr.link.x;
    } else {
      prob *= pl;
      left = nl.link.x;
    }
    ++k;
  } while (k < depth);
  return prob;
}
