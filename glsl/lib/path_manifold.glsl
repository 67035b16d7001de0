// path_manifold.glsl — manifold next-event estimation as a step of the path tracer's bounce
// (manifold.glsl solves the chains): at the first diffuse vertex x the light sample is joined to x
// through a caster (the estimate), and a bounce that went from x through a caster's chain to an
// emitter is weighted against it (the other technique of the pair). One solve per bounce serves both,
// since llvmpipe runs every call site on every bounce (docs/architecture.md). Needs path_state.glsl,
// vertex.glsl, manifold.glsl.

// PathState.chain: what the path did after x, its first diffuse vertex.
const uint kChainActive = 0x100u;    // x was recorded (PathState.mx...)
const uint kChainDead = 0x200u;      // something other than one caster's specular events followed x
const uint kChainOwnerMask = 0xffu;  // the caster owning the first event after x; kChainNoOwner before it
const uint kChainNoOwner = 0xffu;
const uint kChainEventShift = 12u;   // delta events since x (4 bits)
const uint kMinCellPhotons = 2u;     // photons a cell needs for manifold NEE to join through its caster

vec3 gManifoldDeferred = vec3(0.0);  // emission of a hit that ends a caster chain, added after the solve
bool gManifoldCheck = false;         // this hit ends a caster chain from x: weigh its emission

uint chainEvents(uint chain) { return (chain >> kChainEventShift) & 15u; }
bool casterRefracts(uint caster) { return (casters.count.y & (1u << caster)) != 0u; }
uint casterChainEvents(uint caster) { return casterRefracts(caster) ? 2u : 1u; }

// The casters manifold NEE joins through from point p with unit shading normal n: those whose
// photons reached p's cell from above the surface (casterCell); their photon counts, one byte each
// (bit 8 i: caster i, saturated at 255), and in dirs the cells' directions. A function of p and n
// alone, so a bounce from x finds the same casters, counts and directions later.
uvec2 manifoldCasters(vec3 p, vec3 n, out vec3 dirs[CAUSTICA_MAX_CASTERS]) {
  uvec2 counts = uvec2(0u);
  for (uint i = 0u; i < uint(CAUSTICA_MAX_CASTERS); ++i) dirs[i] = vec3(0.0);
  uint i = 0u;
  do {  // bottom-tested, over the scene's casters only (count.x >= 1 where this is compiled): llvmpipe
        // runs a masked body per iteration, so a loop to CAUSTICA_MAX_CASTERS paid 8 cell lookups a bounce
    uvec4 cell = casterCell(i, p);
    vec3 d = vec3(ivec3(cell.yzw));
    float len = length(d);
    if (cell.x >= kMinCellPhotons && len > 0.0 && dot(d, n) > 0.0) {
      dirs[i] = d / len;
      uint c = min(cell.x, 255u) << (8u * (i & 3u));
      if (i < 4u) counts.x |= c;
      else counts.y |= c;
    }
  } while (++i < casters.count.x);
  return counts;
}

uint casterCount(uvec2 counts, uint i) { return ((i < 4u ? counts.x : counts.y) >> (8u * (i & 3u))) & 255u; }
float casterCountSum(uvec2 counts) {
  float sum = 0.0;
  for (uint i = 0u; i < uint(CAUSTICA_MAX_CASTERS); ++i) sum += float(casterCount(counts, i));
  return sum;
}

// The caster chosen with u in [0, 1) in proportion to its count.
uint pickCaster(uvec2 counts, float u) {
  float target = u * casterCountSum(counts), run = 0.0;
  uint caster = 0u, last = 0u;
  bool found = false;
  for (uint i = 0u; i < uint(CAUSTICA_MAX_CASTERS); ++i) {
    float c = float(casterCount(counts, i));
    run += c;
    if (c > 0.0) last = i;
    if (!found && c > 0.0 && target < run) {
      caster = i;
      found = true;
    }
  }
  return found ? caster : last;
}

// Whether the emitter the path of s has just hit ends a caster chain from x that manifold NEE could
// have produced (the caster's events, all of them, and nothing else): its emission waits for the solve.
bool manifoldChainEnds(PathState s) {
  if ((s.chain & (kChainActive | kChainDead)) != kChainActive) return false;
  uint owner = s.chain & kChainOwnerMask;
  return owner != kChainNoOwner && chainEvents(s.chain) == casterChainEvents(owner);
}

// Direction parameters (gnomonic, about the unit axis) of unit direction w.
vec2 manifoldParams(vec3 axis, vec3 w) {
  vec3 t, b;
  orthonormalBasis(axis, t, b);
  return vec2(dot(w, t), dot(w, b)) / dot(w, axis);
}

// The manifold step of a bounce at surface sf, after the lobe's light samples (v: its vertex) and
// before its scattering. At x (firstDiffuse: the path's first diffuse vertex, diffuse: a Lambertian
// lobe there): the estimate through a caster picked uniformly from manifoldCasters towards this
// vertex's emitter sample, MIS-weighted against x's bounce sampling. At an emitter hit that ends a
// chain from x: the emission deferred by addEmission, weighted against the estimate when the bounce
// is the very path the estimate finds from x to this point. Returns whether sf is x with casters to
// join through (trackCasterChain records it).
bool addManifoldLight(inout PathState s, Surface sf, bool diffuse, bool firstDiffuse, Vertex v) {
  bool here = diffuse && firstDiffuse && nextRayTraced(s);
  vec3 dirs[CAUSTICA_MAX_CASTERS];
  uvec2 counts = manifoldCasters(here ? sf.p : s.mx, here ? sf.ns : s.mxN, dirs);
  bool atX = here && counts != uvec2(0u);
  float uPick = rand01(s.rng);
  float uLambda = rand01(s.rng);
  uint caster = atX ? pickCaster(counts, uPick) : min(s.chain & kChainOwnerMask, uint(CAUSTICA_MAX_CASTERS) - 1u);
  bool nee = atX && gManifoldLightOk && s.depth + casterChainEvents(caster) + 1u < frame.options.x;
  ManifoldQuery q;
  q.x = nee ? sf.p : s.mx;
  q.xOrg = nee ? offsetRayOrigin(sf.p, sf.pError, sf.ng) : s.mxOrg;
  q.sigma = nee ? s.sigma : s.mxSigma;
  q.axis = dirs[caster];  // the cell's direction: where the caster's photons came from
  q.caster = caster;
  q.y = nee ? gManifoldLight.p : sf.p;
  q.nL = nee ? gManifoldLight.n : sf.ngFront;
  q.lambda = s.lambda;
  q.uLambda = uLambda;
  q.seed = vec2(0.0);
  bool check = gManifoldCheck && casterCount(counts, caster) > 0u;
  ManifoldResult r = manifoldSolve(q, nee || check);
  float pickProb = float(casterCount(counts, caster)) / max(casterCountSum(counts), 1.0);
  if (nee && r.ok) {
    LightSample ls = gManifoldLight;
    float cosL = dot(r.dLast, ls.n);  // < 0: the chain arrives at the emitter's front
    vec3 f = vertexEval(v, r.w);
    float pdfMan = pickProb * ls.pdfArea * r.areaPerSolidAngle;
    if ((cosL < 0.0 || ls.twoSided) && maxComponent(f) > 0.0 && pdfMan > 0.0) {
      ++gShadowRays;
      vec3 from = offsetRayOrigin(r.pLast, r.pLastError, r.ngLast);
      vec3 to = offsetRayOrigin(ls.p, ls.pError, cosL < 0.0 ? ls.n : -ls.n);
      vec3 seg = to - from;
      float segLen = length(seg);
      if (segLen > 0.0 && !traceOccluded(from, seg / segLen, segLen * (1.0 - 1.0e-4))) {
        float w = powerHeuristic(pdfMan, vertexPdf(v, r.w) * r.eventProb);
        vec3 le = ls.le;
#ifdef CAUSTICA_SPOT_EMITTERS
        le *= spotEmitterFactor(materialAt(ls.material), -r.dLast);
#endif
        s.radiance += s.beta * s.filt * r.filt * f * r.throughput * le * (w / pdfMan);
      }
    }
  }
  if (gManifoldCheck) {
    float w = 1.0;
    if (check && r.ok && length(manifoldParams(q.axis, s.mxDir) - r.ab) <= kManifoldSameSolution) {
#ifdef CAUSTICA_INSTANCED
      float pdfArea = instanceLightPdfArea(sf.g, sf.xf, s.mx, s.mxN);
#else
      float pdfArea = lightPdfArea(sf.tri, s.mx, s.mxN);
#endif
      w = powerHeuristic(s.mxPdf * r.eventProb, pickProb * pdfArea * r.areaPerSolidAngle);
    }
    s.radiance += gManifoldDeferred * w;
  }
  gManifoldLightOk = false;
  gManifoldCheck = false;
  if (atX) s.chain = kChainActive | kChainNoOwner;
  return atX;
}

// Follows the path of s after its bounce at sf (lobe, new direction newDir): records x, or counts the
// caster's events after it (the first one names the caster), or ends the chain.
void trackCasterChain(inout PathState s, Surface sf, uint lobe, vec3 newDir, bool atX) {
  if (atX) {
    s.mx = sf.p;
    s.mxN = sf.ns;
    s.mxOrg = offsetRayOrigin(sf.p, sf.pError, sf.ng);
    s.mxSigma = s.sigma;
    s.mxDir = newDir;
    s.mxPdf = s.prevPdf;
    return;
  }
  if ((s.chain & (kChainActive | kChainDead)) != kChainActive) return;
  uint owner = s.chain & kChainOwnerMask;
  if (chainEvents(s.chain) == 0u) {  // the first event after x: the caster it belongs to
    owner = casterOwning(sf.p);
    if (owner >= uint(CAUSTICA_MAX_CASTERS)) owner = kChainNoOwner;
  }
  bool refracts = owner != kChainNoOwner && casterRefracts(owner);
  bool transmitted = dot(newDir, sf.ng) < 0.0;
  bool matches = owner != kChainNoOwner && (refracts ? lobe == kLobeGlass && transmitted : lobe == kLobeMirror);
  uint events = chainEvents(s.chain) + 1u;
  s.chain = matches && events <= 2u
                ? (s.chain & ~(kChainOwnerMask | (15u << kChainEventShift))) | owner | (events << kChainEventShift)
                : kChainDead;
}
