// gltf_materials.cpp — glTF materials after the contract in docs/materials.md, and their textures:
// images decoded by stb_image or libwebp (tinygltf's image callback), samplers, the default material.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include <webp/decode.h>

#include "scene/gltf_internal.h"

namespace caustica::gltf {
namespace {

double extNumber(const tinygltf::Value* ext, const char* key, double fallback) {
  if (!ext || !ext->Has(key) || !ext->Get(key).IsNumber()) return fallback;
  return ext->Get(key).GetNumberAsDouble();
}

bool extHas(const tinygltf::Value* ext, const char* key) { return ext && ext->Has(key); }

// KHR_materials_unlit: the surface shows its base colour whatever the lighting (docs/materials.md). A
// path tracer's only such surface is an emitter that reflects nothing: it emits the base colour (factor
// x texture; alpha, MASK and doubleSided as for any material) and every other property, emission
// included, is the fallback for viewers without the extension and is not used.
void makeUnlit(Material& m) {
  Material u;
  u.name = m.name;
  u.unlit = true;
  u.emission = glm::vec3(m.baseColor);
  u.emissiveTexture = m.baseColorTexture;
  u.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, m.baseColor.a);
  u.alphaFromTexture = m.alphaFromTexture;
  u.alphaCutoff = m.alphaCutoff;
  if (m.alphaFromTexture) u.baseColorTexture = m.baseColorTexture;  // for its alpha only
  u.doubleSided = m.doubleSided;
  u.roughness = 1.0f;  // black Lambertian: no specular layer (specularF90 0), no metal, no glass
  m = u;
}

// Adds `what` to a material's list of things not rendered (`ignored`, comma-separated) if present.
void ignore(std::string& ignored, bool present, const char* what) {
  if (present) ignored += (ignored.empty() ? "" : ", ") + std::string(what);
}

void wrapMode(int mode, bool& repeat, bool& mirror) {
  repeat = mode != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  mirror = mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
}

}  // namespace

namespace {
// A WebP file: "RIFF", 4 size bytes, "WEBP".
bool isWebp(const unsigned char* bytes, int size) {
  return size >= 12 && std::memcmp(bytes, "RIFF", 4) == 0 && std::memcmp(bytes + 8, "WEBP", 4) == 0;
}
}  // namespace

bool decodeImage(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                 const unsigned char* bytes, int size, void* user) {
  auto* log = static_cast<ImageLog*>(user);
  int w = 0, h = 0, channels = 0;
  const bool webp = bytes && size > 0 && isWebp(bytes, size);
  if (webp) {
    if (!WebPGetInfo(bytes, std::size_t(size), &w, &h)) {
      log->failures[index] = "not a decodable WebP image (bad header, or an animated WebP)";
      return true;
    }
  } else if (!bytes || size <= 0 || !stbi_info_from_memory(bytes, size, &w, &h, &channels)) {
    const char* reason = stbi_failure_reason();
    log->failures[index] =
        std::string("not a decodable PNG/JPEG/WebP image (") + (reason ? reason : "unknown format") + ")";
    return true;
  }
  if (w < 1 || h < 1 || w > kMaxTextureSide || h > kMaxTextureSide ||
      std::int64_t(w) * std::int64_t(h) > kMaxTexturePixels) {
    log->failures[index] = "its size " + str(std::uint64_t(std::max(w, 0))) + "x" + str(std::uint64_t(std::max(h, 0))) +
                           " is out of range (at most " + str(kMaxTextureSide) + " per side)";
    return true;
  }
  const std::uint64_t decodedBytes = std::uint64_t(w) * std::uint64_t(h) * 4;
  log->declared += decodedBytes;
  if (log->declared > log->budget) {
    log->overBudget = "images[" + str(std::uint64_t(std::max(index, 0))) + "] (" + str(std::uint64_t(w)) + "x" +
                      str(std::uint64_t(h)) + ") brings the decoded textures to " + mib(log->declared) +
                      ", more than the limit of " + mib(log->budget) + " (use --max-texture-mib to raise it)";
    return false;
  }
  // PNG and JPEG through stb_image, WebP (EXT_texture_webp) through libwebp; both to 8-bit RGBA.
  unsigned char* pixels = webp ? WebPDecodeRGBA(bytes, std::size_t(size), &w, &h)
                               : stbi_load_from_memory(bytes, size, &w, &h, &channels, 4);
  if (!pixels) {
    const char* reason = webp ? "libwebp could not decode it" : stbi_failure_reason();
    log->failures[index] = std::string("it could not be decoded (") + (reason ? reason : "unknown error") + ")";
    return true;
  }
  image->width = w;
  image->height = h;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.assign(pixels, pixels + std::size_t(w) * std::size_t(h) * 4);
  if (webp) WebPFree(pixels);
  else stbi_image_free(pixels);
  return true;
}

double SceneBuilder::unit(double v, const std::string& what) {
  if (v < 0.0 || v > 1.0) {
    warn(what + " = " + num(v) + " is outside [0, 1]; clamped");
    return std::clamp(v, 0.0, 1.0);
  }
  return v;
}

Material SceneBuilder::convertMaterial(int index) {
  const tinygltf::Material& m = model_.materials[std::size_t(index)];
  const std::string at = "materials[" + str(std::uint64_t(index)) + "]";
  Material out;
  materialTexCoords_.clear();
  out.name = m.name.empty() ? "material " + str(std::uint64_t(index)) : m.name;
  convertBasePbr(m, at, out);
  convertEmission(m, at, out);
  out.doubleSided = m.doubleSided;

  std::string ignored;  // what the material has that is not rendered, for one notRendered line
  ignore(ignored, m.occlusionTexture.index >= 0, "occlusionTexture (ambient occlusion is what a path tracer computes)");
  convertTransmission(m, at, out, ignored);
  convertSpecular(m, at, out);
  convertClearcoat(m, at, out);
  convertSheen(m, at, out);
  if (const tinygltf::Value* d = extension(m.extensions, "KHR_materials_dispersion")) {
    const double dispersion = extNumber(d, "dispersion", 0.0);
    if (dispersion < 0.0) warn(at + ": dispersion " + num(dispersion) + " is negative; using 0");
    else out.dispersion = float(dispersion);
  }
  if (extension(m.extensions, "KHR_materials_unlit")) makeUnlit(out);
  if (!ignored.empty()) notRendered(at + " '" + oneLine(out.name) + "': " + ignored);
  chooseMaterialTexCoord(at, out);
  return out;
}

void SceneBuilder::convertBasePbr(const tinygltf::Material& m, const std::string& at, Material& out) {
  const auto& pbr = m.pbrMetallicRoughness;
  glm::dvec4 base(1.0);
  for (std::size_t c = 0; c < 4 && c < pbr.baseColorFactor.size(); ++c)
    base[int(c)] = unit(pbr.baseColorFactor[c], at + ".baseColorFactor[" + str(c) + "]");
  out.metallic = float(unit(pbr.metallicFactor, at + ".metallicFactor"));
  out.roughness = float(unit(pbr.roughnessFactor, at + ".roughnessFactor"));
  out.baseColorTexture = texture(pbr.baseColorTexture, at + ".baseColorTexture");
  out.metallicRoughnessTexture = texture(pbr.metallicRoughnessTexture, at + ".metallicRoughnessTexture");
  out.normalTexture = texture(m.normalTexture, at + ".normalTexture");
  out.normalScale = float(m.normalTexture.scale);
  if (!std::isfinite(out.normalScale)) fail(at + ".normalTexture.scale is not finite");

  // Opacity: OPAQUE ignores alpha; MASK thresholds factor x texture alpha at alphaCutoff; BLEND keeps
  // it as partial opacity (docs/materials.md). Without a texture the threshold is applied here.
  if (m.alphaMode == "OPAQUE" || m.alphaMode.empty()) {
    base.a = 1.0;
  } else if (m.alphaMode == "MASK") {
    if (!(m.alphaCutoff >= 0.0)) fail(at + ".alphaCutoff is " + num(m.alphaCutoff) + "; it must be >= 0");
    out.alphaCutoff = float(m.alphaCutoff);
    out.maskAlpha = float(base.a);
    if (out.baseColorTexture < 0) base.a = base.a >= m.alphaCutoff ? 1.0 : 0.0;
  } else if (m.alphaMode != "BLEND") {
    fail(at + ".alphaMode is \"" + oneLine(m.alphaMode) + "\"; it must be OPAQUE, BLEND or MASK");
  }
  out.baseColor = glm::vec4(base);
  out.alphaFromVertices = m.alphaMode == "BLEND" || m.alphaMode == "MASK";
  out.alphaFromTexture = out.baseColorTexture >= 0 && out.alphaFromVertices;
}

void SceneBuilder::convertEmission(const tinygltf::Material& m, const std::string& at, Material& out) {
  // Emission: emissiveFactor x KHR_materials_emissive_strength = radiance (linear).
  glm::dvec3 emissive(0.0);
  for (std::size_t c = 0; c < 3 && c < m.emissiveFactor.size(); ++c) {
    emissive[int(c)] = m.emissiveFactor[c];
    if (emissive[int(c)] < 0.0) {
      warn(at + ".emissiveFactor[" + str(c) + "] is negative; clamped to 0");
      emissive[int(c)] = 0.0;
    }
  }
  double strength = extNumber(extension(m.extensions, "KHR_materials_emissive_strength"), "emissiveStrength", 1.0);
  if (strength < 0.0) {
    warn(at + ": emissiveStrength " + num(strength) + " is negative; using 0");
    strength = 0.0;
  }
  out.emission = glm::vec3(emissive * strength);
  if (!std::isfinite(out.emission.r) || !std::isfinite(out.emission.g) || !std::isfinite(out.emission.b))
    fail(at + ": emitted radiance overflows a float");
  out.emissiveTexture = texture(m.emissiveTexture, at + ".emissiveTexture");
}

void SceneBuilder::convertTransmission(const tinygltf::Material& m, const std::string& at, Material& out,
                                       std::string& ignored) {
  if (const tinygltf::Value* t = extension(m.extensions, "KHR_materials_transmission")) {
    out.transmission = float(unit(extNumber(t, "transmissionFactor", 0.0), at + ".transmissionFactor"));
    if (out.transmission > 0.0f) out.transmissionTexture = extTexture(t, "transmissionTexture", at);
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_ior")) {
    const double ior = extNumber(e, "ior", 1.5);
    if (ior < 1.0) warn(at + ": ior " + num(ior) + " is below 1; using 1.5");
    else out.ior = float(ior);
  }
  if (const tinygltf::Value* v = extension(m.extensions, "KHR_materials_volume")) {
    // thicknessFactor is ignored: the ray tracer follows the real geometry through the volume.
    ignore(ignored, extHas(v, "thicknessTexture"), "thicknessTexture");
    if (extHas(v, "attenuationColor") && v->Get("attenuationColor").ArrayLen() == 3)
      for (int c = 0; c < 3; ++c)
        out.attenuationColor[c] = float(unit(v->Get("attenuationColor").Get(c).GetNumberAsDouble(),
                                             at + ".attenuationColor[" + str(std::uint64_t(c)) + "]"));
    const double distance = extNumber(v, "attenuationDistance", std::numeric_limits<double>::infinity());
    if (!(distance > 0.0)) warn(at + ": attenuationDistance " + num(distance) + " is not positive; no absorption");
    else out.attenuationDistance = float(distance);
  }
}

// The dielectric specular layer over the diffuse base (glTF Appendix B fresnel_mix, with
// KHR_materials_specular): F0 = min(((ior - 1) / (ior + 1))^2 specularColorFactor, 1) specularFactor,
// F90 = specularFactor.
void SceneBuilder::convertSpecular(const tinygltf::Material& m, const std::string& at, Material& out) {
  double specularFactor = 1.0;
  glm::dvec3 specularColor(1.0);
  if (const tinygltf::Value* sp = extension(m.extensions, "KHR_materials_specular")) {
    specularFactor = unit(extNumber(sp, "specularFactor", 1.0), at + ".specularFactor");
    if (extHas(sp, "specularColorFactor") && sp->Get("specularColorFactor").ArrayLen() == 3)
      for (int c = 0; c < 3; ++c) {
        const tinygltf::Value& v = sp->Get("specularColorFactor").Get(c);
        double x = v.IsNumber() ? v.GetNumberAsDouble() : 1.0;
        if (!(x >= 0.0) || !std::isfinite(x)) {
          warn(at + ".specularColorFactor[" + str(std::uint64_t(c)) + "] is not a finite number >= 0; using 1");
          x = 1.0;
        }
        specularColor[c] = x;
      }
    // Textures only where a specular layer can exist (the dielectric base; not a full metal or glass).
    if (out.metallic < 1.0f && out.transmission < 1.0f) {
      out.specularTexture = extTexture(sp, "specularTexture", at);
      out.specularColorTexture = extTexture(sp, "specularColorTexture", at);
    }
  }
  const double r = (double(out.ior) - 1.0) / (double(out.ior) + 1.0);
  out.specularF0 = glm::vec3(glm::min(r * r * specularColor, glm::dvec3(1.0)) * specularFactor);
  out.specularF90 = float(specularFactor);
  out.specularColorFactor = glm::vec3(specularColor);
  out.specularFactor = float(specularFactor);
  // A specular texture can raise F90 from 0 only if the factor does: specularFactor 0 stays Lambertian.
  if (out.specularF90 == 0.0f) out.specularTexture = out.specularColorTexture = -1;
}

void SceneBuilder::convertClearcoat(const tinygltf::Material& m, const std::string& at, Material& out) {
  const tinygltf::Value* c = extension(m.extensions, "KHR_materials_clearcoat");
  if (!c) return;
  out.clearcoat = float(unit(extNumber(c, "clearcoatFactor", 0.0), at + ".clearcoatFactor"));
  out.clearcoatRoughness = float(unit(extNumber(c, "clearcoatRoughnessFactor", 0.0), at + ".clearcoatRoughnessFactor"));
  if (out.clearcoat > 0.0f) {
    out.clearcoatTexture = extTexture(c, "clearcoatTexture", at);
    out.clearcoatRoughnessTexture = extTexture(c, "clearcoatRoughnessTexture", at);
    out.clearcoatNormalTexture = extTexture(c, "clearcoatNormalTexture", at);
    if (out.clearcoatNormalTexture >= 0) {
      out.clearcoatNormalScale = float(extNumber(&c->Get("clearcoatNormalTexture"), "scale", 1.0));
      if (!std::isfinite(out.clearcoatNormalScale)) fail(at + ".clearcoatNormalTexture.scale is not finite");
    }
  }
}

void SceneBuilder::convertSheen(const tinygltf::Material& m, const std::string& at, Material& out) {
  const tinygltf::Value* sh = extension(m.extensions, "KHR_materials_sheen");
  if (!sh) return;
  if (extHas(sh, "sheenColorFactor") && sh->Get("sheenColorFactor").ArrayLen() == 3)
    for (int c = 0; c < 3; ++c) {
      const tinygltf::Value& v = sh->Get("sheenColorFactor").Get(c);
      out.sheenColor[c] = float(unit(v.IsNumber() ? v.GetNumberAsDouble() : 0.0,
                                     at + ".sheenColorFactor[" + str(std::uint64_t(c)) + "]"));
    }
  out.sheenRoughness = float(unit(extNumber(sh, "sheenRoughnessFactor", 0.0), at + ".sheenRoughnessFactor"));
  if (out.hasSheen()) {
    out.sheenColorTexture = extTexture(sh, "sheenColorTexture", at);
    out.sheenRoughnessTexture = extTexture(sh, "sheenRoughnessTexture", at);
  }
}

// Triangles carry one UV set, so a material's textures must agree on theirs (TEXCOORD_0 or _1).
void SceneBuilder::chooseMaterialTexCoord(const std::string& at, Material& out) {
  if (materialTexCoords_.size() == 1 && (*materialTexCoords_.begin() == 0 || *materialTexCoords_.begin() == 1)) {
    out.texCoord = *materialTexCoords_.begin();
  } else if (!materialTexCoords_.empty()) {
    std::string sets;
    for (int t : materialTexCoords_) sets += (sets.empty() ? "TEXCOORD_" : ", TEXCOORD_") + str(std::uint64_t(std::max(t, 0)));
    warn(at + " '" + oneLine(out.name) + "': its textures read " + sets +
         "; caustica keeps one UV set per material (TEXCOORD_0 or TEXCOORD_1) and uses TEXCOORD_0 for all of them");
  }
}

int SceneBuilder::texture(const tinygltf::TextureInfo& info, const std::string& at) {
  if (info.index < 0) return -1;
  if (std::size_t(info.index) >= model_.textures.size())
    fail(at + ".index is " + str(std::uint64_t(info.index)) + ", but the file has " + str(model_.textures.size()) +
         " textures");
  int texCoord = info.texCoord;
  // KHR_texture_transform (the ratified form, whose example maps rotation pi/2, offset (0, 1), scale
  // 0.5 to the lower left quadrant): u' = c sx u + s sy v + ox, v' = -s sx u + c sy v + oy.
  glm::dvec3 row0(1.0, 0.0, 0.0), row1(0.0, 1.0, 0.0);
  if (const tinygltf::Value* t = extension(info.extensions, "KHR_texture_transform")) {
    const auto pair = [&](const char* key, glm::dvec2 fallback) {
      if (!t->Has(key) || t->Get(key).ArrayLen() != 2) return fallback;
      glm::dvec2 v;
      for (int c = 0; c < 2; ++c) v[c] = t->Get(key).Get(c).IsNumber() ? t->Get(key).Get(c).GetNumberAsDouble() : fallback[c];
      return v;
    };
    const glm::dvec2 offset = pair("offset", glm::dvec2(0.0)), scale = pair("scale", glm::dvec2(1.0));
    const double rotation = extNumber(t, "rotation", 0.0);
    if (!std::isfinite(offset.x) || !std::isfinite(offset.y) || !std::isfinite(scale.x) || !std::isfinite(scale.y) ||
        !std::isfinite(rotation))
      fail(at + ".extensions.KHR_texture_transform has a number that is not finite");
    const double c = std::cos(rotation), s = std::sin(rotation);
    row0 = glm::dvec3(c * scale.x, s * scale.y, offset.x);
    row1 = glm::dvec3(-s * scale.x, c * scale.y, offset.y);
    if (t->Has("texCoord") && t->Get("texCoord").IsInt()) texCoord = t->Get("texCoord").GetNumberAsInt();
  }
  materialTexCoords_.insert(texCoord);  // one UV set per material: chosen in convertMaterial
  if (row0 != glm::dvec3(1.0, 0.0, 0.0) || row1 != glm::dvec3(0.0, 1.0, 0.0)) {
    tinygltf::TextureInfo plain = info;
    plain.extensions.clear();
    plain.texCoord = texCoord;
    const int base = texture(plain, at);
    if (base < 0) return -1;
    const std::vector<float> key = {float(row0.x), float(row0.y), float(row0.z), float(row1.x), float(row1.y), float(row1.z)};
    const auto found = transformMap_.find({info.index, key});
    if (found != transformMap_.end()) return found->second;
    Texture shared = scene_.textures[std::size_t(base)];
    shared.rgba.clear();
    shared.pixelSource = base;
    shared.uvRow0 = glm::vec3(row0);
    shared.uvRow1 = glm::vec3(row1);
    scene_.textures.push_back(std::move(shared));
    const int result = int(scene_.textures.size() - 1);
    transformMap_[{info.index, key}] = result;
    return result;
  }
  const auto cached = textureMap_.find(info.index);
  if (cached != textureMap_.end()) return cached->second;

  const tinygltf::Texture& tex = model_.textures[std::size_t(info.index)];
  const std::string tat = "textures[" + str(std::uint64_t(info.index)) + "]";
  int result = -1;
  // EXT_texture_webp names the WebP image, which replaces the (PNG/JPEG fallback) source.
  int source = tex.source;
  std::string sourceAt = tat + ".source";
  if (const tinygltf::Value* webp = extension(tex.extensions, "EXT_texture_webp")) {
    if (webp->Has("source") && webp->Get("source").IsInt()) {
      source = webp->Get("source").GetNumberAsInt();
      sourceAt = tat + ".extensions.EXT_texture_webp.source";
    }
  }
  if (source < 0) {
    warn(tat + " has no source image; ignored");
  } else {
    if (std::size_t(source) >= model_.images.size())
      fail(sourceAt + " is " + str(std::uint64_t(source)) + ", but the file has " + str(model_.images.size()) + " images");
    const tinygltf::Image& img = model_.images[std::size_t(source)];
    const std::string iat = "images[" + str(std::uint64_t(source)) + "]" +
                            (img.uri.empty() ? std::string() : " '" + oneLine(img.uri) + "'");
    if (img.image.empty()) {
      const auto reason = images_.failures.find(source);
      fail(iat + " could not be loaded: " +
           (reason != images_.failures.end() ? reason->second : std::string("file not found or unreadable")));
    }
    if (img.width < 1 || img.height < 1 || img.component != 4 || img.bits != 8 ||
        img.image.size() != std::size_t(img.width) * std::size_t(img.height) * 4)
      fail(iat + " has an unexpected pixel layout");
    Texture out;
    out.width = img.width;
    out.height = img.height;
    out.rgba = img.image;
    if (tex.sampler >= 0) {
      if (std::size_t(tex.sampler) >= model_.samplers.size())
        fail(tat + ".sampler is " + str(std::uint64_t(tex.sampler)) + ", but the file has " +
             str(model_.samplers.size()) + " samplers");
      const tinygltf::Sampler& s = model_.samplers[std::size_t(tex.sampler)];
      wrapMode(s.wrapS, out.repeatS, out.mirrorS);
      wrapMode(s.wrapT, out.repeatT, out.mirrorT);
      out.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
    }
    scene_.textures.push_back(std::move(out));
    result = int(scene_.textures.size() - 1);
  }
  textureMap_[info.index] = result;
  return result;
}

int SceneBuilder::extTexture(const tinygltf::Value* ext, const char* key, const std::string& at) {
  if (!ext || !ext->Has(key) || !ext->Get(key).IsObject()) return -1;
  const tinygltf::Value& v = ext->Get(key);
  tinygltf::TextureInfo t;
  if (!v.Has("index") || !v.Get("index").IsNumber()) return -1;  // the JSON check requires an integer index
  t.index = v.Get("index").GetNumberAsInt();
  if (v.Has("texCoord") && v.Get("texCoord").IsNumber()) t.texCoord = v.Get("texCoord").GetNumberAsInt();
  if (v.Has("extensions") && v.Get("extensions").IsObject()) {
    const tinygltf::Value& e = v.Get("extensions");
    for (const std::string& name : e.Keys()) t.extensions[name] = e.Get(name);
  }
  return texture(t, at + ".extensions." + key);
}

int SceneBuilder::texture(const tinygltf::NormalTextureInfo& info, const std::string& at) {
  tinygltf::TextureInfo t;
  t.index = info.index;
  t.texCoord = info.texCoord;
  t.extensions = info.extensions;
  return texture(t, at);
}

std::uint32_t SceneBuilder::defaultMaterial(const std::string& at) {
  if (defaultMaterial_ < 0) {
    Material m;
    m.name = "default (no material)";
    m.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    scene_.materials.push_back(m);
    defaultMaterial_ = int(scene_.materials.size() - 1);
    warn(at + " has no material; primitives without one use a plain diffuse grey (albedo 0.8)");
  }
  return std::uint32_t(defaultMaterial_);
}

}  // namespace caustica::gltf
